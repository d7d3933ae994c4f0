"""``dump`` writes a datafile that pyevolver and the Evolver load back to the
same surface; ``load`` / ``replace_load`` replace the session's surface.

The expected numbers are those of the surface before dumping (energy, area,
body volumes, quantity values); the reloaded surface is measured in
pyevolver and, live, in evolver-nox-d.  Continuing with ``g 5`` after the
reload prints what continuing without the dump prints.
"""
import io
import os
import re

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.commands.interpreter import parse_command
from pyevolver.datafile.writer import dump, expr_text
from pyevolver.expr import nodes as N
from pyevolver.errors import PyEvolverError

from conftest import example
from reference import numbers, run_reference

CHECKS = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data", "checks")

CASES = [
    (example("cube.fe"), "r; g 5"),
    (example("mound.fe"), "r; g 5"),
    (example("catbody.fe"), "r; g 5"),
    (example("cat.fe"), "r; g 5"),
    (example("quad.fe"), "r; g 5"),
    (example("tankex.fe"), "g 5"),
    (example("column.fe"), "g 5"),
    (example("qmound.fe"), "g 5"),
    (example("sphere.fe"), "r; g 5"),
    (example("twointor.fe"), "r; g 5"),
    (os.path.join(CHECKS, "vesicle.fe"), "g 3"),
    (os.path.join(CHECKS, "blob.fe"), "g 3"),
    (os.path.join(CHECKS, "blob_legacy.fe"), "g 3"),
    (os.path.join(CHECKS, "icosa_curv.fe"), "g 3"),
]


def _session(path, cmds=""):
    s = Session.load(path, out=io.StringIO(), err=io.StringIO())
    if cmds:
        s.run(cmds)
    return s


def _measure(s):
    t = s.surface.evaluate()
    vals = {"total_energy": t.energy, "total_area": t.total_area}
    for k, v in enumerate(np.atleast_1d(t.volumes) if s.surface.bodies.n else []):
        vals[f"body[{k + 1}].volume"] = float(v)
    for name, q in s.surface.quantities.items():
        if q.kind != "instance":
            vals[f"{name}.value"] = float(t.quantity_values[name])
    return vals


def _close(a, b, tol=1e-12):
    return abs(a - b) <= tol * max(1.0, abs(a), abs(b))


_PROGRESS = re.compile(r"^\s*\d+\.\s+area:\s*(\S+)\s+energy:\s*(\S+)")


def _progress(text):
    return [(float(m.group(1)), float(m.group(2)))
            for m in map(_PROGRESS.match, text.splitlines()) if m]


def _continue(s, cmds="g 5"):
    s.out = io.StringIO()
    s.run(cmds)
    return _progress(s.out.getvalue())


@pytest.mark.parametrize("path,cmds", CASES, ids=[os.path.basename(c[0]) for c in CASES])
def test_dump_round_trip(evolver, path, cmds, tmp_path):
    s = _session(path, cmds)
    want = _measure(s)
    out = str(tmp_path / "dumped.fe")
    dump(s, out)
    # pyevolver loads the same surface
    s2 = _session(out)
    got = _measure(s2)
    assert got.keys() == want.keys()
    for k in want:
        assert _close(want[k], got[k]), (k, want[k], got[k])
    assert s2.surface.nv == s.surface.nv and s2.surface.ne == s.surface.ne \
        and s2.surface.nf == s.surface.nf
    np.testing.assert_array_equal(s2.surface.X, s.surface.X)
    # so does the Evolver, with the same element counts
    counts = {"vertex_count": s.surface.nv, "edge_count": s.surface.ne,
              "facet_count": s.surface.nf, "body_count": s.surface.bodies.n}
    ref = numbers(evolver, out, list(want) + list(counts), cwd=str(tmp_path))
    for k, r in zip(want, ref):
        assert _close(want[k], r), (k, want[k], r)
    assert ref[len(want):] == list(counts.values()), (counts, ref[len(want):])
    # continuing after the reload prints what continuing without it prints
    a = _continue(s)
    b = _continue(s2)
    assert len(a) == len(b) == 5
    for (aa, ae), (ba, be) in zip(a, b):
        assert _close(aa, ba, 1e-9) and _close(ae, be, 1e-9), (a, b)


def test_reference_continues_from_dump(evolver, tmp_path):
    """The Evolver evolving our dump prints what pyevolver prints."""
    s = _session(example("cube.fe"), "r; g 5")
    out = str(tmp_path / "cube_dump.fe")
    s.run(f'dump "{out}"')
    ours = _continue(_session(out), "g 3")
    ref = _progress("\n".join(run_reference(evolver, out, "g 3", cwd=str(tmp_path))))
    assert len(ours) == len(ref) == 3
    for (oa, oe), (ra, re_) in zip(ours, ref):
        assert _close(oa, ra, 1e-9) and _close(oe, re_, 1e-9), (ours, ref)


def test_dump_command_default_name(tmp_path):
    src = tmp_path / "cube.fe"
    src.write_text(open(example("cube.fe"), encoding="latin-1").read(), encoding="latin-1")
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        s = _session("cube.fe", "g 2")
        s.out = io.StringIO()
        s.run("dump")
        assert s.out.getvalue() == "Dumping to cube.fe.dmp.\n"
        assert _close(_measure(_session("cube.fe.dmp"))["total_energy"],
                      _measure(s)["total_energy"])
    finally:
        os.chdir(cwd)


def test_dump_refuses_what_it_cannot_write(tmp_path):
    s = _session(example("cube.fe"))
    s.surface.vattr["mystery"] = np.zeros(s.surface.nv)
    out = tmp_path / "x.fe"
    with pytest.raises(PyEvolverError, match="dump: the vertex attribute 'mystery'"):
        s.run(f'dump "{out}"')
    assert not out.exists()


def test_replace_load_keeps_variables_and_continues(evolver, tmp_path):
    s = _session(example("cube.fe"), "r; g 5")
    out = str(tmp_path / "cube_r.fe")
    s.run(f'dump "{out}"')
    s2 = _session(example("cube.fe"))
    s2.run("myvar := 7")
    s2.out = io.StringIO()
    s2.run(f'{{ replace_load "{out}"; g 2 }}')
    assert s2.variables["myvar"] == 7
    assert s2.surface.nf == s.surface.nf
    ours = _progress(s2.out.getvalue())
    ref = _progress("\n".join(run_reference(evolver, example("cube.fe"),
                                            f'{{ replace_load "{out}"; g 2 }}',
                                            cwd=str(tmp_path))))
    assert len(ours) == len(ref) == 2
    for (oa, oe), (ra, re_) in zip(ours, ref):
        assert _close(oa, ra, 1e-9) and _close(oe, re_, 1e-9), (ours, ref)


def test_load_replaces_and_ends_the_command(tmp_path):
    s = _session(example("cube.fe"), "r")
    out = str(tmp_path / "cube_r.fe")
    s.run(f'dump "{out}"')
    s2 = _session(example("mound.fe"))
    s2.run("myvar := 7")
    s2.out = io.StringIO()
    s2.run(f'{{ load "{out}"; g 2 }}')
    assert "area:" not in s2.out.getvalue()          # the command ended at load
    assert "myvar" not in s2.variables
    assert s2.surface.nf == s.surface.nf


def test_failing_load_leaves_the_surface(tmp_path):
    s = _session(example("cube.fe"), "g 2")
    X = s.surface.X.copy()
    for cmd in ("load", "replace_load"):
        with pytest.raises(PyEvolverError, match=cmd):
            s.run(f'{cmd} "{tmp_path}/missing.fe"')
        assert s.surface.X is not None and np.array_equal(s.surface.X, X)
    with pytest.raises(PyEvolverError, match="replace_load"):
        s2 = _session(example("qmound.fe"))
        s2.run(f'replace_load "{example("cube.fe")}"')


def test_addload_example_matches_reference(evolver, tmp_path):
    """addload_example.fe's read section addloads itself eight times."""
    f = example("addload_example.fe")
    s = _session(f)
    t = s.surface.evaluate()
    exprs = ["vertex_count", "edge_count", "facet_count", "body_count", "total_energy",
             "total_area"] + [f"body[{k}].volume" for k in range(1, 10)]
    ref = numbers(evolver, f, exprs, cwd=str(tmp_path))
    ours = [s.surface.nv, s.surface.ne, s.surface.nf, s.surface.bodies.n, t.energy,
            t.total_area] + list(t.volumes)
    for k, a, b in zip(exprs, ours, ref):
        assert _close(a, b), (k, a, b)
    got = _continue(s, "re; g 5")
    want = _progress("\n".join(run_reference(evolver, f, "re; g 5", cwd=str(tmp_path))))
    assert len(got) == len(want) == 5
    for (oa, oe), (ra, re_) in zip(got, want):
        assert _close(oa, ra, 1e-9) and _close(oe, re_, 1e-9), (got, want)


def test_addload_two_cubes(evolver, tmp_path):
    f = example("cube.fe")
    cmds = f'addload "{f}"; set vertex x x+2 where id > 8; recalc'
    s = _session(f, cmds)
    t = s.surface.evaluate()
    exprs = ["vertex_count", "edge_count", "facet_count", "body_count", "total_energy",
             "body[1].volume", "body[2].volume"]
    ours = [s.surface.nv, s.surface.ne, s.surface.nf, s.surface.bodies.n, t.energy] + \
        list(t.volumes)
    lines = run_reference(evolver, f, cmds + "\n" + "".join(
        f'printf "RESULT %.17g\\n", {e}\n' for e in exprs), cwd=str(tmp_path))
    ref = [float(ln.split()[1]) for ln in lines if ln.startswith("RESULT")]
    assert len(ref) == len(exprs), lines
    for k, a, b in zip(exprs, ours, ref):
        assert _close(a, b), (k, a, b)


@pytest.mark.parametrize("text", [
    "-x^2", "2^-y", "x-(y-z)", "(x/y)/z", "x/(y*z)", "-(x+y)*z", "x^y^2", "(x^y)^2",
    "x % 3 + y imod 2", "x > y ? x - y : (y < 0 ? -y : y*2)", "!(x > 1) && y < 2 || z == 3",
    "sqrt(x^2 + y^2) - 1e-17*atan2(y, x)", "-(-x)", "x*-1.5"])
def test_formula_text_round_trip(text):
    def expr_of(t):
        return parse_command(f"print {t}")[1][0][1]
    node = expr_of(text)
    again = expr_of(expr_text(node))
    rng = np.random.default_rng(3)
    for _ in range(20):
        env = N.MapEnv({k: float(v) for k, v in zip("xyz", rng.uniform(-3, 3, 3))})
        a, b = node.ev(env), again.ev(env)
        assert a == b or (np.isnan(a) and np.isnan(b)), (text, expr_text(node))
