"""The command language prints what evolver-nox-d prints (reference check 18,
run live through both programs)."""
import os
import re

import pytest

from conftest import example
from comparison import _same, run_pyevolver
from reference import run_reference

# reference check 18 (copied from shared/reference-checks/scripts)
SCRIPT18 = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data", "18_language.cmd")
ROOT = os.path.join(os.path.dirname(os.path.dirname(__file__)), "..")


def test_check18_language(evolver, tmp_path):
    with open(SCRIPT18, newline="") as fh:
        script = fh.read().replace("\r\n", "\n")
    script = script.rsplit("q\nq", 1)[0]           # both programs get the same commands
    ref = run_reference(evolver, example("cube.fe"), script, cwd=str(tmp_path))
    code, out, err = run_pyevolver(example("cube.fe"), script + "q\n", cwd=str(tmp_path))
    assert code == 0, err
    assert err == ""
    assert _same(out, ref), (out, ref)


@pytest.mark.parametrize("cmd", [
    "print total_energy", "print total_area", "print 2^10", "print -7 % 3", "print 7 idiv 2",
    "print 3 -5", "printf \"%d %x %o %5.2e|%-6s|\\n\", -42.9, 255, 8, 12345.678, \"ab\"",
    "print sqrt(2)*pi", "print atan2(1, -1)", "print (1 < 2) && (3 > 4) || !0",
    "print body[1].volume", "print facet[7].area", "print edge[13].length",
    "print vertex[13].z", "print sum(edge, length)", "print min(vertex, x - 2*y)",
    "print count(facet where area > 0.2, 1)", "v",
    "foreach facet ff where ff.id < 4 do printf \"%d %g\\n\", ff.id, ff.area",
    "aa := 1; bb := 0; while aa < 100 do { aa *= 3; bb += 1 }; print bb; print aa",
    "list facet[2]", "list edge[20]", "list vertex[9]",
])
def test_commands_match_reference(evolver, cmd, tmp_path):
    ref = run_reference(evolver, example("cube.fe"), cmd, cwd=str(tmp_path))
    code, out, err = run_pyevolver(example("cube.fe"), cmd + "\nq\n", cwd=str(tmp_path))
    assert err == ""
    assert _same(out, ref), (out, ref)


def test_quantities_v_report(evolver, tmp_path):
    ref = run_reference(evolver, example("qmound.fe"), "v", cwd=str(tmp_path))
    code, out, err = run_pyevolver(example("qmound.fe"), "v\nq\n", cwd=str(tmp_path))
    assert _same(out, ref), (out, ref)


READ_SECTION_FILES = ["100grain", "addload_example", "cat", "catbody", "catman", "column",
                      "crystal", "cube", "knotty", "metric", "mound", "mylarcube", "octa", "phelanc",
                      "popstr", "qmound", "quad", "quadm", "relaxed", "simplex3", "slidestr",
                      "sphere", "symtest", "tankex", "twointor"]


@pytest.mark.parametrize("name", READ_SECTION_FILES)
def test_read_sections_of_examples_parse(evolver, name):
    """Every command in the read sections of the shipped examples parses
    (mylarcube.fe's array attributes and `r :::=` included)."""
    from pyevolver.commands.interpreter import split_commands, parse_command
    from pyevolver.datafile.preprocess import preprocess, read_source
    path = example(name + ".fe")
    sections, _ = preprocess(read_source(path), path)
    reads = [s for s in sections if s.kind == "read"]
    for sec in reads:
        for chunk, ln in split_commands(sec.text):
            parse_command(chunk, path, sec.line + ln)


# Tier 1 and 2 examples of the spec, and knotty.fe (its knot energies)
TIER12 = ["cube", "mound", "catbody", "cat", "catman", "twointor", "column", "quad", "sphere",
          "qmound", "tankex", "octa", "phelanc", "addload_example", "slidestr", "popstr",
          "100grain", "knotty"]


@pytest.mark.parametrize("name", TIER12)
def test_read_sections_run(evolver, name, tmp_path):
    """The read section of each Tier 1/2 example runs without an error and
    leaves the surface REF has after it (energy, counts, commands defined)."""
    import io
    from pyevolver import Session
    exprs = ["total_energy", "vertex_count", "edge_count", "facet_count", "body_count"]
    script = "".join(f'printf "%.15g\\n", {e}\n' for e in exprs)
    ref = [float(x) for x in run_reference(evolver, example(name + ".fe"), script,
                                            cwd=str(tmp_path))
           if re.fullmatch(r"\s*[-+]?[\d.]+(?:e[-+]?\d+)?\s*", x)]   # (not r's report)
    out, err = io.StringIO(), io.StringIO()
    s = Session.load(example(name + ".fe"), out=out, err=err)
    assert err.getvalue() == ""
    from pyevolver.expr.nodes import Var
    ours = [s.interp.value(Var(e)) for e in exprs]
    assert len(ref) == len(ours)
    for a, b in zip(ours, ref):
        assert abs(a - b) <= 1e-12 * max(1.0, abs(b)), (name, ours, ref)
