"""The mobility options of ``g`` (pyevolver.evolve.mobility) against
evolver-nox-d run live: every progress line of each ``g`` block agrees in
area and energy within STEPS (the printed 15 digits), and the final
``total_energy`` too."""
import io
import os
import re

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.evolve.mobility import Mobility, star_measure

from comparison import run_pyevolver
from conftest import example
from reference import run_reference
from tolerances import ROUNDOFF, STEPS

LINE = re.compile(r"^\s*(\d+)\. (?:area|length):\s*(\S+) energy:\s*(\S+)\s+scale:\s*(\S+)")
TAIL = 'printf "FINAL %.17g\\n", total_energy\n'


def _rel(a, b):
    a, b = float(a), float(b)
    return abs(a - b) / max(abs(a), abs(b), 1e-300)


def compare_g(evolver, path, cmds, tmp_path, tol=STEPS):
    """Run ``cmds`` in both programs; every g line and the final energy agree."""
    ref = run_reference(evolver, path, cmds + "\n" + TAIL, cwd=str(tmp_path))
    code, out, err = run_pyevolver(path, cmds + "\n" + TAIL + "q\n", cwd=str(tmp_path))
    assert "not supported" not in err and "Traceback" not in err, err
    rl = [m.groups() for m in map(LINE.match, ref) if m]
    ml = [m.groups() for m in map(LINE.match, out) if m]
    assert rl and len(rl) == len(ml), (ref, out, err)
    for r, m in zip(rl, ml):
        assert r[0] == m[0]
        assert _rel(r[1], m[1]) <= tol and _rel(r[2], m[2]) <= tol, (r, m)
    rf = [l.split()[1] for l in ref if l.startswith("FINAL")]
    mf = [l.split()[1] for l in out if l.startswith("FINAL")]
    assert rf and mf and _rel(rf[0], mf[0]) <= tol, (rf, mf)
    return rl


def grain(tmp_path):
    """100grain.fe without its autopop and autochop lines (popping is
    another family's)."""
    text = open(example("100grain.fe")).read()
    text = re.sub(r"(?m)^(autopop|autochop)\b.*$", "", text)
    path = tmp_path / "grain.fe"
    path.write_text(text)
    return str(path)


# -- closed form ------------------------------------------------------------------------
def test_star_measure_of_the_cube():
    """cube.fe: a corner is on 6 triangles of area 1/4 (star 3/2), a face
    centre on 4 (star 1): a third of each."""
    s = Session.load(example("cube.fe"), out=io.StringIO())
    a = star_measure(s.surface.evaluate())
    corner = np.all(np.isin(s.surface.X, (0.0, 1.0)), axis=1)
    assert corner.sum() == 8
    assert np.allclose(a[corner], 0.5, rtol=0, atol=ROUNDOFF)
    assert np.allclose(a[~corner], 1 / 3, rtol=0, atol=ROUNDOFF)
    m = Mobility(s.surface.evaluate(), area_normalization=True)
    (v,) = m.apply([np.ones((s.surface.nv, 3))])
    assert np.allclose(v[corner], 2.0) and np.allclose(v[~corner], 3.0)
    assert Mobility(s.surface.evaluate()).identity


def test_star_measure_of_a_string():
    """The string model: half the length of the edges at each vertex."""
    s = Session.load(example("popstr.fe"), out=io.StringIO())
    t = s.surface.evaluate()
    a = star_measure(t)
    assert np.isclose(a[4], 0.5 * 4 * np.sqrt(0.5), rtol=ROUNDOFF)
    assert np.allclose(a[:4], 0.5 * np.sqrt(0.5), rtol=ROUNDOFF)


# -- area normalization against REF ----------------------------------------------------------
@pytest.mark.parametrize("name,cmds", [
    ("catbody", "area_normalization\nU\nr\ng 10"),       # CG restart after 10 restorings
    ("mound", "area_normalization\nr\ng 6"),             # constraint, volume, gravity
    pytest.param("cube", "area_normalization\nm 0.1\ng 3", marks=pytest.mark.slow),
    pytest.param("cube", "area_normalization\ng 10", marks=pytest.mark.slow),
    pytest.param("catbody", "area_normalization\nr\ng 10", marks=pytest.mark.slow),
    pytest.param("quad", "area_normalization\nr\ng 10", marks=pytest.mark.slow),
    pytest.param("cube", "area_normalization\nU\nr\ng 10", marks=pytest.mark.slow),
    pytest.param("mound", "area_normalization\nU\nr\ng 10", marks=pytest.mark.slow),
    pytest.param("cube", "area_normalization\nU\nribiere off\nr\ng 6",
                 marks=pytest.mark.slow),
])
def test_area_normalization_matches_reference(evolver, name, cmds, tmp_path):
    compare_g(evolver, example(name + ".fe"), cmds, tmp_path)


def test_area_normalization_string_model(evolver, tmp_path):
    """100grain.fe's string network on the torus (area_normalization and a
    fixed scale from its top section)."""
    compare_g(evolver, grain(tmp_path), "g 3", tmp_path)


@pytest.mark.slow
def test_area_normalization_string_model_long(evolver, tmp_path):
    """100grain.fe ``g 10`` and a constrained string drop."""
    compare_g(evolver, grain(tmp_path), "g 10", tmp_path)
    compare_g(evolver, example("slidestr.fe"), "area_normalization\nr\ng 10", tmp_path,
              tol=1e-11)


# -- normal_motion --------------------------------------------------------------------------
@pytest.mark.parametrize("name,cmds", [
    ("cat", "normal_motion\nr\nU\ng 6"),               # CG: projected before and after
    pytest.param("cube", "normal_motion\nr\ng 10", marks=pytest.mark.slow),
    pytest.param("cube", "normal_motion\nr\nset body target 1.3\ng 4",   # restoring
                 marks=pytest.mark.slow),
])
def test_normal_motion_matches_reference(evolver, name, cmds, tmp_path):
    compare_g(evolver, example(name + ".fe"), cmds, tmp_path)


def test_normal_motion_refused_where_not_reproduced():
    from pyevolver.errors import UnsupportedError
    s = Session.load(example("catbody.fe"), out=io.StringIO())
    s.run("normal_motion")
    with pytest.raises(UnsupportedError, match="normal_motion with fixed volumes"):
        s.g(1)


def test_normal_motion_moves_along_the_normal():
    """Closed form: on cube.fe a face centre's velocity is along its face
    normal, a corner's along the diagonal."""
    s = Session.load(example("cube.fe"), out=io.StringIO())
    s.run("normal_motion; r; m 0.1; g 1")
    _, _, X, V = s.__dict__["_last_motion"]       # start positions, velocities
    corner = np.all(np.isin(X, (0.0, 1.0)), axis=1)
    assert corner.sum() == 8
    n = np.sign(X[corner] - 0.5)
    u = V[corner] / np.linalg.norm(V[corner], axis=1)[:, None]
    assert np.allclose(np.abs(np.einsum("ij,ij->i", u, n)), np.sqrt(3), rtol=0, atol=1e-12)


# -- runge_kutta ------------------------------------------------------------------------------
@pytest.mark.parametrize("name,cmds", [
    ("quad", "area_normalization\nrunge_kutta\nr\nm 0.01\ng 3"),
    pytest.param("quad", "runge_kutta\nr\nm 0.1\ng 5", marks=pytest.mark.slow),
    pytest.param("cat", "runge_kutta\nr\nm 0.05\ng 5", marks=pytest.mark.slow),
    pytest.param("cube", "runge_kutta\ng 3", marks=pytest.mark.slow),   # optimizing: no effect
])
def test_runge_kutta_matches_reference(evolver, name, cmds, tmp_path):
    compare_g(evolver, example(name + ".fe"), cmds, tmp_path)


def test_runge_kutta_refused_with_fixed_volumes():
    from pyevolver.errors import UnsupportedError
    s = Session.load(example("cube.fe"), out=io.StringIO())
    s.run("runge_kutta; m 0.1")
    with pytest.raises(UnsupportedError, match="runge_kutta with fixed volumes"):
        s.g(1)


# -- diffusion --------------------------------------------------------------------------------
DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")


@pytest.mark.parametrize("name,cmds", [
    ("diffusion_cubes_attr.fe", "m 0.05\ng 3\ndiffusion_coeff := 0.3\ng 2"),   # facet_diffusion
    pytest.param("diffusion_cubes.fe", "g 3\nv", marks=pytest.mark.slow),
    pytest.param("diffusion_cubes.fe",
                 "m 0.05\ng 3\ndiffusion_coeff := 0.3\ng 2\ndiffusion off\ng 2",
                 marks=pytest.mark.slow),
])
def test_diffusion_matches_reference(evolver, name, cmds, tmp_path):
    compare_g(evolver, os.path.join(DATA, name), cmds, tmp_path)


@pytest.mark.slow
def test_diffusion_keyword_and_dumps(evolver, tmp_path):
    """DIFFUSION sets diffusion_coeff and turns the toggle on; REF's dump
    after ``g 2`` goes on in pyevolver as in REF, and so does ours in REF."""
    path = os.path.join(DATA, "diffusion_cubes.fe")
    s = Session.load(path, out=io.StringIO())
    assert s.toggles["diffusion"] == 1 and s.settings["diffusion_coeff"] == 0.1
    want = [m.groups() for m in map(LINE.match, run_reference(evolver, path, "g 4")) if m][2:]
    ref_dump, our_dump = tmp_path / "ref.dmp", tmp_path / "ours.dmp"
    run_reference(evolver, path, f'g 2\ndump "{ref_dump}"')
    run_pyevolver(path, f'g 2\ndump "{our_dump}"\nq\n')
    for dmp in (ref_dump, our_dump):
        _, out, err = run_pyevolver(str(dmp), "g 2\nq\n")
        got = [m.groups() for m in map(LINE.match, out) if m]
        ref = [m.groups() for m in map(LINE.match, run_reference(evolver, str(dmp), "g 2")) if m]
        for a, b, c in zip(want, got, ref):
            assert _rel(a[2], b[2]) <= STEPS and _rel(a[2], c[2]) <= STEPS, (a, b, c)
        assert len(got) == len(ref) == 2


# -- jiggle -----------------------------------------------------------------------------------
def test_jiggle_toggle_statistics():
    """With ``jiggle`` on and a zero scale, a g step moves each free vertex
    by a Gaussian of deviation jiggle_temperature × mean edge length
    (single.htm, j); FIXED vertices stay; seeded, so repeatable."""
    def run(name, seed):
        s = Session.load(example(name), out=io.StringIO())
        s.run(f"r; r; r; m 0; jiggle on; jiggle_temperature := 0.1; random_seed := {seed}")
        L = float(np.mean(s.surface.evaluate().edge_length))
        X0 = s.surface.X.copy()
        s.run("g 1")
        return (s.surface.X - X0) / L, s.surface.vattr["fixed"]
    d, _ = run("cube.fe", 7)                # no constraints: the pure perturbation
    n = d.size
    assert n > 2000                         # 5 standard errors:
    assert abs(d.std() / 0.1 - 1) < 5 / np.sqrt(2 * n) and abs(d.mean()) < 5 * 0.1 / np.sqrt(n)
    assert np.array_equal(run("cube.fe", 7)[0], d)
    assert not np.array_equal(run("cube.fe", 8)[0], d)
    d, fixed = run("quad.fe", 7)
    assert fixed.any() and np.all(d[fixed] == 0.0) and np.all(d[~fixed] != 0.0)


def test_jiggle_off_changes_nothing():
    a = Session.load(example("cube.fe"), out=io.StringIO())
    b = Session.load(example("cube.fe"), out=io.StringIO())
    b.run("jiggle on; jiggle off")
    assert [r.energy for r in a.g(5)] == [r.energy for r in b.g(5)]


# -- approximate curvature --------------------------------------------------------------------
def test_mass_matrix_closed_form():
    """∫ φ_i φ_j of linear interpolation: its entries sum to the area (the
    length in the string model), and a triangle's rows are A/12 (2, 1, 1)."""
    from pyevolver.evolve.mobility import mass_matrix
    s = Session.load(example("cube.fe"), out=io.StringIO())
    t = s.surface.evaluate()
    M = mass_matrix(t)
    assert abs(M.sum() - 6.0) < ROUNDOFF
    assert np.allclose(M.diagonal(), star_measure(t) / 2, rtol=0, atol=ROUNDOFF)
    g = Session.load(example("popstr.fe"), out=io.StringIO()).surface.evaluate()
    assert abs(mass_matrix(g).sum() - g.total_length) < ROUNDOFF


@pytest.mark.parametrize("name,cmds,tol", [
    ("cat", "approx_curv\nr\nU\ng 4", STEPS),
    pytest.param("quad", "approx_curv\nr\nm 0.01\ng 3", STEPS, marks=pytest.mark.slow),
    pytest.param("quad", "approx_curv\nr\ng 5", STEPS, marks=pytest.mark.slow),
])
def test_approximate_curvature_matches_reference(evolver, name, cmds, tol, tmp_path):
    compare_g(evolver, example(name + ".fe"), cmds, tmp_path, tol)


@pytest.mark.slow
def test_approximate_curvature_string_and_free_boundary(evolver, tmp_path):
    """100grain.fe's network (area normalization off), and cat.fe with its
    rings free to slide: REF moves no boundary vertex (equal within 1e-10;
    REF's ring vertices are recomputed from their parameters)."""
    compare_g(evolver, grain(tmp_path), "area_normalization off\napprox_curv\ng 3", tmp_path)
    text = open(example("cat.fe")).read().replace(" fixed", "")
    path = tmp_path / "catfree.fe"
    path.write_text(text)
    compare_g(evolver, str(path), "approx_curv\nr\nm 0.01\ng 3", tmp_path, 1e-10)


def test_approximate_curvature_refusals():
    from pyevolver.errors import UnsupportedError
    s = Session.load(example("cube.fe"), out=io.StringIO())
    s.run("approx_curv")
    with pytest.raises(UnsupportedError, match="approx_curv with fixed volumes"):
        s.g(1)
