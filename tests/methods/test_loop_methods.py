"""pyevolver.methods.loop: the Loop-subdivision-surface methods as vertex
methods.  Invariants: the vertex shares add up to the facet totals, the
limit surface's area scales as λ², its volume as λ³ and W = ∫H² dA not at
all, all three are invariant under translation; gradients against central
differences."""
import numpy as np
import pytest

from comparison import octasphere
from tolerances import FD, ROUNDOFF
from pyevolver.methods import loop as L
from pyevolver.methods.registry import lookup
from pyevolver.model.scene import MethodDecl


def _totals(s):
    t = s.evaluate()
    idx = np.arange(s.nv)
    return {k: float(L.values(t, MethodDecl(method=k), idx).sum()) for k in L.KIND}


def test_vertex_shares_add_up_to_the_facet_totals():
    s = octasphere(0, jiggle=0.05)
    t = s.evaluate()
    per_facet = L.evaluator(s).values(s.X)
    for name, kind in L.KIND.items():
        v = L.values(t, MethodDecl(method=name), np.arange(s.nv))
        assert v.shape == (s.nv,)
        assert abs(v.sum() - per_facet[kind].sum()) <= ROUNDOFF * max(1.0, abs(v.sum()))
        assert lookup(name).etype == "vertex" and lookup(name).no_hessian
    # the limit surface lies inside the control polyhedron of a convex mesh
    tot = _totals(s)
    assert 0 < tot["loop_area"] < t.total_area
    assert 0 < tot["loop_volume"] < t.volumes[0]


def test_scaling_and_translation():
    a = _totals(octasphere(1, jiggle=0.05))
    lam = 1.7
    b = _totals(octasphere(1, jiggle=0.05, scale=lam, shift=(0.4, -2.0, 1.1)))
    assert abs(b["loop_area"] - lam ** 2 * a["loop_area"]) <= 1e-10 * b["loop_area"]
    assert abs(b["loop_volume"] - lam ** 3 * a["loop_volume"]) <= 1e-10 * b["loop_volume"]
    w = "loop_sq_mean_curvature"
    assert abs(b[w] - a[w]) <= 1e-10 * a[w]
    # the limit surface of a sphere-like mesh: W close to the round sphere's 4π
    assert 0.8 * 4 * np.pi < a[w] < 1.5 * 4 * np.pi


def test_evaluator_is_cached_with_the_topology():
    s = octasphere(2, jiggle=0.05)
    assert L.evaluator(s) is L.evaluator(s)


@pytest.mark.parametrize("name", sorted(L.KIND))
def test_gradient_matches_central_differences(name):
    s = octasphere(3, jiggle=0.05)
    decl = MethodDecl(method=name)
    idx = np.arange(s.nv)
    w = np.random.default_rng(4).uniform(0.5, 1.5, s.nv)
    g = L.gradient(s.evaluate(), decl, idx, w)
    X0 = s.X.copy()
    h = 1e-6
    rng = np.random.default_rng(5)
    scale = max(1.0, np.abs(g).max())
    for _ in range(8):
        i, k = rng.integers(s.nv), rng.integers(3)
        s.X = X0.copy(); s.X[i, k] += h
        ep = w @ L.values(s.evaluate(), decl, idx)
        s.X = X0.copy(); s.X[i, k] -= h
        em = w @ L.values(s.evaluate(), decl, idx)
        assert abs((ep - em) / (2 * h) - g[i, k]) <= FD * scale
    s.X = X0
