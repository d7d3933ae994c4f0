"""``set vertex x expr`` on whole coordinate columns
(pyevolver.commands.columns): the same numbers as the element-by-element
evaluation, the same errors, and the loop wherever the columns do not apply."""
from __future__ import annotations

import io
import os

import numpy as np
import pytest

from pyevolver.commands import element_attrs, columns
from pyevolver.errors import PyEvolverError
from pyevolver.session.core import Session

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CUBE = os.path.join(ROOT, "datafiles", "cube.fe")


def _session():
    s = Session.load(CUBE, out=io.StringIO(), err=io.StringIO())
    s.run("r; r")
    s.surface.X += 1e-3 * np.random.default_rng(7).normal(size=s.surface.X.shape)
    s.refresh()
    return s


def _spy(m, module, name, real, use):
    """Put in ``module.name`` the column function ``real`` (recording whether
    it applied: the list returned) or, without ``use``, one that never does."""
    calls = []

    def spy(*a, **k):
        r = real(*a, **k)
        calls.append(r is not None)
        return r
    m.setattr(module, name, spy if use else lambda *a, **k: None)
    return calls


def _both(monkeypatch, commands):
    """The coordinates (or the error) after ``commands`` with the columns
    and with the element loop alone."""
    out = []
    for use_columns in (True, False):
        with monkeypatch.context() as m:
            calls = _spy(m, element_attrs, "column_values", columns.column_values, use_columns)
            s = _session()
            try:
                s.run(commands)
                got = s.surface.X.copy()
            except PyEvolverError as exc:
                got = str(exc)
            out.append((got, any(calls)))
    return out


@pytest.mark.parametrize("commands", [
    "set vertex z z*1.5",
    "set vertex x 2*x - y/3 + 0.5",
    "set vertex y -x + -(z - 0.25)*7/3",
    "sc := 1.1; set vertex x x*sc - sc/7",
    "set vertex z z*1.5 where id < 20",
    "set vertex x1 x3 + x2",
    "set vertex z 0",
])
def test_same_numbers_as_the_element_loop(monkeypatch, commands):
    (cols, used), (loop, _) = _both(monkeypatch, commands)
    assert used, "the columns were not used"
    assert isinstance(cols, np.ndarray) and np.array_equal(cols, loop)


@pytest.mark.parametrize("commands", [
    "set vertex z sin(z)",                       # functions: the loop
    "set vertex z z^2",                          # (powers round differently on arrays)
    "x := 2; set vertex z x",                    # a variable shadows the coordinate
    "foreach vertex vv do set vertex z vv.z",    # inside another element loop
    "set vertex z z/(x - x)",                    # a division by zero: the loop's error
])
def test_the_loop_where_the_columns_do_not_apply(monkeypatch, commands):
    (cols, _), (loop, _) = _both(monkeypatch, commands)
    if isinstance(loop, str):
        assert cols == loop
    else:
        assert np.array_equal(cols, loop)


def test_a_failing_set_leaves_the_surface(monkeypatch):
    s = _session()
    X = s.surface.X.copy()
    with pytest.raises(PyEvolverError):
        s.run("set vertex z z/(x - x)")
    assert np.array_equal(s.surface.X, X)


def test_element_id_without_the_array():
    s = _session()
    ids = s.surface.ids("vertex")
    assert [s.surface.element_id("vertex", i) for i in range(s.surface.nv)] == list(ids)
    s.surface.vattr["id"] = ids * 3
    assert s.surface.element_id("vertex", 5) == 3 * int(ids[5])


def _selected(monkeypatch, use_columns, command):
    """The vertex indices a ``where`` selects (through ``set vertex z ...``
    of a marker value: the vertices whose z becomes it) and where_count."""
    from pyevolver.commands import elements
    with monkeypatch.context() as m:
        calls = _spy(m, elements, "where_mask", columns.where_mask, use_columns)
        s = _session()
        try:
            s.run(command)
        except PyEvolverError as exc:
            return str(exc), None, any(calls)
        return np.nonzero(s.surface.X[:, 2] == 7.25)[0].tolist(), s.counts.get("where"), \
            any(calls)


@pytest.mark.parametrize("cond", [
    "id < 20", "z > 0.3 and not (x < 0 or y >= 0.25)", "x*2 - 1 >= y/4 or id == 5",
    "-x != 0.5", "x < y", "w1 := 0.2; z > w1",
])
def test_where_selects_what_the_element_loop_selects(monkeypatch, cond):
    pre, _, c = cond.rpartition("; ")
    command = (pre + "; " if pre else "") + f"set vertex z 7.25 where {c}"
    a = _selected(monkeypatch, True, command)
    b = _selected(monkeypatch, False, command)
    assert a[2], "the columns were not used"
    assert a[:2] == b[:2] and len(a[0]) > 0


@pytest.mark.parametrize("cond", [
    "z > 0.3 and 1/x > 2",                     # a division by a coordinate: the loop
    "sin(z) > 0.2",                            # functions: the loop
    "on_constraint 1",
])
def test_where_loop_where_the_columns_do_not_apply(monkeypatch, cond):
    a = _selected(monkeypatch, True, f"set vertex z 7.25 where {cond}")
    b = _selected(monkeypatch, False, f"set vertex z 7.25 where {cond}")
    assert not a[2] and a[:2] == b[:2]
