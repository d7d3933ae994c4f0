"""pyevolver.methods.gauss_integral: ``gauss_curvature_integral`` is the
total geodesic curvature of the boundary; Gauss–Bonnet (closed-form) fixes
its value, the analytic gradient agrees with central differences, and the
extra attributes ``gauss_bdry_v`` / ``gauss_bdry_e`` override the FIXED /
boundary criterion.  REF's values and steps: test_curvature_constrained_reference.py."""
import io
import os

import numpy as np

from conftest import example
from pyevolver import Session
from pyevolver.methods import gauss_integral as GI
from pyevolver.methods.registry import lookup
from pyevolver.model.scene import MethodDecl
from tolerances import FD, ROUNDOFF


def _cat(tmp_path):
    with open(example("cat.fe")) as fh:
        src = fh.read()
    src = src[:src.index("read")].replace(
        "vertices   //", "quantity gc energy method gauss_curvature_integral global\n\nvertices //")
    p = tmp_path / "cat_gci.fe"
    p.write_text(src)
    s = Session.load(str(p), out=io.StringIO())
    s.run("r")
    return s.surface


def _total(S):
    m = lookup("gauss_curvature_integral")
    return float(m.value(S.evaluate(), MethodDecl(method="gauss_curvature_integral"),
                         np.arange(S.nf)).sum())


def test_gauss_bonnet_and_gradient(tmp_path):
    """An annulus (χ = 0) with both rings marked: the boundary term equals
    the interior angle deficit Σ_v (2π − Σ angles) (Gauss–Bonnet); the
    gradient against central differences after a random move."""
    S = _cat(tmp_path)
    vmark, emark = GI.boundary_marks(S)
    assert vmark.sum() == 24 and emark.sum() == 24
    S.X[~vmark] += 0.05 * np.random.default_rng(0).standard_normal((int((~vmark).sum()), 3))
    t = S.evaluate()
    from pyevolver.methods.curvature import _angles
    from pyevolver.methods._common import facet_points
    ang, _ = _angles(facet_points(t))
    sums = np.bincount(S.F.ravel(), weights=ang.ravel(), minlength=S.nv)
    deficit = (2 * np.pi - sums)[~vmark].sum()
    assert abs(_total(S) - deficit) <= ROUNDOFF * 100
    m = lookup("gauss_curvature_integral")
    decl = MethodDecl(method="gauss_curvature_integral")
    w = np.random.default_rng(1).uniform(0.5, 1.5, S.nf)
    g = m.gradient(t, decl, np.arange(S.nf), w)
    X0 = S.X.copy()
    h = 1e-6
    rng = np.random.default_rng(2)
    for _ in range(12):
        i, k = rng.integers(S.nv), rng.integers(3)
        S.X = X0.copy()
        S.X[i, k] += h
        ep = float(m.value(S.evaluate(), decl, np.arange(S.nf)) @ w)
        S.X = X0.copy()
        S.X[i, k] -= h
        em = float(m.value(S.evaluate(), decl, np.arange(S.nf)) @ w)
        assert abs((ep - em) / (2 * h) - g[i, k]) <= FD * max(1.0, np.abs(g).max())
    S.X = X0


def test_extra_attributes_override_the_boundary(tmp_path):
    """With gauss_bdry_v and gauss_bdry_e zero everywhere nothing counts."""
    S = _cat(tmp_path)
    S.extra[("vertex", "gauss_bdry_v")] = np.zeros(S.nv)
    S.extra[("edge", "gauss_bdry_e")] = np.zeros(S.ne)
    try:
        vmark, emark = GI.boundary_marks(S)
        assert not vmark.any() and not emark.any()
        assert _total(S) == 0.0
    finally:
        del S.extra[("vertex", "gauss_bdry_v")]
        del S.extra[("edge", "gauss_bdry_e")]


def test_mound_on_a_constraint_has_no_boundary():
    """Level-set constrained vertices are no boundary (REF: 0 on the mound)."""
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with open(os.path.join(here, "data", "curv_mound.fe")) as fh:
        src = fh.read()
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        p = os.path.join(d, "m.fe")
        with open(p, "w") as fh:
            fh.write(src.replace("method star_perp_sq_mean_curvature",
                                 "method gauss_curvature_integral"))
        S = Session.load(p, out=io.StringIO()).surface
    assert _total(S) == 0.0
