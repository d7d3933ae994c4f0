"""The curvature methods at vertices on level-set constraints and on free
edges (pyevolver/methods/curvature.py, mirror_projector): analytic gradients
against central differences of the values and analytic Hessians against
differences of the gradients, on a dome whose free edge lies on the plane
z = 0 and on a closed vesicle resting on it (both refined and moved off any
symmetry).  On planes the projectors are constant, so the gradients are the
exact derivatives; REF's values and steps are compared in
tests/reference/test_curvature_constrained_reference.py.  Where REF's force
is not the derivative of its energy the gradient is refused by name."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.errors import UnsupportedError
from pyevolver.methods import curvature as C
from pyevolver.methods import curvature_hessian as CH
from pyevolver.methods.registry import lookup
from pyevolver.model.scene import MethodDecl
from tolerances import FD

DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data")
ALL = list(C.VERTEX_METHODS)
STAR = [m for m in ALL if m.startswith("star_")]


def _load(name, commands="r"):
    s = Session.load(os.path.join(DATA, name), out=io.StringIO())
    s.run(commands)
    return s.surface


@pytest.fixture(scope="module")
def dome():
    """curv_mound.fe refined, the upper vertices pushed onto a
    hemisphere of radius 0.8 about (0.5, 0.5, 0), then jiggled in x, y
    (the base stays on z = 0)."""
    S = _load("curv_mound.fe", "r")
    c = np.array([0.5, 0.5, 0.0])
    d = S.X - c
    r = np.linalg.norm(d, axis=1)
    S.X = c + d * (0.8 / r)[:, None]
    S.X[:, 2] = np.where(np.abs(S.X[:, 2]) < 1e-12, 0.0, S.X[:, 2])
    S.X[:, :2] += 0.02 * np.random.default_rng(5).standard_normal((S.nv, 2))
    return S


@pytest.fixture(scope="module")
def vesicle():
    """curv_vesicle.fe refined, moved off symmetry keeping the base on z = 0."""
    S = _load("curv_vesicle.fe", "r")
    x, y, z = S.X.T.copy()
    S.X[:, 0] = x + 0.1 * z * z + 0.05 * y * z
    S.X[:, 2] = z * (1 + 0.2 * x * y) + 0.1 * z * (1 - z)
    return S


def _fd(S, name, n=10, seed=0):
    m = lookup(name)
    decl = MethodDecl(method=name)
    idx = np.arange(S.nv)
    w = np.random.default_rng(seed).uniform(0.5, 1.5, S.nv)
    X0 = S.X.copy()
    g = m.gradient(S.evaluate(), decl, idx, w)
    rng = np.random.default_rng(seed + 1)
    on = np.zeros(S.nv, bool)
    for mask in S.vcon.values():
        on |= mask
    rows = np.concatenate([np.nonzero(on)[0][:n // 2], rng.integers(S.nv, size=n - n // 2)])
    worst = 0.0
    h = 1e-6
    try:
        for i in rows:
            for k in range(3):
                S.X = X0.copy()
                S.X[i, k] += h
                ep = float(m.value(S.evaluate(), decl, idx) @ w)
                S.X = X0.copy()
                S.X[i, k] -= h
                em = float(m.value(S.evaluate(), decl, idx) @ w)
                worst = max(worst, abs((ep - em) / (2 * h) - g[i, k]))
        v = rng.standard_normal(X0.shape)
        S.X = X0
        D = m.hessian(S.evaluate(), decl, idx, w).toarray()
        S.X = X0 + h * v
        gp = m.gradient(S.evaluate(), decl, idx, w)
        S.X = X0 - h * v
        gm = m.gradient(S.evaluate(), decl, idx, w)
        herr = np.abs(D @ v.ravel() - (gp - gm).ravel() / (2 * h)).max()
        asym = np.abs(D - D.T).max()
    finally:
        S.X = X0
    return worst / max(1.0, np.abs(g).max()), herr / max(1.0, np.abs(D).max()), asym


@pytest.mark.parametrize("name", ALL)
def test_gradient_and_hessian_on_the_dome(dome, name):
    """Free edge on the plane: F and N projected at the base for every method."""
    gerr, herr, asym = _fd(dome, name)
    assert gerr <= FD and herr <= FD and asym <= 1e-10


@pytest.mark.parametrize("name", ["sq_mean_curvature", "star_sq_mean_curvature",
                                  "star_eff_area_sq_mean_curvature",
                                  "star_perp_sq_mean_curvature"])
def test_gradient_and_hessian_on_the_vesicle(vesicle, name):
    """Closed surface on the plane: the old methods project at the base
    vertices, the star methods (complete stars) do not."""
    gerr, herr, asym = _fd(vesicle, name)
    assert gerr <= FD and herr <= FD and asym <= 1e-10


def test_projection_rules(dome, vesicle):
    """Which vertices are projected: every constrained one for the old
    methods, the constrained ones on a free edge for the star methods."""
    for S, star_rows in ((dome, True), (vesicle, False)):
        on = np.zeros(S.nv, bool)
        for mask in S.vcon.values():
            on |= mask
        rows, P = C.mirror_projector(S, MethodDecl(method="sq_mean_curvature"))
        assert set(rows) == set(np.nonzero(on)[0])
        assert np.allclose(P[:, 2, :], 0.0) and np.allclose(P[:, 0, 0], 1.0)
        rows, _ = C.mirror_projector(S, MethodDecl(method="star_perp_sq_mean_curvature"))
        assert (len(rows) > 0) == star_rows
        ign = MethodDecl(method="sq_mean_curvature", ignore_constraints=True)
        assert len(C.mirror_projector(S, ign)[0]) == 0
        ign = MethodDecl(method="star_perp_sq_mean_curvature", ignore_constraints=True)
        assert (len(C.mirror_projector(S, ign)[0]) > 0) == star_rows     # no effect (REF)


def test_old_method_gradients_refused_where_ref_differs(vesicle):
    """eff_area at a projected vertex with a complete star, h_zero at any
    projected vertex: REF's force is not the derivative there (v_force after
    g 1), so the gradient is refused by name; the values stay available."""
    m = lookup("eff_area_sq_mean_curvature")
    decl = MethodDecl(method="eff_area_sq_mean_curvature")
    idx = np.arange(vesicle.nv)
    t = vesicle.evaluate()
    assert np.isfinite(m.value(t, decl, idx)).all()
    with pytest.raises(UnsupportedError, match="eff_area_sq_mean_curvature"):
        m.gradient(t, decl, idx, np.ones(vesicle.nv))
    vesicle.params["h_zero"] = 0.5
    try:
        decl = MethodDecl(method="sq_mean_curvature")
        with pytest.raises(UnsupportedError, match="h_zero"):
            lookup("sq_mean_curvature").gradient(vesicle.evaluate(), decl, idx,
                                                 np.ones(vesicle.nv))
        # the star methods are fine with h_zero
        gerr, _, _ = _fd(vesicle, "star_perp_sq_mean_curvature", n=4)
        assert gerr <= FD
    finally:
        vesicle.params.pop("h_zero")


def test_curved_constraint_old_gradient_refused_star_projector_constant(tmp_path):
    """On a curved constraint the old-style gradient is refused; the star
    methods hold the projector constant (as REF: its g steps agree)."""
    with open(os.path.join(DATA, "curv_mound.fe")) as fh:
        src = fh.read().replace("formula: x3 = 0", "formula: x3 = 0.2*x1^2 + 0.1*x2")
    p = tmp_path / "curved.fe"
    p.write_text(src)
    S = Session.load(str(p), out=io.StringIO()).surface
    idx = np.arange(S.nv)
    with pytest.raises(UnsupportedError, match="curved constraints"):
        lookup("sq_mean_curvature").gradient(S.evaluate(), MethodDecl(method="sq_mean_curvature"),
                                             idx, np.ones(S.nv))
    g = lookup("star_perp_sq_mean_curvature").gradient(
        S.evaluate(), MethodDecl(method="star_perp_sq_mean_curvature"), idx, np.ones(S.nv))
    assert np.isfinite(g).all()
    # the analytic Hessian leaves out the projectors' derivatives: hessian
    # falls back to differences of the gradient there, not on planes
    entry = lookup("star_perp_sq_mean_curvature")
    assert entry.hessian_applies is CH.plane_constraints_only
    assert not entry.hessian_applies(S)
    flat = Session.load(os.path.join(DATA, "curv_mound.fe"), out=io.StringIO()).surface
    assert entry.hessian_applies(flat)


def test_mix_sq_mean_curvature_is_refused_by_name():
    with pytest.raises(UnsupportedError, match="1559"):
        lookup("mix_sq_mean_curvature")


def test_mean_curvature_integral_drops_dtheta_at_flat_edges(tmp_path):
    """REF's gradient of ∫H dA leaves out dθ at exactly flat edges.  On cube.fe the
    centre of a face is a wing of the four cube edges, whose θ = π/2 falls
    by 2 dz per unit lift (the facets tilt by dz/½), so the force there is
    4 outward (closed form; REF's v_force after ``g 1``), while the exact
    derivative, which also moves the flat spokes, is 0."""
    with open(os.path.join(DATA, "curv_vesicle.fe")) as fh:
        src = fh.read().replace("method sq_mean_curvature", "method mean_curvature_integral")
    p = tmp_path / "cube_mci.fe"
    p.write_text(src.replace(" constraint 1", ""))
    S = Session.load(str(p), out=io.StringIO()).surface
    m = lookup("mean_curvature_integral")
    g = m.gradient(S.evaluate(), MethodDecl(method="mean_curvature_integral"),
                   np.arange(S.ne), np.ones(S.ne))
    top = int(np.nonzero(np.all(np.abs(S.X - [0.5, 0.5, 1.0]) < 1e-12, axis=1))[0][0])
    assert np.allclose(-g[top], [0.0, 0.0, 4.0], atol=1e-12)
