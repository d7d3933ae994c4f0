"""Issue 6: the command language runs legacy scripts unchanged.

Every comparison runs evolver-nox-d live on the same input; the expected
output is never pasted in.  Exporter scripts shipped with the Evolver
(off.cmd, stl.cmd, ...) must write byte-identical files.
"""
import os

import pytest

from conftest import example
from reference import run_reference
from comparison import _run_both, _same, run_pyevolver

HERE = os.path.dirname(os.path.dirname(__file__))
MEMORY = ("Element memory", "Total data memory")


def _lines(lines):
    return [l for l in lines if l.strip() and not l.startswith(MEMORY)]


# (datafile, script in tests/data) run in both programs, compared line by line:
# language_procs.cmd — procedures, functions, locals, recursion, loops with
#   break/continue, :::=, arrays, runtime attributes, fix/unfix, histogram,
#   sprintf, element navigation, colours and show criteria;
# language_more.cmd — history and !!, quiet, REF's toggle wording,
#   Fixed/Unfixed and refine counts per command, define constraint at run
#   time, on_constraint by name, defined attributes in list, whole arrays
#   (vertex_normal, __x, edge_vector, {..} literals, dot products), a single =
#   in comparisons, a lone printf format, elliptic integrals, `eee length` in
#   aggregates, set gen.attr, valid_element, frontbody.
LANGUAGE_SCRIPTS = [("cube.fe", "language_procs.cmd"), ("mound.fe", "language_more.cmd")]


@pytest.mark.parametrize("datafile,script_name", LANGUAGE_SCRIPTS)
def test_language_script_matches_reference(evolver, tmp_path, datafile, script_name):
    with open(os.path.join(HERE, "data", script_name)) as fh:
        script = fh.read()
    ref = run_reference(evolver, example(datafile), script, cwd=str(tmp_path))
    code, out, err = run_pyevolver(example(datafile), script + "q\n", cwd=str(tmp_path))
    assert err == ""
    assert _same(_lines(out), _lines(ref)), (out, ref)


# exporter script -> command it defines; the output file is named after the command
EXPORTERS = [("off", "do_off"), ("stl", "stl"), ("dxf", "dxf"), ("obj", "obj"),
             ("obj", "obj_edge_lines"), ("ply", "ply"), ("povray", "povray"),
             ("povrays", "povrays"), ("vrml", "vrml"), ("vrml2", "vrml2"), ("x3d", "x3d"),
             ("wavefront", "wavefront"), ("wavefront", "wavefrontn"), ("offn", "offn"),
             ("off_show", "off_show"), ("rib", "rib"), ("jvx", "jvx"), ("iges", "iges"),
             ("iges114", "iges114"), ("iges128", "iges128"), ("iges136", "iges136"),
             ("iges144", "iges144"), ("ansys", "ansys"), ("ansurf", "ansurf"),
             ("polyfilm", "polyfilm"), ("coff", "coff"), ("save_view", "save_view"),
             ("maya", "maya"), ("maya1", "maya1"), ("collada", "collada"),
             ("dxf_thick", "dxf_thick")]
# lines that hold the time of the run (date_and_time)
TIMESTAMPED = ("// Date:", "    <created>", "    <modified>")


def _read(path):
    with open(path, "rb") as fh:
        return [l for l in fh.read().split(b"\n") if not l.startswith(
            tuple(t.encode() for t in TIMESTAMPED))]


@pytest.mark.parametrize("datafile", ["cube.fe", "mound.fe"])
def test_exporter_scripts_write_the_same_files(evolver, datafile, tmp_path):
    script = "".join(f'read "{f}.cmd"\n{cmd} >>> "out_{cmd}"\n' for f, cmd in EXPORTERS)
    dirs, ref, out, err = _run_both(evolver, example(datafile), script, tmp_path)
    assert err == ""
    for _, cmd in EXPORTERS:
        a = dirs["ref"] / f"out_{cmd}"
        b = dirs["ours"] / f"out_{cmd}"
        assert a.exists() and b.exists(), cmd
        assert a.stat().st_size > 0, cmd
        assert _read(a) == _read(b), cmd


def test_colouring_scripts_match_reference(evolver, tmp_path):
    """equi.cmd (edges failing the Delaunay test), strips.cmd's three strip
    builders, and >> appending versus >>> overwriting."""
    script = ('read "equi.cmd"\nshowequi\nread "strips.cmd"\nstrips\nstrips2\nstrips3\n'
              'foreach facet ff do printf "%d ", ff.color >> "colors"\n'
              'print 1 >> "colors"\nprint 2 >>> "over"\nprint 3 >>> "over"\n'
              'r\nshowequi\nstrips3\n')
    dirs, ref, out, err = _run_both(evolver, example("cube.fe"), script, tmp_path)
    assert err == ""
    assert _same(_lines(out), _lines(ref)), (out, ref)
    for name in ("colors", "over"):
        assert _read(dirs["ref"] / name) == _read(dirs["ours"] / name), name


def test_catbody_adjust_procedure(evolver, tmp_path):
    """catbody.fe's own procedures: gogo, then adjust (a for loop of
    hessians chasing zero pressure).  The pressures agree until they reach
    round-off (the last lines are noise in both programs)."""
    script = "gogo\nadjust\n"
    ref = run_reference(evolver, example("catbody.fe"), script, cwd=str(tmp_path), timeout=120)
    code, out, err = run_pyevolver(example("catbody.fe"), script + "q\n", cwd=str(tmp_path))
    assert err == ""
    # every g and hessian line: area and energy within 1e-9 (the g tolerance
    # of the evolve issue; measured 1e-14), scales to the printed digits
    gr = [l.split() for l in ref if "area:" in l]
    go = [l.split() for l in out if "area:" in l]
    assert len(gr) == len(go) == 80
    for a, b in zip(gr, go):
        assert a[0] == b[0] and len(a) == len(b)
        for k in (2, 4):
            assert abs(float(a[k]) - float(b[k])) <= 1e-9 * abs(float(a[k])), (a, b)
        if len(a) > 5:
            assert a[6] == b[6], (a, b)
    pr = [l.split() for l in ref if l.startswith("Pressure")]
    po = [l.split() for l in out if l.startswith("Pressure")]
    assert len(pr) == len(po) == 20
    for a, b in zip(pr[:12], po[:12]):        # beyond ~1e-9 both are round-off
        for x, y in ((a[1], b[1]), (a[3], b[3]), (a[5], b[5])):
            assert abs(float(x) - float(y)) <= 2e-4 * abs(float(x)) + 1e-12, (a, b)


def test_column_force_procedures(evolver, tmp_path):
    """column.fe's do_yforce/do_zforce (set vertex y y+dy*z/zh; recalc;
    central differences of total_energy)."""
    script = "u\ng 5\nr\ng 5\ndo_yforce\ndo_zforce\n"
    ref = run_reference(evolver, example("column.fe"), script, cwd=str(tmp_path), timeout=120)
    code, out, err = run_pyevolver(example("column.fe"), script + "q\n", cwd=str(tmp_path))
    assert err == ""
    fr = [float(l.split()[-1]) for l in ref if "force:" in l]
    fo = [float(l.split()[-1]) for l in out if "force:" in l]
    assert len(fr) == len(fo) == 2
    for a, b in zip(fr, fo):
        assert abs(a - b) <= 1e-8 * abs(a)


# ---------------------------------------------------------------------------
# refusals and errors (no reference needed: these are pyevolver's messages)


def _session():
    import io
    from pyevolver import Session
    out, err = io.StringIO(), io.StringIO()
    return Session.load(example("cube.fe"), out=out, err=err), out, err


@pytest.mark.parametrize("cmd, word", [
    ('print 1 | "cat"', "piping output"),
    ('system "ls"', "system"),
    ('shell', "shell"),
    ('dissolve edge[1]', "dissolve"),
    ('permload "x.fe"', "permload"),
    ('define boundary bb parameters 1 x1: p1', "define boundary"),
    ('list topinfo', "list topinfo"),
])
def test_refused_by_name(cmd, word):
    from pyevolver.errors import PyEvolverError
    s, out, err = _session()
    with pytest.raises(PyEvolverError) as exc:
        s.run(cmd)
    assert word in str(exc.value)


@pytest.mark.parametrize("cmd, text", [
    ("procedure pq(real aa) { print aa }\npq(1, 2)", "needs 1 argument"),
    ("function real fz(real aa) { local bb; bb := aa }\nprint fz(1)", "without 'return"),
    ("function real fr(real aa) { return fr(aa) }\nprint fr(1)", "too deep"),
    ('read "no_such_file.cmd"', "cannot find file"),
    ("define arr2 real[2]\narr2[3] := 1", "outside 1..2"),
    ("aa := { printf \"x\\n\"; abort }\naa", "aborted"),
    ("r :::= 3", "syntax error"),
])
def test_errors_name_the_problem(cmd, text):
    from pyevolver.errors import PyEvolverError
    s, out, err = _session()
    with pytest.raises(PyEvolverError) as exc:
        s.run(cmd)
    assert text in str(exc.value)


def test_failing_procedure_leaves_surface():
    import numpy as np
    s, out, err = _session()
    X = s.surface.X.copy()
    s.run("procedure spoil(real dd) { set vertex x x+dd; print nosuchvariable }")
    with pytest.raises(Exception):
        s.run("spoil(0.5)")
    assert np.array_equal(s.surface.X, X)
    assert "spoil" in s.commands


def test_read_stops_at_first_error(tmp_path):
    s, out, err = _session()
    p = tmp_path / "bad.cmd"
    p.write_text('aa := 1\nprint nosuch\naa := 2\n')
    s.run(f'read "{p}"')
    assert s.variables["aa"] == 1.0
    assert "nosuch" in err.getvalue()
