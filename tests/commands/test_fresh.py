"""The evaluation after a command is skipped only when nothing it reads
changed since the last one (pyevolver.commands.fresh, issue 24)."""
from __future__ import annotations

import io
import os

import numpy as np
import pytest

from pyevolver.errors import CommandError
from pyevolver.model.surface import Surface
from pyevolver.commands import fresh
from pyevolver.session.core import Session

EXAMPLES = "/usr/share/doc/evolver/examples"
needs_examples = pytest.mark.skipif(not os.path.isdir(EXAMPLES),
                                    reason="evolver-doc examples not installed")

CUBE = """PARAMETER kk = 1
vertices
1 0 0 0
2 1 0 0
3 1 1 0
4 0 1 0
5 0 0 1
6 1 0 1
7 1 1 1
8 0 1 1
edges
1 1 2
2 2 3
3 3 4
4 4 1
5 5 6
6 6 7
7 7 8
8 8 5
9 1 5
10 2 6
11 3 7
12 4 8
faces
1 1 10 -5 -9 tension kk
2 2 11 -6 -10
3 3 12 -7 -11
4 4 9 -8 -12
5 -4 -3 -2 -1
6 5 6 7 8
bodies
1 1 2 3 4 5 6 volume 1
"""


@pytest.fixture
def session(tmp_path):
    p = tmp_path / "cube.fe"
    p.write_text(CUBE)
    return Session.load(str(p), out=io.StringIO(), err=io.StringIO())


@pytest.fixture
def count(monkeypatch):
    """The number of surface evaluations made since the fixture started."""
    calls = []
    real = Surface.evaluate

    def counted(self, *a, **k):
        calls.append(1)
        return real(self, *a, **k)
    monkeypatch.setattr(Surface, "evaluate", counted)
    return calls


def _exact(session):
    """The session's totals agree with a new evaluation of its surface."""
    t = session.surface.evaluate()
    assert session.totals.energy == t.energy
    assert np.array_equal(session.totals.volumes, t.volumes)


def test_remesh_commands_evaluate_once(session, count):
    for cmd in ("r", "u", "V", "printf \"%g\\n\", total_energy", "print total_area"):
        del count[:]
        session.run(cmd)
        flips = session.counts.get("equi", 1) if cmd == "u" else 1
        assert len(count) == (0 if cmd.startswith("print") or not flips else 1), cmd
        _exact(session)


def test_first_command_after_loading_evaluates_once(tmp_path, count):
    """A file with no read section: the load's evaluation is marked, so a
    first V (or r, u) evaluates only the surface it makes."""
    p = tmp_path / "plain.fe"
    p.write_text(CUBE)
    s = Session.load(str(p), out=io.StringIO(), err=io.StringIO())
    assert fresh.is_fresh(s)
    del count[:]
    s.run("V")
    assert len(count) == 1
    _exact(s)


def test_a_remesh_that_changes_nothing_does_not_evaluate(session, count):
    session.run("r")
    session.run("u")
    while session.counts.get("equi"):
        session.run("u")
    del count[:]
    session.run("u")                     # no flip: the surface object is the same
    assert session.counts["equi"] == 0 and not count
    _exact(session)
    session.run("set vertex[1] x x + 0.001")
    del count[:]
    session.run("u")                     # a new surface when it flips, else none
    assert len(count) == (1 if session.counts["equi"] else 0)
    _exact(session)


def test_g_ends_with_the_evaluation_of_its_last_move(session, count):
    session.run("g 2")
    session.run("print 1")
    del count[:]
    session.run("g 3")
    steps = len(count)                   # (the steps' own evaluations)
    del count[:]
    session.run("print 1")
    assert not count
    _exact(session)
    del count[:]                         # (_exact's own evaluation)
    session.run("g 1")
    assert len(count) <= steps           # no evaluation after the steps
    _exact(session)
    del count[:]
    session.run("g 0")                   # no step: nothing new to trust
    _exact(session)


def test_changes_in_place_are_seen(session, count):
    session.run("print 1")
    for cmd in ("set vertex[1] x 0.1", "set facet[2] tension 3", "kk := 2",
                "set body[1] target 1.5", "fix vertex[3]", "set vertex[2] z z + 0.01"):
        del count[:]
        session.run(cmd)
        assert count, cmd                     # the check evaluated again
        _exact(session)
        del count[:]
        session.run("print 2")                # and nothing changed since
        assert not count, cmd


def test_api_writes_between_commands(session):
    session.run("print 1")
    e0 = session.totals.energy
    session.surface.X[0, 0] += 0.25          # a user of the API, in place
    assert not fresh.is_fresh(session)
    session.run("print 1")
    assert session.totals.energy != e0
    _exact(session)


def test_failing_command_keeps_fresh_totals(session, count):
    session.run("r")
    t, X = session.totals, session.surface.X.copy()
    with pytest.raises(CommandError):
        session.run("set vertex[1] x 1/0")
    assert session.totals is t and np.array_equal(session.surface.X, X)
    assert fresh.is_fresh(session)
    del count[:]
    session.run("print 1")
    assert not count
    _exact(session)


def test_autorecalc_off_is_not_fresh(session):
    session.run("autorecalc off")
    session.run("set vertex[1] x 0.2")
    assert not fresh.is_fresh(session)


def test_fingerprint_parts():
    a = np.arange(6.0).reshape(2, 3)
    fp = fresh._fp(a, 1, {})
    b = a.copy()
    assert fresh._fp(b, 1, {}) == fp          # by content, not identity
    b[1, 2] = -1
    assert fresh._fp(b, 1, {}) != fp
    assert fresh._fp(a.T, 1, {}) != fp        # (shape and strides: a copy is taken)
    o = np.array([None, "x"], dtype=object)
    assert fresh._fp(o, 1, {}) == fresh._fp(o, 1, {})
    assert fresh._fp(np.float64(2.5), 1, {}) == 2.5
    assert fresh._fp({"a": [1, 2]}, 0, {})[0] == "id"      # beyond the depth: identity


@needs_examples
def test_example_after_r_u_V_matches_new_evaluation(count):
    s = Session.load(os.path.join(EXAMPLES, "catbody.fe"), out=io.StringIO(),
                     err=io.StringIO())
    s.run("g 3")
    for cmd in ("r", "g 2", "u", "V", "list vertices where id < 3"):
        s.run(cmd)
        _exact(s)
