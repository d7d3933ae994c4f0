"""pyevolver.methods.basic: areas, volumes, lengths and gravity of the
unit cube and the octahedron (analytic values), their gradients against
central differences, their Hessians (symmetric; H v against the difference
of gradients)."""
import numpy as np

from tolerances import FD, ROUNDOFF
import pyevolver
from pyevolver import Session
from pyevolver.methods import basic as B

OCT_X = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
OCT_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
H = 1e-6


def _irregular(seed):
    rng = np.random.default_rng(seed)
    return pyevolver.Surface.from_arrays(OCT_X + 0.15 * rng.standard_normal(OCT_X.shape), OCT_F,
                                         body=True)


def _facet_values(P, what):
    x0, x1, x2 = P[:, 0], P[:, 1], P[:, 2]
    if what == "area":
        return 0.5 * np.linalg.norm(np.cross(x1 - x0, x2 - x0), axis=1)
    cz = (x1[:, 0] - x0[:, 0]) * (x2[:, 1] - x0[:, 1]) - (x1[:, 1] - x0[:, 1]) * (x2[:, 0] - x0[:, 0])
    z = P[:, :, 2]
    if what == "zflux":
        return z.sum(1) / 6.0 * cz
    if what == "symmetric":
        return np.einsum("ij,ij->i", x0, np.cross(x1, x2)) / 6.0
    S = (z * z).sum(1) + z[:, 0] * z[:, 1] + z[:, 1] * z[:, 2] + z[:, 0] * z[:, 2]
    return S / 24.0 * cz                                    # gravity


def _corner_fd(P, what):
    g = np.zeros_like(P)
    for c in range(3):
        for k in range(3):
            Pp, Pm = P.copy(), P.copy()
            Pp[:, c, k] += H
            Pm[:, c, k] -= H
            g[:, c, k] = (_facet_values(Pp, what) - _facet_values(Pm, what)) / (2 * H)
    return g


def test_cube_and_octahedron_values():
    s = Session.load("datafiles/cube.fe").surface
    t = s.evaluate()
    idx = np.arange(s.nf)
    assert abs(B._facet_area(t, None, idx).sum() - 6.0) <= ROUNDOFF * 6
    assert abs(B._facet_volume(t, None, idx).sum() - 1.0) <= ROUNDOFF
    o = pyevolver.Surface.from_arrays(OCT_X, OCT_F, body=True)
    to = o.evaluate()
    assert abs(B._facet_area(to, None, np.arange(8)).sum() - 4 * np.sqrt(3)) <= ROUNDOFF * 8
    assert abs(B._facet_volume(to, None, np.arange(8)).sum() - 4.0 / 3.0) <= ROUNDOFF * 8
    assert np.allclose(B._edge_length(to, None, np.arange(o.ne)), np.sqrt(2), atol=ROUNDOFF)
    P = o.X[o.F]
    # both volume integrands give the enclosed volume on a closed surface
    assert abs(_facet_values(P, "symmetric").sum() - 4.0 / 3.0) <= ROUNDOFF * 8
    assert abs(_facet_values(P, "zflux").sum() - 4.0 / 3.0) <= ROUNDOFF * 8
    # ∭ z dV = 0 for the octahedron: its gravity integral (∯ z²/2 n_z) vanishes
    assert abs(_facet_values(P, "gravity").sum()) <= ROUNDOFF * 8


def test_per_corner_gradients_match_central_differences():
    s = _irregular(0)
    t = s.evaluate()
    P = s.X[s.F]
    cases = [(B.facet_area_grad(t), "area"),
             (B.facet_volume_grad(t, False), "zflux"),
             (B.facet_volume_grad(t, True), "symmetric"),
             (B.facet_gravity_grad(t), "gravity")]
    for g, what in cases:
        assert np.abs(g - _corner_fd(P, what)).max() <= FD, what


def test_registered_gradients_against_differences_of_the_values():
    s = _irregular(1)
    rng = np.random.default_rng(2)
    wf = rng.uniform(0.5, 2.0, s.nf)
    we = rng.uniform(0.5, 2.0, s.ne)
    fidx, eidx = np.arange(s.nf), np.arange(s.ne)

    def total(t):
        return (wf @ B._facet_area(t, None, fidx), we @ B._edge_length(t, None, eidx),
                wf @ B._facet_volume(t, None, fidx))
    t = s.evaluate()
    grads = [B._area_gradient(t, None, fidx, wf), B._length_gradient(t, None, eidx, we),
             B._volume_gradient(t, None, fidx, wf)]
    X0 = s.X.copy()
    for i in range(s.nv):
        for k in range(3):
            s.X = X0.copy(); s.X[i, k] += H
            ep = total(s.evaluate())
            s.X = X0.copy(); s.X[i, k] -= H
            em = total(s.evaluate())
            for g, a, b in zip(grads, ep, em):
                assert abs((a - b) / (2 * H) - g[i, k]) <= FD * max(1.0, np.abs(g).max())
    s.X = X0


def test_hessians_are_symmetric_and_match_gradient_differences():
    s = _irregular(3)
    rng = np.random.default_rng(4)
    wf = rng.uniform(0.5, 2.0, s.nf)
    we = rng.uniform(0.5, 2.0, s.ne)
    fidx, eidx = np.arange(s.nf), np.arange(s.ne)
    pairs = [(B._area_gradient, B._area_hessian, fidx, wf),
             (B._volume_gradient, B._volume_hessian, fidx, wf),
             (B._length_gradient, B._length_hessian, eidx, we)]
    v = rng.standard_normal((s.nv, 3))
    X0 = s.X.copy()
    eps = 1e-6
    for grad, hess, idx, w in pairs:
        s.X = X0.copy()
        D = hess(s.evaluate(), None, idx, w).toarray()
        assert np.abs(D - D.T).max() <= ROUNDOFF * max(1.0, np.abs(D).max()), hess.__name__
        s.X = X0 + eps * v
        gp = grad(s.evaluate(), None, idx, w)
        s.X = X0 - eps * v
        gm = grad(s.evaluate(), None, idx, w)
        Hv = ((gp - gm) / (2 * eps)).ravel()
        assert np.abs(D @ v.ravel() - Hv).max() <= FD * max(1.0, np.abs(D).max()), hess.__name__
    s.X = X0
