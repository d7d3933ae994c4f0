"""The paper's Figure 4 (pyevolver.studies.fig4_vesicles): Canham vesicles.

Expected numbers come from closed forms (a sphere's W = 4π, an ellipsoid's
axis ratio), from the independent axisymmetric reference
(pyevolver.studies.axisymmetric, itself tested against 4π and under
refinement in test_axisymmetric.py) or from the reference Evolver run live
on the same datafile and the same command script.  The bounds on the
coarse (162-vertex) runs are justified by the measured convergence of the
method under refinement (docs/paper.md): the error falls roughly fourfold
per refinement (O(h²)), from about 1% at 162 vertices to 0.1–0.5% at 2,562.
"""
import io
import math
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.studies import fig4_vesicles as F4
from pyevolver.studies.meshes import icosphere, write_fe

FOURPI = 4 * math.pi


def _load(path):
    return Session.load(path, out=io.StringIO(), err=io.StringIO())


# -- conventions, starting shapes, descriptors -------------------------------------------------

@pytest.mark.parametrize("method", ["star_perp_sq_mean_curvature", "normal_sq_mean_curvature"])
def test_energy_is_integral_of_H_squared_not_2H(method, tmp_path):
    """W = Σ h² A/3 with h the mean of the principal curvatures: a unit
    sphere gives 4π (the (2H)² convention would give 16π), to O(h²)."""
    errs = []
    for level in (2, 3, 4):
        X, F = icosphere(level)
        path = write_fe(str(tmp_path / f"s{level}.fe"), X, F, face_attrs="tension 0",
                        header=f"quantity w energy method {method} global")
        errs.append(abs(_load(path).totals.quantity_values["w"] - FOURPI) / FOURPI)
    assert errs[-1] < 2e-3
    assert errs[1] < errs[0] / 3 and errs[2] < errs[1] / 3        # O(h²)


@pytest.mark.parametrize("shape", list(F4.SHAPES))
def test_initial_shapes_are_exactly_constrained(shape):
    v0 = F4.SHAPES[shape][0]
    X, F = F4.initial_shape(shape, 3)
    A, V = F4.area_volume(X, F)
    assert abs(A - FOURPI) < 1e-12 and abs(V - v0 * FOURPI / 3) < 1e-12
    d = F4.mesh_descriptors(X, F)
    # the discocyte starts as a plain oblate ellipsoid: its dimples must come out
    assert d["type"] == {"prolate": "prolate", "discocyte": "oblate",
                         "stomatocyte": "stomatocyte"}[shape]


def test_shipped_datafiles_match_the_generator(tmp_path):
    """datafiles/paper/vesicle_*.fe are what initial_shape writes."""
    for shape in F4.SHAPES:
        for kind in ("perp", "normal"):
            shipped = F4.datafile(shape, kind)
            fresh = F4.datafile(shape, kind, directory=str(tmp_path))
            with open(shipped) as a, open(fresh) as b:
                assert a.read() == b.read(), shipped


def test_descriptors_of_an_ellipsoid():
    X, F = icosphere(4)
    X = X * np.array([1.0, 1.0, 1.7])
    d = F4.mesh_descriptors(X, F)
    assert abs(d["height_width"] - 1.7) < 1e-9
    assert d["type"] == "prolate" and d["axis_crossings"] == 2
    assert abs(d["pole_depth_min"]) < 1e-9 and abs(d["pole_depth_max"]) < 1e-9
    d = F4.mesh_descriptors(X * np.array([1.0, 1.0, 0.2 / 1.7]), F)
    assert abs(d["height_width"] - 0.2) < 1e-9 and d["type"] == "oblate"


def _revolve(r, z, m=64):
    """Mesh of the surface of revolution of a profile with r = 0 at both ends."""
    rings = len(r) - 2
    phi = 2 * np.pi * np.arange(m) / m
    X = [[0.0, 0.0, z[0]]]
    for k in range(1, len(r) - 1):
        X += [[r[k] * np.cos(p), r[k] * np.sin(p), z[k]] for p in phi]
    X.append([0.0, 0.0, z[-1]])
    X = np.array(X)
    F = []

    def ring(k, j):
        return 1 + k * m + j % m
    for j in range(m):
        F.append([0, ring(0, j + 1), ring(0, j)])
        for k in range(rings - 1):
            F.append([ring(k, j), ring(k, j + 1), ring(k + 1, j + 1)])
            F.append([ring(k, j), ring(k + 1, j + 1), ring(k + 1, j)])
        F.append([len(X) - 1, ring(rings - 1, j), ring(rings - 1, j + 1)])
    return X, np.array(F)


@pytest.mark.parametrize("shape", list(F4.SHAPES))
def test_descriptors_agree_on_the_reference_surface(shape):
    """mesh_descriptors of the revolved reference profile equal
    reference_descriptors of the profile (both say the right type)."""
    ref = F4.reference(shape)
    want = F4.reference_descriptors(ref)
    X, F = _revolve(ref.r, ref.z)
    got = F4.mesh_descriptors(X, F)
    assert want["type"] == got["type"] == {"prolate": "prolate", "discocyte": "discocyte",
                                           "stomatocyte": "stomatocyte"}[shape]
    for k in ("height_width", "pole_depth_min", "pole_depth_max"):
        assert abs(got[k] - want[k]) < 2e-3, (k, got[k], want[k])
    assert got["axisym_dev"] < 1e-3


# -- the methods at 162 vertices (CI size) ---------------------------------------------------

@pytest.mark.parametrize("shape", ["prolate", "discocyte"])
def test_normal_harmonic_162(shape):
    """NormalCur + harmonic regularization, Newton converged, λ lowered by
    the continuation: the right type, W within 3% of the reference, every
    angle above 20° (the collapse the continuation guards against ends
    below 10°)."""
    _, rows = F4.run(shape, "normal", max_nv=162)
    r = rows[0]
    assert r["converged"] and r["lambda"] < 1.0
    assert r["type"] == shape, r
    assert abs(r["rel_error"]) < 0.03, r
    assert r["min_angle_deg"] >= 20.0
    assert abs(r["area_error"]) < 1e-9 and abs(r["volume_error"]) < 1e-9


def test_unregularized_normal_curvature_collapses():
    """The paper's point: without the harmonic term Newton drives
    normal_sq_mean_curvature to a degenerate mesh whose W falls below the
    smooth minimum (here the 162-vertex discocyte, regularized W > W_ref)."""
    s = _load(F4.datafile("discocyte", "normal"))
    assert F4.newton_lm(s)[0]
    W_reg = s.totals.quantity_values["willmore"]
    s.surface.quantities["harm"].modulus = 0.0
    s.recalc()
    F4.newton_lm(s, maxit=40)
    W = s.totals.quantity_values["willmore"]
    ref = F4.reference("discocyte").W
    assert W_reg > ref
    assert W < ref - 0.5 and F4.min_angle(s.surface.X, s.surface.F) < 5.0


def test_newton_step_is_quadratic_near_the_minimum():
    """newton_lm ends with max |∇L| below 1e-9 in a few steps from a
    converged neighbour (λ halved), and keeps the fixed values."""
    s = _load(F4.datafile("prolate", "normal"))
    assert F4.newton_lm(s)[0]
    s.surface.quantities["harm"].modulus = 0.5
    s.recalc()
    ok, steps, g = F4.newton_lm(s)
    assert ok and steps <= 8 and g < 1e-9
    A, V = s.totals.total_area, s.totals.volumes[0]
    assert abs(A - FOURPI) < 1e-10 and abs(V - 0.85 * FOURPI / 3) < 1e-10


def test_equiangulated_stage_follows_the_surface():
    """harmonic + u (:func:`_solve_stage` with flips): from the 162-vertex
    cup with every ninth edge swapped (a badly connected complex), Newton
    alone stops with edges left that ``u`` would flip, while solving and
    equiangulating in turn ends converged on a mesh ``u`` leaves alone, at
    a lower total energy W + λE (measured 54.15 against 55.06)."""
    ends = {}
    for flips in (0, 10):
        s = _load(F4.datafile("stomatocyte", "normal"))
        s.edgeswap(np.arange(0, s.surface.ne, 9), echo=False)
        ok, _, flipped = F4._solve_stage(s, 80, None, flips)
        ends[flips] = (ok, flipped, s.totals.energy, s.equiangulate(echo=False))
    assert ends[0][1] == 0 and ends[0][3] > 0
    ok, flipped, energy, left = ends[10]
    assert ok and flipped > 0 and left == 0
    assert energy < ends[0][2] - 0.5


def test_recipe_newton_162_prolate():
    """Fifteen cycles of V, u, g 5 and two hessian_seek steps."""
    _, rows = F4.run("prolate", "perp_newton", max_nv=162, recipe_vars={"recipe_max": 15})
    r = rows[0]
    assert r["type"] == "prolate" and abs(r["rel_error"]) < 0.03, r
    assert r["min_angle_deg"] > 20.0


def test_recipe_runs_unchanged_in_the_evolver(evolver):
    """datafiles/paper/vesicle_recipe.cmd on the shipped prolate: pyevolver
    and evolver-nox-d print the same W (20 cycles, 400 g steps, at 162
    vertices; measured agreement 1e-13)."""
    settings = {"recipe_max": 20}
    ours = F4.run("prolate", "perp", max_nv=162, recipe_vars=settings)[1][0]
    ref = F4.run_evolver("prolate", max_nv=162, executable=evolver, recipe_vars=settings)[0]
    assert ours["cycles"] == ref["cycles"] == 20
    assert abs(ours["energy"] - ref["energy"]) < 1e-10 * ref["energy"], (ours, ref)
    assert abs(ours["min_angle_deg"] - ref["min_angle_deg"]) < 1e-8
    assert ours["type"] == ref["type"] == "prolate"


def test_bad_names_are_refused():
    with pytest.raises(ValueError, match="unknown method 'cotan'"):
        F4.run("prolate", "cotan")
    with pytest.raises(ValueError, match="unknown shape 'torus'"):
        F4.run("torus", "normal")
    with pytest.raises(ValueError, match="resolution 100"):
        F4.run("prolate", "normal", max_nv=100)
    with pytest.raises(SystemExit):
        F4.main(["--methods", "cotan", "--no-evolver"])


def test_cli_writes_csv_and_png(tmp_path):
    out = str(tmp_path / "fig4")
    assert F4.main(["--max-nv", "162", "--methods", "normal", "--shapes", "prolate",
                    "--no-evolver", "--out", out]) == 0
    with open(os.path.join(out, "fig4_vesicles.csv")) as fh:
        lines = fh.read().splitlines()
    head = lines[0].split(",")
    for k in F4.CHART_KEYS + ("type", "height_width", "pole_depth_max"):
        assert k in head
    assert len(lines) == 3                  # reference row + one run
    assert os.path.getsize(os.path.join(out, "fig4_vesicles.png")) > 1000


def test_chart_records_keys():
    rows = F4.chart_records(max_nv=162, methods=["normal"], shapes=["prolate"])
    assert len(rows) == 1
    for k in F4.CHART_KEYS:
        assert k in rows[0]
    assert rows[0]["method"] == "NormalCur+harmonic" and rows[0]["resolution"] == 162


# -- acceptance at 2,562 vertices (slow) ---------------------------------------------------------

# known failures (docs/paper.md): NormalCur+harmonic with its complex fixed
# ends 1.9% above the stomatocyte's W (the regularization, conformal to the
# icosphere's structure, crowds the invagination: 55% of the vertices on 30%
# of the area; with `u` between the Newton solves, normal_u, it is 0.23%);
# the plain Evolver recipe loses the stomatocyte at 162 vertices (V unfolds
# the cup into a prolate)
KNOWN = {("normal", "stomatocyte"): "NormalCur+harmonic: W 1.9% high on the stomatocyte",
         ("perp", "stomatocyte"): "the plain recipe turns the stomatocyte into a prolate"}


@pytest.mark.slow
@pytest.mark.parametrize("method", ["normal", "normal_u", "perp", "perp_newton"])
@pytest.mark.parametrize("shape", list(F4.SHAPES))
def test_acceptance_2562(shape, method, request):
    """Issue 7: at 2,562 vertices the shape is of the right type and W is
    within 1% of the axisymmetric reference (the two known failures are
    strict xfails: they are reported if they start to pass).  Measured:
    normal_u 0.095%, 0.19%, 0.225% (prolate, discocyte, stomatocyte; the
    stomatocyte takes about 16 minutes on a loaded 2-core machine)."""
    if (method, shape) in KNOWN:
        request.applymarker(pytest.mark.xfail(strict=True, reason=KNOWN[(method, shape)]))
    _, rows = F4.run(shape, method, max_nv=2562)
    r = rows[-1]
    assert r["resolution"] == 2562
    assert r["min_angle_deg"] > 10.0, r
    assert r["type"] == shape, r
    assert abs(r["rel_error"]) < 0.01, r
    ref = F4.reference_descriptors(F4.reference(shape))
    assert abs(r["height_width"] - ref["height_width"]) < 0.05 * ref["height_width"], r


@pytest.mark.slow
def test_stomatocyte_reference_converged():
    """The reference's own accuracy on its hardest branch: W at 128 modes
    (the study's) agrees with 256 modes to 1e-7 relative (measured 9.5e-8;
    384 and 512 modes agree with 256 to 1.2e-12, docs/paper.md)."""
    from pyevolver.studies.axisymmetric import canham_reference
    a = canham_reference(0.5, "stomatocyte", n=128)
    b = canham_reference(0.5, "stomatocyte", n=256, coef0=a.coef)
    assert abs(a.W - b.W) < 1e-7 * b.W
    assert abs(a.W - F4.reference("stomatocyte").W) < 1e-12
