"""The Hessian of quantity FUNCTIONs nonlinear in their instances' values
(issue 27): the low-rank term ``Σ ∂²f/∂v_i∂v_j ∇v_i ∇v_jᵀ`` carried as
auxiliary unknowns of the bordered system (:meth:`HessianSystem.border`).

Checked against central differences of the analytic gradient (Hessian-vector
products), and the border algebra (solve, inertia) against dense linear
algebra; the steps against evolver-nox-d are in
tests/reference/test_quantity_function_reference.py.
"""
import io

import numpy as np
import pytest

from conftest import example
from pyevolver import Session
from pyevolver.errors import CommandError
from pyevolver.evolve import hessian as H
from pyevolver.evolve import symfactor as SF
from pyevolver.evolve.eigen import ShiftedFactor

#: one FUNCTION of one instance (positive curvature) and one of two
#: instances whose second derivative (2×2) is indefinite: both signs of W
TOPS = {
    "ade": ("parameter kk = 0.7\nparameter m0 = 5\n"
            "method_instance mci method mean_curvature_integral global\n"
            "quantity ade energy function kk*(mci.value - m0)^2\n"),
    "mixed": ("method_instance mci method mean_curvature_integral global\n"
              "method_instance ar method facet_area global\n"
              "quantity mix energy modulus 0.5 function "
              "0.3*(mci.value - 5)^2 + mci.value*ar.value - 0.2*ar.value^2 + pi\n"),
}


def _session(tmp_path, top, seed=3, scale=0.04):
    text = open(example("cube.fe"), encoding="utf-8").read()
    path = tmp_path / "cube_f.fe"
    path.write_text(top + text[:text.index("\nread")] + "\n")
    s = Session.load(str(path), out=io.StringIO(), err=io.StringIO())
    s.refine(echo=False)
    s.surface.X += scale * np.random.default_rng(seed).standard_normal(s.surface.X.shape)
    s.surface.bodies.lagrange[:] = 0.4      # a multiplier, so the volume's Hessian enters
    return s


@pytest.mark.parametrize("name", sorted(TOPS))
@pytest.mark.parametrize("normal", [False, True])
def test_hessian_vector_products_match_differences(tmp_path, name, normal):
    s = _session(tmp_path, TOPS[name])
    hs = H.hessian_system(s.iterator, normal=normal, lowrank=True)
    assert hs.W is not None
    if name == "mixed":
        assert sorted(hs.Wsign) == [-1.0, 1.0]          # an indefinite 2×2 term
    S = s.surface
    gL = H.lagrangian_gradient(hs.cons, hs.lam)
    X0 = S.X.copy()
    rng = np.random.default_rng(1)
    h = 1e-6
    for _ in range(3):
        v = rng.standard_normal(hs.K.shape[0])
        dx = (hs.T @ v).reshape(X0.shape)
        try:
            S.X = X0 + h * dx
            gp = hs.T.T @ gL(S.evaluate()).ravel()
            S.X = X0 - h * dx
            gm = hs.T.T @ gL(S.evaluate()).ravel()
        finally:
            S.X = X0
        fd = (gp - gm) / (2 * h)
        Hv = hs.K @ v + hs.W @ (hs.Wsign * (hs.W.T @ v))
        assert np.abs(Hv - fd).max() <= 1e-7 * np.abs(fd).max(), np.abs(Hv - fd).max()
        # without the rank term the product is wrong: the test can fail
        assert np.abs(hs.K @ v - fd).max() > 1e-3 * np.abs(fd).max()


def _dense_case(seed, n=30, k=2, signs=(1.0, -1.0)):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    K = A + A.T + np.diag(np.linspace(-3, 12, n))        # indefinite, nonsingular
    B = rng.standard_normal((n, k))
    W = 2.0 * rng.standard_normal((n, len(signs)))
    return K, B, W, np.array(signs)


@pytest.mark.parametrize("signs", [(1.0,), (-1.0,), (1.0, -1.0), (1.0, 1.0, -1.0)])
def test_border_solve_and_inertia_equal_dense(signs):
    """``[[K, B, W], [Bᵀ, 0, 0], [Wᵀ, 0, −diag(s)]]`` solves and counts as
    the dense ``K + W diag(s) Wᵀ`` with the border ``B``."""
    import scipy.sparse as sp
    K, B, W, sg = _dense_case(5, signs=signs)
    n, k = B.shape
    M = K + (W * sg) @ W.T
    r, d = np.linspace(-1, 1, n), np.array([0.3, -0.2])
    # the dense KKT solution of M
    kkt = np.block([[M, B], [B.T, np.zeros((k, k))]])
    want = np.linalg.solve(kkt, np.concatenate([r, d]))
    Bx = np.hstack([B, W])
    dx = np.concatenate([d, np.zeros(len(sg))])
    D = np.concatenate([np.zeros(k), -sg])
    Ks = sp.csc_matrix(K)
    got = H.solve_bordered(Ks, Bx, r, dx, method="splu", D=D)
    assert np.allclose(got[:n + k], want, rtol=1e-10, atol=1e-12)
    got2, index = SF.newton_solve(Ks, Bx, r, dx, D=D)
    assert np.allclose(got2[:n + k], want, rtol=1e-9, atol=1e-11)
    # the index: negative eigenvalues of M on Bᵀ y = 0
    Z = np.linalg.qr(B, mode="complete")[0][:, k:]
    ev = np.linalg.eigvalsh(Z.T @ M @ Z)
    assert index == int(np.sum(ev < 0))
    # refined on K + δI (hessian's path on large systems): K's solution, the
    # index of M + δI (no eigenvalue of M within δ of 0 here)
    assert np.abs(ev).min() > 1e-2
    got3, index3 = SF.newton_solve(Ks, Bx, r, dx, D=D, delta=1e-3)
    assert np.allclose(got3[:n + k], want, rtol=1e-9, atol=1e-11)
    assert index3 == int(np.sum(ev < 0))
    inert = ShiftedFactor(Ks, Bx, 0.0, 0.0, D=D).inertia()
    assert (inert.below, inert.above) == (int(np.sum(ev < 0)), int(np.sum(ev > 0)))


@pytest.mark.parametrize("signs", [(1.0,), (-1.0,), (1.0, -1.0)])
@pytest.mark.parametrize("shift", [0.0, 4.0, 40.0])
def test_lowrank_factor_tells_positive_definite_and_solves(signs, shift):
    """The damped ``newton``'s factorization of ``M + W diag(s) Wᵀ``
    (newton._factor_lowrank) is None exactly when the dense matrix has an
    eigenvalue ≤ 0, and otherwise solves it."""
    import scipy.sparse as sp
    from pyevolver.evolve.newton import _factor_lowrank
    K, _, W, sg = _dense_case(7, signs=signs)
    M = K + shift * np.eye(len(K))
    dense = M + (W * sg) @ W.T
    f = _factor_lowrank(sp.csc_matrix(M), W, sg)
    pd = np.linalg.eigvalsh(dense).min() > 0
    assert (f is not None) == pd
    if pd:
        R = np.random.default_rng(2).standard_normal((len(K), 2))
        assert np.allclose(f(R), np.linalg.solve(dense, R), rtol=1e-10, atol=1e-12)


def test_damped_newton_with_a_nonlinear_function(tmp_path):
    """``newton`` with an ADE-like FUNCTION energy (the rank term of its
    Hessian by the Woodbury formula) converges quadratically: the damping
    falls to nothing, the normal forces vanish and the Hessian there has no
    negative eigenvalue on the fixed volume (a minimum: ``hessian`` barely
    moves it).  (m0 near the closed surface's own integral of the mean
    curvature; far from it the FUNCTION folds this coarse mesh.)"""
    from pyevolver.evolve.newton import damped_newton
    s = _session(tmp_path, TOPS["ade"].replace("m0 = 5", "m0 = 7.2"))
    s.run("g 2")
    e0 = s.value("total_energy")

    def normal_force():           # (the part of −∇E off the volume's gradient)
        hs = H.hessian_system(s.iterator, normal=True, lowrank=True)
        Q = np.linalg.qr(hs.B, mode="complete")[0][:, hs.B.shape[1]:]     # Bᵀ y = 0
        return hs, Q, np.abs(Q.T @ hs.rhs).max()
    f0 = normal_force()[2]
    res = damped_newton(s.iterator, 30)
    assert res.success and res.message.startswith("converged"), res.message
    assert res.energy < e0
    hs, Q, f1 = normal_force()
    assert hs.W is not None
    assert res.delta < 1e-3 * float(np.abs(hs.K.diagonal()).mean())
    assert f1 < 1e-4 * f0, (f0, f1)
    Kd = hs.K.toarray() + (hs.W * hs.Wsign) @ hs.W.T
    ev = np.linalg.eigvalsh(Q.T @ Kd @ Q)
    assert ev.min() > 0
    s.run("hessian")
    assert s.value("total_energy") == pytest.approx(res.energy, rel=1e-9)
