"""The Python API (pyevolver/api.py): ``pyevolver.load``, ``Session.g``,
``.run``, ``.surface``, ``.quantities``, ``.value``, ``.history`` and the
progress bars, which never reach the Evolver-compatible output."""
import io
import os

import numpy as np
import pytest

import pyevolver
from pyevolver.session.api import progress_bar
from pyevolver.errors import PyEvolverError

from conftest import example
from reference import numbers

tqdm = pytest.importorskip("tqdm")


def test_load_run_and_arrays():
    s = pyevolver.load(example("cube.fe"), out=io.StringIO())
    assert isinstance(s, pyevolver.Session)
    s.run("r; u")
    res = s.g(10)
    assert len(res) == 10 and res[-1].energy == s.total_energy
    X, F = s.surface.X, s.surface.F
    assert X.shape == (50, 3) and F.shape == (96, 3) and F.max() == 49
    assert s.value("total_energy") == s.total_energy
    assert s.value("body[1].volume") == pytest.approx(1.0, abs=1e-6)
    with pytest.raises(PyEvolverError, match="not one expression"):
        s.value("1; g 2")


def test_quantities_match_the_reference(evolver, tmp_path):
    """qmound.fe's named quantities, as the Evolver prints them after loading."""
    f = example("qmound.fe")
    s = pyevolver.load(f, out=io.StringIO())
    q = s.quantities
    assert q, "qmound.fe declares quantities"
    ref = numbers(evolver, f, [f"{k}.value" for k in q], cwd=str(tmp_path))
    for (k, v), r in zip(q.items(), ref):
        assert abs(v - r) <= 1e-12 * max(1.0, abs(r)), (k, v, r)


def test_progress_bar_in_the_api_only(capsys):
    s = pyevolver.load(example("cube.fe"), out=io.StringIO())
    s.g(3, progress=True)
    err = capsys.readouterr().err
    assert "/3 [" in err                                 # tqdm's counter
    s.out = io.StringIO()
    s.run("g 150")                                       # a long run of the command: no bar
    assert capsys.readouterr().err == ""
    assert s.out.getvalue().count("area:") == 150
    assert progress_bar(500, None) is None               # not a terminal: no bar by default
    assert progress_bar(500, False) is None


def test_bfgs_progress_bar(capsys):
    torus = os.path.join(os.path.dirname(os.path.dirname(__file__)), "..", "datafiles", "paper",
                         "torus5x9_circle_willmore.fe")
    s = pyevolver.load(torus, out=io.StringIO())
    s.surface.X += 1e-3 * np.random.default_rng(0).standard_normal(s.surface.X.shape)
    s.recalc()
    r = s.bfgs(3, echo=False, progress=True)
    assert r.nit == 3 and "/3 [" in capsys.readouterr().err
    s.bfgs(3)                                       # echoed: the Evolver-style lines, no bar
    assert capsys.readouterr().err == "" and s.out.getvalue().count("energy:") == 3
