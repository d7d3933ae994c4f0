"""The command language of scripts and read sections: aggregates over
nested generators, pi and e, adjacent string literals, quantity and method
instance attributes, the manual's set / unset forms.

Each script runs in evolver-nox-d and in pyevolver; the printed lines must
agree (numbers to 1e-10).  Nothing printed by pyevolver is pasted in.
"""
import io
import os

import numpy as np
import pytest

from conftest import example
from reference import run_reference
from comparison import _same, run_pyevolver

import pyevolver
from pyevolver.errors import CommandError

AGGREGATES = """g 2
print sum(edge ee where ee.id < 5, sum(ee.facet, area))
print max(facet ff, count(ff.edge ee where ee.length > 0.3, 1))
print count(facet[1].edge where length > 0.3, 1)
print sum(edge[9].facet, area)
print max(vertex vv where vv.z > 0.5, vv.x)
print min(vertex vv where vv.z > 0.5, vv.x)
print avg(vertex where z > 100, x)
print max(vertex where z > 100, x)
print min(vertex where z > 100, x)
print sum(vertex where z > 100, x)
print count(vertex where z > 100, x)
print sum(vertex[1].edge ee, ee.length)
print max(vertex vv, min(vv.facet, area))
print sum(body bb, sum(bb.facet ff, ff.area))
print count(edge ee where max(ee.facet, area) > 0.2, 1)
print max(edge ee, max(ee.vertex, z))
print avg(edge, length)*count(edge, 1) - sum(edge, length)
print pi
print e
print pi*e
print e + 1
print exp(1) - e
print 2*pi - pi*2
printf "a" "b\\n"
printf "%s-%s\\n", "x" "y", "z"
print "abc" "def"
printf "%g %s\\n", pi, "x" "y" "z"
"""

SETS = """g 2
set facet color red where id < 3
print facet[1].color
set facet[2] color green
print facet[2].color
set facet frontcolor blue where id == 3
print facet[3].frontcolor
print facet[3].backcolor
set facet backcolor yellow where id == 3
print facet[3].backcolor
set edge color red where id == 1
print edge[1].color
set facet[1].edge color blue
print edge[1].color
set vertex[1].facet color magenta
print facet[1].color
set facet ff color ff.id imod 15 where id < 4
print facet[3].color
set edge tension 0.5 where id < 3
print edge[1].tension
recalc
print total_energy
set facet tension 2 where id == 1
recalc
print total_energy
set body target 1.5
print body[1].target
print body[1].volfixed
unset body target
print body[1].target
print body[1].volfixed
set body pressure 2
print body[1].pressure
unset body pressure
print body[1].pressure
set body target 1
set body density 3
print body[1].density
set body volconst 0.1
print body[1].volconst
set body[1].volconst 0.2
print body[1].volconst
set vertex x x*1.1 where id < 3
print vertex[2].x
set vertex vv z vv.z+0.01 where vv.id == 8
print vertex[8].z
set vertex[8] z 1.2
print vertex[8].z
set vertex[1] fixed
print vertex[1].fixed
unset vertex[1] fixed
print vertex[1].fixed
set edge[1] no_refine
print edge[1].no_refine
unset edge[1] no_refine
print edge[1].no_refine
set facet[1] no_refine
print facet[1].no_refine
set facet[1] fixed
print facet[1].fixed
set facet opacity 0.5 where id == 2
print facet[2].opacity
print facet[1].opacity
set facet no_display where id < 3
print facet[2].no_display
unset facet nodisplay
print facet[2].nodisplay
set edge no_transform
print edge[3].no_transform
set facet no_transform
set body centerofmass
print body[1].centerofmass
set vertex bare where id == 5
print vertex[5].bare
unset vertex bare
print vertex[5].bare
set edge bare where id == 9
print edge[9].bare
set facet orientation 1 where id == 1
set background red
set background 3
print facet[1].orientation
g 2
"""

QUANTITIES = """g 3
print vol.value
print vol.target
print vol.modulus
print vol.pressure
print vol.tolerance
print vol.fixed
print vol.energy
print vol.info_only
print vol.conserved
vol.target := 1.1
print vol.target
set vol target 1.2
print vol.target
set vol tolerance 0.001
print vol.tolerance
set vol info_only
print vol.fixed
print vol.info_only
print vol.target
g
set vol fixed
print vol.target
print vol.fixed
set vol energy
print vol.energy
set vol modulus 0.5
print vol.modulus
set vol conserved
print vol.conserved
set vol fixed
print facet[1].vol
print count(facet where on_quantity vol, 1)
set vertices constraint 1 where id == 5
print vertex[5].on_constraint 1
print vertex[5].z
unset vertices constraint 1 where id == 5
print vertex[5].on_constraint 1
"""

INSTANCES = """g 2
print aa.value
print ll.value
print mix.value
print aa.modulus
set aa modulus 2
print aa.modulus
aa.modulus := 3
print aa.modulus
recalc
print aa.value
print mix.value
print facet[1].aa
print facet[3].aa
print facet[1].on_method_instance aa
print facet[3].on_method_instance aa
print edge[1].ll
print edge[1].on_method_instance ll
print count(facet where on_method_instance aa, 1)
print mix.info_only
set aa modulus 1
unset facet aa where id == 1
recalc
print aa.value
print facet[1].aa
set facet[1] aa
recalc
print aa.value
set facet method_instance aa where id == 5
recalc
print aa.value
print facet[5].on_method_instance aa
unset facet ll
unset edge ll where id == 1
set edge ll where id == 1
recalc
print ll.value
print mix.value
"""

DENSITY = """gravity_constant := 2
recalc
print total_energy
unset body density
print body[1].density
recalc
print total_energy
g 2
"""

BOUNDARIES = """g 2
print vertex[2].p[1]
print vertex[2].p
print vertex[13].p
set vertex[3] p[1] 2.2
print vertex[3].x
set vertex p1 p1+0.1 where id == 2
print vertex[2].x
print vertex[2].y
print vertex[2].on_boundary 1
unset vertex boundary 1 where id == 2
print vertex[2].on_boundary 1
print vertex[2].x
unset edge boundary 1 where id == 1
print edge[1].on_boundary 1
recalc
print total_energy
"""


def _instance_file(tmp_path):
    """cube.fe with two method instances and a FUNCTION quantity of them."""
    with open(example("cube.fe")) as fh:
        src = fh.read()
    head, rest = src.split("vertices", 1)
    head += ("\nmethod_instance aa method facet_area\n"
             "method_instance ll method edge_length global\n"
             "quantity mix info_only function aa.value + 2*ll.value\n\n")
    rest = rest.replace("1   1 10 -5  -9", "1   1 10 -5  -9 aa").replace(
        "2   2 11 -6 -10", "2   2 11 -6 -10 aa")
    path = tmp_path / "cubeq.fe"
    path.write_text(head + "vertices" + rest)
    return str(path)


@pytest.mark.parametrize("datafile,script", [
    ("cube.fe", AGGREGATES), ("cube.fe", SETS), ("qmound.fe", QUANTITIES),
    ("instances", INSTANCES), ("cat.fe", BOUNDARIES), ("mound.fe", DENSITY)],
    ids=["aggregates", "sets", "quantities", "instances", "boundaries", "density"])
def test_language_matches_reference(evolver, tmp_path, datafile, script):
    path = _instance_file(tmp_path) if datafile == "instances" else example(datafile)
    ref = run_reference(evolver, path, script, cwd=str(tmp_path))
    code, out, err = run_pyevolver(path, script + "q\n", cwd=str(tmp_path))
    assert err == ""
    assert _same(out, [l for l in ref if l.strip()], rtol=1e-10), (out, ref)


# commands REF rejects; pyevolver rejects them with a located message and
# leaves the surface, the quantities and the variables as they were
REJECTED = [
    ("set quantity vol target 3", "write set NAME target value"),
    ("unset vol fixed", "unset vol: a quantity is not an element"),
    ("unset facet color", "not supported in pyevolver: unset facet color"),
    ("set vol volconst 0.5", "not supported in pyevolver: quantity volconst"),
    ("set vol bogus 2", "'bogus' is not a settable quantity attribute"),
    ("set vertex[1] mean_curvature 2", "vertex attribute 'mean_curvature' is read-only"),
    ("print vol.bogus", "quantity vol has no attribute 'bogus'"),
    ("set vertex boundary 1 where id == 1", "not supported in pyevolver: set vertex boundary"),
    ("set vertex p1 2 where id == 1", "is on no parametric boundary"),
]


@pytest.mark.parametrize("cmd,text", REJECTED)
def test_rejected_commands_leave_everything(cmd, text):
    s = pyevolver.load(example("qmound.fe"), out=io.StringIO(), err=io.StringIO())
    s.run("g 2\nxx := 3")
    X = s.surface.X.copy()
    q = s.surface.quantities["vol"]
    before = (q.kind, q.target, q.modulus, q.tolerance, s.total_energy)
    with pytest.raises(CommandError) as exc:
        s.run(f"xx := 5; {cmd}")
    assert text in str(exc.value) and str(exc.value).startswith("<command>:1: ")
    assert np.array_equal(s.surface.X, X)
    assert (q.kind, q.target, q.modulus, q.tolerance, s.total_energy) == before
    assert s.value("xx") == 3


def test_rejected_by_the_reference_too(evolver, tmp_path):
    """The forms refused above that REF also refuses (syntax errors there)."""
    import subprocess
    for cmd in ("set quantity vol target 3", "unset vol fixed", "unset facet color",
                "set vertex[1] mean_curvature 2"):
        proc = subprocess.run([evolver, "-p1", example("qmound.fe")], input=cmd + "\nq\nq\n",
                              capture_output=True, text=True, timeout=60, cwd=str(tmp_path))
        assert "error" in (proc.stdout + proc.stderr).lower(), cmd


def test_set_quantity_on_elements_it_cannot_apply_to_warns_as_reference(evolver, tmp_path):
    """``set vertex quantity vol`` (a facet quantity): REF's WARNING 1569 once
    per element, nothing changed."""
    import subprocess
    cmd = "set vertex quantity vol where id < 4\nprint vol.value\n"
    proc = subprocess.run([evolver, "-p1", example("qmound.fe")], input=cmd + "q\nq\n",
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          timeout=60, cwd=str(tmp_path))
    n_ref = proc.stdout.count("WARNING 1569")
    code, out, err = run_pyevolver(example("qmound.fe"), cmd + "q\n", cwd=str(tmp_path))
    assert n_ref == 3 and err.count("WARNING 1569: Quantity 'vol' has no methods applying "
                                    "to this type element.") == n_ref
    ref = run_reference(evolver, example("qmound.fe"), cmd, cwd=str(tmp_path))
    assert _same(out, [l for l in ref if l.strip() and "WARNING" not in l])
