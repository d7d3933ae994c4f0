"""Direct tests of pyevolver.session.core.Session: loading, running command
text, history, errors, the Python API values, refine/dump; numbers from the
reference Evolver run live."""
import io
import os

import numpy as np
import pytest

from pyevolver.errors import CommandError
from pyevolver.session.core import Session

from comparison import _same
from reference import numbers, run_reference
from tolerances import PRINTED, STEPS

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def session():
    return Session.load(CUBE, out=io.StringIO(), err=io.StringIO())


def test_run_many_commands_and_stop_on_error():
    s = session()
    s.run("aa := 1\nprint aa + 1\nprint nosuchname\naa := 5", stop_on_error=False)
    assert s.variables["aa"] == 5                    # went on after the error
    assert "nosuchname" in s.err.getvalue()
    assert s.out.getvalue().split() == ["2"]
    with pytest.raises(CommandError, match=r"script.cmd:3:"):
        s.run("aa := 1\nprint aa\nprint nosuchname\naa := 9", where="script.cmd")
    assert s.variables["aa"] == 1


def test_history_and_bang(evolver):
    """``!!``, ``!n``, ``!prefix`` and ``history`` print what the Evolver prints
    (the read section's commands are in the history too)."""
    script = "print 11\nprint 22\n!!\n!print 1\nhistory\n"
    ref = run_reference(evolver, CUBE, script)
    s = session()
    s.run(script)
    assert _same(s.out.getvalue().split("\n"), ref), (s.out.getvalue(), ref)
    assert s.command_history[-1][1] == "history"
    with pytest.raises(CommandError, match="not in history"):
        s.run("!99")
    with pytest.raises(CommandError, match="not found in history"):
        s.run("!nosuchprefix")


def test_refine_counts_and_area_match_reference(evolver):
    exprs = ["vertex_count", "edge_count", "facet_count", "total_area", "body[1].volume"]
    ref = numbers(evolver, CUBE, exprs)             # before refining
    s = session()
    assert [s.count("vertex"), s.count("edge"), s.count("facet")] == ref[:3]
    assert s.total_area == pytest.approx(ref[3], rel=PRINTED)
    lines = run_reference(evolver, CUBE, "r\n" + "".join(
        f'printf "RESULT %.17g\\n", {e}\n' for e in exprs))
    after = [float(l.split()[1]) for l in lines if l.startswith("RESULT")]
    s.refine(echo=False)
    assert [s.count("vertex"), s.count("edge"), s.count("facet")] == after[:3]
    assert s.count("vertex") - s.count("edge") + s.count("facet") == 2
    assert s.total_area == pytest.approx(6.0, rel=PRINTED)
    assert s.value("body[1].volume") == pytest.approx(after[4], rel=PRINTED)


def test_g_api_returns_energies(evolver):
    lines = run_reference(evolver, CUBE, "QUIETGO\ng 4\nprintf \"RESULT %.17g\\n\", total_energy\n")
    e4 = [float(l.split()[1]) for l in lines if l.startswith("RESULT")][0]
    s = session()
    s.run("quietgo")
    s.g(4)
    assert s.total_energy == pytest.approx(e4, rel=STEPS)
    assert len(s.history) == 4
    assert [h[1] for h in s.history][-1] == pytest.approx(e4, rel=STEPS)


def test_value_count_internal():
    s = session()
    assert s.value("body[1].volume") == pytest.approx(1.0, rel=PRINTED)
    assert s.value('"abc"') == "abc"
    assert s.internal("vertex_count") == s.count("vertex")
    with pytest.raises(CommandError, match="not one expression"):
        s.value("1; print 2")
    s.set_variable("zz", 4)
    assert s.value("zz * 2") == 8.0


def test_dump_and_reload(tmp_path):
    s = session()
    s.refine(echo=False)
    path = str(tmp_path / "cube.dmp")
    s.dump(path)
    assert s.out.getvalue().startswith(f"Dumping to {path}.")
    t = Session.load(path, out=io.StringIO(), err=io.StringIO())
    assert (t.count("vertex"), t.count("edge"), t.count("facet")) == \
        (s.count("vertex"), s.count("edge"), s.count("facet"))
    assert np.allclose(t.surface.X, s.surface.X, rtol=0, atol=1e-14)
    assert t.total_energy == pytest.approx(s.total_energy, rel=PRINTED)


def test_quiet_suppresses_notes_only():
    s = session()
    s.run("quiet")
    s.note("hidden\n")
    s.write("shown\n")
    s.write_err("err\n")
    assert s.out.getvalue() == "shown\n" and s.err.getvalue() == "err\n"


def test_steps_of_one_g_chain_their_evaluations_with_the_same_numbers():
    """``g 4`` starts each step from the previous step's evaluation (issue 24);
    four separate ``g 1`` evaluate afresh: the same coordinates bit for bit.
    Only the last step of the returned list keeps its arrays."""
    path = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")
    a = Session.load(path, out=io.StringIO())
    b = Session.load(path, out=io.StringIO())
    counts = {}
    for name, sess in (("a", a), ("b", b)):
        surf = sess.surface
        evaluate = surf.evaluate

        def counting(*args, _name=name, _evaluate=evaluate, **kw):
            counts[_name] = counts.get(_name, 0) + 1
            return _evaluate(*args, **kw)
        surf.evaluate = counting
    res = a.g(4)
    for _ in range(4):
        b.g(1)
    assert counts["b"] - counts["a"] == 3          # steps 2 to 4 start from the last
    assert np.array_equal(a.surface.X, b.surface.X)
    assert a.totals.energy == b.totals.energy
    assert res[0].totals is None and res[0].motion is None
    assert res[-1].totals is a.totals and res[-1].motion is not None
