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


# The counters (notch_count, edge_delete_count, ..., where_count): REF 2.70
# keeps the last command's count for n and t, adds up within a command (and
# onto l's count) the ones it reports when the command ends ("Edges refined:
# 12") and starts them again after the report; w counts into
# facet_delete_count.  Each script prints labelled values in both programs.
COUNTER_SCRIPTS = {
    "notch": "g 5\nn 0.3\nprintf \"A %d\\n\", notch_count\nn 0.3; printf \"B %d\\n\", notch_count\n"
             "n 0.3; n 0.3; printf \"C %d\\n\", notch_count\nprintf \"D %d\\n\", notch_count\n",
    "refine": "refine edges where id < 5; printf \"A %d\\n\", edge_refine_count; "
              "refine edges where id < 9; printf \"B %d\\n\", edge_refine_count\n"
              "printf \"C %d %d\\n\", edge_refine_count, refine_count\n"
              "refine edges where id < 3\nprintf \"D %d %d\\n\", edge_refine_count, refine_count\n"
              "l 0.4\nprintf \"E %d %d\\n\", edge_refine_count, refine_count\n"
              "refine edges where id < 4\nprintf \"F %d %d\\n\", edge_refine_count, refine_count\n"
              "refine facets where id < 3; refine facets where id < 2\n"
              "printf \"G %d\\n\", facet_refine_count\n",
    "delete": "r\ng 5\nn 0.3\nt 0.02\nprintf \"A %d\\n\", edge_delete_count\n"
              "t 0.04\nprintf \"B %d %d\\n\", edge_delete_count, delete_count\n"
              "w 0.0005\nprintf \"C %d %d %d\\n\", edge_delete_count, facet_delete_count, "
              "delete_count\n",
    "where": "list edges where id < 10\nprintf \"A %d\\n\", where_count\n"
             "foreach vertex vv where z > 0.5 do print vv.id\nprintf \"B %d\\n\", where_count\n"
             "set facet color red where id < 4\nprintf \"C %d\\n\", where_count\n"
             "print sum(edge where length > 0.3, 1)\nprintf \"D %d\\n\", where_count\n"
             "list vertices where id > 100\nprintf \"E %d\\n\", where_count\n",
}


@pytest.mark.parametrize("name", sorted(COUNTER_SCRIPTS))
def test_counters_match_reference(evolver, name, tmp_path):
    script = COUNTER_SCRIPTS[name]
    ref = run_reference(evolver, example("cube.fe"), script, cwd=str(tmp_path))
    code, out, err = run_pyevolver(example("cube.fe"), script + "q\n", cwd=str(tmp_path))
    assert code == 0 and err == "", err
    def labelled(text):
        lines = text.splitlines() if isinstance(text, str) else text
        return [ln.strip() for ln in lines if re.match(r"^[A-G] ", ln.strip())]

    assert labelled(ref) and labelled(out) == labelled(ref)
