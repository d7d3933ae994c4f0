"""pyevolver.methods.curvature_hessian: the analytic Hessians of the
curvature energies are symmetric and their product with a vector equals the
central difference of the analytic gradients (which test_curvature.py checks
against differences of the values), on an irregular closed surface; the
registry entries of the family point at these functions."""
import numpy as np
import pytest

from comparison import octasphere
from tolerances import FD, ROUNDOFF
from pyevolver.methods import curvature_hessian as CH
from pyevolver.methods.registry import lookup
from pyevolver.model.scene import MethodDecl


CASES = [("star_sq_mean_curvature", CH.vertex_hessian),
         ("sq_mean_curvature", CH.vertex_hessian),
         ("mean_curvature_integral", CH.mci_hessian),
         ("mean_curvature_integral_a", CH.mci_hessian),
         ("star_gauss_curvature", CH.star_gauss_hessian),
         ("sq_gauss_curvature", CH.sq_gauss_hessian),
         ("cotan_sq_mean_curvature", CH.cotan_hessian)]


@pytest.mark.parametrize("name,hess", CASES)
def test_hessian_symmetric_and_equal_to_gradient_differences(name, hess):
    s = octasphere(1)
    m = lookup(name)
    assert m.hessian is hess
    decl = MethodDecl(method=name)
    n = s.nv if m.etype == "vertex" else s.ne
    idx = np.arange(n)
    w = np.random.default_rng(2).uniform(0.5, 1.5, n)
    X0 = s.X.copy()
    D = hess(s.evaluate(), decl, idx, w).toarray()
    assert D.shape == (3 * s.nv, 3 * s.nv)
    scale = max(1.0, np.abs(D).max())
    assert np.abs(D - D.T).max() <= ROUNDOFF * 100 * scale
    v = np.random.default_rng(3).standard_normal((s.nv, 3))
    eps = 1e-6
    s.X = X0 + eps * v
    gp = m.gradient(s.evaluate(), decl, idx, w)
    s.X = X0 - eps * v
    gm = m.gradient(s.evaluate(), decl, idx, w)
    s.X = X0
    Hv = (gp - gm).ravel() / (2 * eps)
    assert np.abs(D @ v.ravel() - Hv).max() <= FD * scale


def test_translation_leaves_the_energy_unchanged():
    """A rigid translation is in the kernel of every Hessian."""
    s = octasphere(4)
    T = np.tile([0.3, -1.0, 0.7], s.nv)
    for name, hess in CASES:
        m = lookup(name)
        n = s.nv if m.etype == "vertex" else s.ne
        D = hess(s.evaluate(), MethodDecl(method=name), np.arange(n), np.ones(n))
        assert np.abs(D @ T).max() <= 1e-9 * max(1.0, abs(D).max()), name
