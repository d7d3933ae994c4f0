"""Read-only element attributes (the manual's "Element attributes") against
the live reference evolver-nox-d.

Every expected value comes from evolver-nox-d run in the test on the same
commands; pyevolver's output is never pasted in.
"""
import io
import os
import subprocess

import numpy as np
import pytest

from conftest import example
from reference import run_reference
from comparison import _same, run_pyevolver

import pyevolver
from pyevolver.methods import attributes as GA
from pyevolver.errors import CommandError

# per-vertex curvature attributes and edge dihedral angles over whole surfaces
ALL_ATTRS = ('foreach vertex vv do printf "V %d %.15g %.15g\\n", vv.id, vv.mean_curvature, '
             'vv.sqcurve\n'
             'foreach edge ee do printf "E %d %.15g\\n", ee.id, ee.dihedral\n')

SURFACES = [
    ("cube.fe", "g 2"),
    ("cube.fe", "r\ng 5"),
    ("cube.fe", "r\ng 5\neffective_area on"),
    ("cube.fe", "r\ng 5\nnormal_curvature on"),
    ("catbody.fe", "g 5\nr\ng 3"),          # FIXED vertices on boundary rings
    ("mound.fe", "g 5\nr\ng 3"),            # vertices on a level-set constraint
    ("mound.fe", "g 5\nr\ng 3\nnormal_curvature on"),
    ("qmound.fe", "r\ng 4"),
    ("sphere.fe", "g 3"),
    ("cat.fe", "g 3"),                      # vertices on parametric boundaries
    ("twointor.fe", "g 3"),                 # the torus model: facets wrap round
]


def _table(lines, tag):
    return np.array([[float(x) for x in l.split()[1:]] for l in lines if l.startswith(tag + " ")])


def _ours(datafile, commands):
    code, out, err = run_pyevolver(example(datafile), commands + "\nq\n")
    assert err == "", err
    return out


@pytest.mark.parametrize("datafile,pre", SURFACES)
def test_curvature_and_dihedral_attributes_match_reference(evolver, datafile, pre):
    ref = run_reference(evolver, example(datafile), pre + "\n" + ALL_ATTRS, timeout=300)
    out = _ours(datafile, pre + "\n" + ALL_ATTRS)
    for tag in "VE":
        R, O = _table(ref, tag), _table(out, tag)
        assert R.shape == O.shape and len(R)
        # REF's acos of coplanar facets' normals gives up to 3e-8 instead of 0
        np.testing.assert_allclose(O, R, rtol=1e-9, atol=1e-7 if tag == "E" else 1e-12)


def test_values_quoted_in_the_brief(evolver):
    cmds = ("g 2\nprint vertex[1].sqcurve\nprint vertex[1].mean_curvature\n"
            "print edge[1].dihedral\n")
    ref = run_reference(evolver, example("cube.fe"), cmds)
    out = _ours("cube.fe", cmds)
    assert _same(out, ref, rtol=1e-12)
    assert [float(x) for x in [l for l in ref if l.strip()][-3:]] == pytest.approx(
        [1.79073421092133, 1.70161660842656, 0.544544646315373], rel=1e-12)


# single attributes printed by both programs (same lines, numbers to 1e-10)
PRINTS = {
    "qmound.fe": ("g 3", [
        "print vertex[1].valence", "print vertex[1].on_constraint 1",
        "print vertex[1].hit_constraint 1", "print vertex[1].value_of_constraint 1",
        "print vertex[5].value_of_constraint 1", "print vertex[1].constraint[1].normal",
        "print vertex[5].constraint[1].normal[3]", "print vertex[1].mid_edge",
        "print vertex[1].mid_facet", "print vertex[1].axial_point",
        "print vertex[1].triple_point", "print vertex[1].tetra_point",
        "print vertex[1].no_hessian_normal", "print vertex[1].bare",
        "print vertex[1].on_quantity vol", "print facet[1].on_quantity vol",
        "print count(facet where on_quantity vol, 1)", "print facet[1].vol",
        "print sum(facet, vol)", "print vertex[1].vol", "print edge[1].vol",
        "print edge[1].dihedral", "print edge[9].dihedral", "print edge[1].valence",
        "print edge[1].no_transform", "print edge[1].noncontent", "print edge[1].bare",
        "print edge[1].orientation", "print edge[1].x1", "print edge[1].x[2]",
        "print edge[1].y", "print edge[1].x3", "print facet[1].area",
        "print facet[1].facet_normal", "print facet[1].facet_normal[2]",
        "print facet[-2].facet_normal", "print facet[1].x", "print facet[1].x[2]",
        "print facet[2].x3", "print facet[-2].x3", "print facet[1].opacity",
        "print facet[1].no_display", "print facet[1].nodisplay",
        "print facet[1].no_transform", "print facet[1].orientation",
        "print facet[1].noncontent", "print facet[1].phase", "print facet[1].frontbody",
        "print facet[1].backbody", "print facet[1].valence", "print body[1].volume",
        "print body[1].volfixed", "print body[1].phase", "print body[1].centerofmass",
        "print body[1].density", "print vol.value", "print vol.fixed", "print vol.energy",
        "print vol.info_only", "print vol.conserved", "print vol.volconst",
        "print vol.tolerance", "print vol.pressure",
        "foreach vertex vv where vv.id < 4 do print vv.sqcurve",
        "list vertex where value_of_constraint 1 > 0.9",
        # live coordinates: a set earlier in the same command counts (REF)
        "set vertex[5] x 0.3; print edge[5].length; print facet[1].area; "
        "print vertex[5].mean_curvature",
    ]),
    "catbody.fe": ("print vertex[1].v_force\nprint vertex[1].v_oldx\ng 3", [
        "print vertex[1].v_force", "print vertex[1].v_oldx", "print vertex[9].v_force",
        "print vertex[14].v_force", "print vertex[14].v_oldx[3]",
    ]),
    "mound.fe": ("g 4", [          # v_force is not projected onto the constraint
        "print vertex[1].v_force", "print vertex[1].v_force[3]", "print vertex[1].v_oldx",
        "print vertex[12].v_force", "print vertex[9].v_force", "print vertex[1].v_velocity",
        "print vertex[5].v_velocity", "print vertex[9].v_velocity",
        "print vertex[1].v_constraint_list", "print vertex[5].v_constraint_list",
        "print vertex[1].v_constraint_list[2] imod 0x100000",
        "set vertex[5] constraint 1; print vertex[5].v_constraint_list",
        "print edge[1].e_constraint_list", "print edge[5].e_constraint_list",
        "print facet[1].f_constraint_list",
        "foreach vertex vs where vs.v_constraint_list[1] == 1 do print vs.id",
    ]),
    "cube.fe": ("print vertex[1].v_velocity\ng", [
        "print vertex[1].v_velocity", "g", "print vertex[1].v_velocity",
        "print vertex[3].v_velocity[2]", "U", "g", "print vertex[5].v_velocity",
    ]),
    "twointor.fe": ("g 2", [      # torus wrap codes
        'foreach edge ee where ee.wrap != 0 do printf "%d %d\\n", ee.id, ee.wrap',
        "print facet[1].facet_normal", "print edge[1].x",
    ]),
    "slidestr.fe": ("g 3", [      # the string model
        "print vertex[3].dihedral", "print vertex[2].dihedral",
        "print max(vertex, dihedral)", "print edge[1].frontbody", "print edge[1].backbody",
    ]),
}


@pytest.mark.parametrize("datafile", sorted(PRINTS))
def test_printed_attributes_match_reference(evolver, datafile):
    pre, cmds = PRINTS[datafile]
    script = pre + "\n" + "\n".join(cmds) + "\n"
    ref = run_reference(evolver, example(datafile), script)
    out = _ours(datafile, script)
    assert _same(_flat(out), _flat(ref), rtol=1e-10), (out, ref)


def _flat(lines):
    """Array values ``{a,b,c}`` as separate tokens."""
    return [l.replace("{", " ").replace("}", " ").replace(",", " ") for l in lines]


# attributes REF rejects: pyevolver rejects them too, with a message naming the
# problem, and leaves the surface as it was
REJECTED = [
    ("qmound.fe", "print vertex[1].dihedral", "Dihedral only for edges"),
    ("qmound.fe", "print edge[1].midv", "MIDV"),
    ("qmound.fe", "print edge[1].frontbody", "Frontbody or backbody"),
    ("qmound.fe", "print facet[1].bare", "No bareness"),
    ("qmound.fe", "print facet[1].normal", "facet has no attribute 'normal'"),
    ("qmound.fe", "print vertex[1].star_area", "vertex has no attribute 'star_area'"),
    ("qmound.fe", "print vertex[1].area", "Area only for facets"),
    ("qmound.fe", "print edge[1].area", "Area only for facets"),
    ("qmound.fe", "print vertex[1].length", "Length only for edges"),
    ("qmound.fe", "print facet[1].volume", "Volume only for bodies"),
    ("qmound.fe", "print edge[1].sqcurve", "Square mean curvature only for vertices"),
    ("qmound.fe", "print facet[1].mean_curvature", "Mean_curvature only for vertices"),
    ("qmound.fe", "print body[1].actual_volume", "actual_volume"),
    ("slidestr.fe", "print edge[1].dihedral", "Dihedral only for vertices"),
]


@pytest.mark.parametrize("datafile,cmd,text", REJECTED)
def test_rejected_attributes(evolver, datafile, cmd, text):
    proc = subprocess.run([evolver, "-p1", example(datafile)], input=cmd + "\nq\nq\n",
                          capture_output=True, text=True, timeout=60)
    assert "ERROR" in proc.stdout + proc.stderr or "error" in proc.stdout + proc.stderr
    code, out, err = run_pyevolver(example(datafile), cmd + "\nprint total_energy\nq\n")
    assert text in err and "Traceback" not in err
    assert err.startswith("<stdin>:1")


# refused by name (no number of pyevolver's can stand for them)
REFUSED = [
    ("print vertex[1].e_constraint_list", "is a edge attribute, not vertex"),
    ("print facet[1].f_body_list", "the internal attribute f_body_list"),
    ("set vertex triple_point where id == 5", "set vertex triple_point"),
    ("set facet orientation -1 where id == 1", "set facet orientation"),
    ("set edge noncontent where id == 1", "set edge noncontent"),
    ("set vol volconst 0.5", "quantity volconst"),
]


@pytest.mark.parametrize("cmd,text", REFUSED)
def test_refused_attributes_leave_everything(cmd, text):
    s = pyevolver.load(example("qmound.fe"), out=io.StringIO(), err=io.StringIO())
    s.run("g 3")
    X = s.surface.X.copy()
    E = s.total_energy
    with pytest.raises(CommandError) as exc:
        s.run(cmd)
    assert text in str(exc.value) and str(exc.value).startswith("<command>:1: ")
    assert np.array_equal(s.surface.X, X) and s.total_energy == E
    assert s.surface.quantities["vol"].kind == "fixed"


def test_generator_computes_the_surface_once(monkeypatch):
    """``foreach vertex vv do print vv.sqcurve`` evaluates the whole surface
    once, and again only after the coordinates change."""
    calls = []
    real = GA.vertex_sqcurve

    def counted(*a, **k):
        calls.append(1)
        return real(*a, **k)

    monkeypatch.setattr(GA, "vertex_sqcurve", counted)
    s = pyevolver.load(example("cube.fe"), out=io.StringIO())
    s.run("r\nr\ng 2")
    s.out = io.StringIO()
    s.run("foreach vertex vv do print vv.sqcurve")
    assert len(calls) == 1
    assert len(s.out.getvalue().split("\n")) > s.surface.nv
    s.run("print sum(vertex, sqcurve)")
    assert len(calls) == 1                      # a new command, nothing changed: same totals
    s.run("aa := vertex[1].sqcurve; set vertex[1] x 0.2; bb := vertex[1].sqcurve; "
          "cc := vertex[2].sqcurve")
    assert len(calls) == 2                      # again after the set, once
    s.run("print sum(vertex, sqcurve)")
    assert len(calls) == 3                      # the check after the set evaluated anew
    assert s.value("aa") != s.value("bb")


def test_attribute_table_in_docs():
    from pyevolver.commands.attributes import ATTRIBUTES
    here = os.path.dirname(os.path.dirname(__file__))
    with open(os.path.join(here, "..", "docs", "supported.md")) as fh:
        text = fh.read()
    for _kind, names, _status in ATTRIBUTES:
        assert names in text, names


def test_hit_constraint_of_one_sided_constraints(evolver, tmp_path):
    """mound.fe with its table a NONNEGATIVE constraint: a vertex lifted off
    the plane is still on the constraint but no longer hits it (REF)."""
    with open(example("mound.fe")) as fh:
        src = fh.read()
    src = src.replace("constraint 1   /* the table top */",
                      "constraint 1 nonnegative  /* the table top */")
    path = tmp_path / "moundn.fe"
    path.write_text(src)
    cmds = ("print vertex[1].hit_constraint 1\nprint vertex[5].hit_constraint 1\n"
            "set vertex[1] z 0.1\nprint vertex[1].hit_constraint 1\n"
            "print vertex[1].on_constraint 1\nprint vertex[1].value_of_constraint 1\n"
            "print count(vertex where hit_constraint 1, 1)\n")
    ref = run_reference(evolver, str(path), cmds)
    code, out, err = run_pyevolver(str(path), cmds + "q\n")
    assert err == ""
    assert _same(out, [l for l in ref if l.strip()])
