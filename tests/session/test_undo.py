"""Direct tests of pyevolver.session.undo: snapshot before a command,
restore when it fails; a failing command leaves coordinates and energy as
they were (the energy the reference Evolver computes for the untouched
surface)."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.errors import CommandError
from pyevolver.session import undo

from comparison import consistent
from reference import numbers, run_reference
from tolerances import PRINTED, STEPS

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def session():
    return Session.load(CUBE, out=io.StringIO(), err=io.StringIO())


def test_snapshot_restore_directly():
    s = session()
    s.run("aa := 1")
    X = s.surface.X.copy()
    snap = undo.snapshot(s)
    assert snap[6] is not s.surface.X and np.array_equal(snap[6], X)   # a copy
    s.surface.X[0] += 0.5
    s.variables["aa"] = 7
    s.variables["bb"] = 2
    s.toggles["quiet"] = 1
    s.settings["scale"] = 99.0
    s.surface.bodies.target[0] = 3.0
    undo.restore(s, snap)
    assert np.array_equal(s.surface.X, X)
    assert s.variables["aa"] == 1 and "bb" not in s.variables
    assert "quiet" not in s.toggles and s.settings["scale"] != 99.0
    assert s.surface.bodies.target[0] == 1.0


def test_failing_command_leaves_x_and_energy(evolver):
    e_ref, v_ref = numbers(evolver, CUBE, ["total_energy", "body[1].volume"])
    s = session()
    X = s.surface.X.copy()
    for bad in ("vertex[1].x := 0.3; set vertex z z*2; print nosuchname",
                "g 3; r; abort",
                "body[1].target := 2; vertex[2].y := 5; saddle"):
        with pytest.raises(CommandError):
            s.run(bad)
        assert np.array_equal(s.surface.X, X)
        assert s.total_energy == pytest.approx(e_ref, rel=PRINTED)
        assert s.value("body[1].volume") == pytest.approx(v_ref, rel=PRINTED)
        assert s.value("body[1].target") == 1.0
        consistent(s.surface)


def test_restored_session_goes_on_like_the_evolver(evolver):
    """After a failed refine + iterate, g 3 gives the Evolver's energy of g 3."""
    lines = run_reference(evolver, CUBE,
                          "QUIETGO\ng 3\nprintf \"RESULT %.17g\\n\", total_energy\n")
    e3 = [float(l.split()[1]) for l in lines if l.startswith("RESULT")][0]
    s = session()
    s.run("quietgo")
    with pytest.raises(CommandError):
        s.run("r; g 2; print nosuchname")
    assert s.count("facet") == numbers(evolver, CUBE, ["facet_count"])[0]
    s.run("g 3")
    assert s.total_energy == pytest.approx(e3, rel=STEPS)


def test_failing_command_rolls_back_history_counters_and_random_state():
    """Everything a command changes goes back with the surface when it
    fails: the g history, the iteration counter, counts, the random stream."""
    import io as _io
    import os as _os
    from pyevolver.session.core import Session as _S
    cube = _os.path.join(_os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")
    s = _S.load(cube, out=_io.StringIO(), err=_io.StringIO())
    s.run("g 2")
    hist, it = list(s.history), s.iteration_counter
    r0 = s.rng.bit_generator.state
    try:
        s.run("g 3; aa := random; print vertex[999].x")
    except Exception:
        pass
    else:
        raise AssertionError("the command should fail")
    assert s.history == hist and s.iteration_counter == it
    assert s.rng.bit_generator.state == r0


def test_random_generator_made_when_first_used_and_rolled_back_to_unmade():
    """The generator of ``random`` (seed 1) is made at its first draw, not at
    the load; a failing command that made it leaves it unmade, so the next
    draw is still the seed's first number."""
    s = session()
    assert s._rng is None
    first = np.random.default_rng(1).random()
    with pytest.raises(CommandError):
        s.run('{ printf "%.17g\\n", random; set vertex[99] x 1 }')
    assert s._rng is None
    s.out = io.StringIO()
    s.run('printf "%.17g\\n", random')
    assert float(s.out.getvalue()) == first and s._rng is not None
