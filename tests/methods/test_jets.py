"""pyevolver.methods.jets: second-order jets.  The value, gradient and
Hessian each jet carries are checked against the closed form and against
central differences of the value (gradients) and of the gradient (Hessians)."""
import numpy as np

from tolerances import FD, ROUNDOFF
from pyevolver.methods import jets as J

H = 1e-6


def _fd(fn, P):
    """Central differences of fn(P (m, k, 3)) -> (m,) or (m, n): (m, n[, n])."""
    m, k, _ = P.shape
    cols = []
    for i in range(k):
        for c in range(3):
            Pp, Pm = P.copy(), P.copy()
            Pp[:, i, c] += H
            Pm[:, i, c] -= H
            cols.append((fn(Pp) - fn(Pm)) / (2 * H))
    return np.stack(cols, axis=-1)


def _check(make, P):
    """make(points jets) -> scalar jet; compare g and H with differences."""
    s = make(J.points(P))
    g = _fd(lambda Q: make(J.points(Q)).v, P)
    Hn = _fd(lambda Q: make(J.points(Q)).g, P)
    scale = max(1.0, np.abs(s.H).max())
    assert np.abs(s.g - g).max() <= FD * max(1.0, np.abs(s.g).max())
    assert np.abs(s.H - Hn).max() <= FD * scale
    assert np.abs(s.H - np.swapaxes(s.H, 1, 2)).max() <= ROUNDOFF * scale


def test_skew_is_the_cross_product_matrix():
    rng = np.random.default_rng(0)
    v, u = rng.standard_normal((2, 4, 3))
    M = J.skew(v)
    assert np.allclose(np.einsum("mij,mj->mi", M, u), np.cross(v, u), atol=ROUNDOFF)
    assert np.allclose(M, -np.swapaxes(M, 1, 2))


def test_triangle_area_jet():
    """|(x1-x0) × (x2-x0)| / 2: value is the area; a right unit triangle has 1/2."""
    P = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], float)

    def area(p):
        return J.norm(J.cross(p[1] - p[0], p[2] - p[0])) * 0.5
    a = area(J.points(P))
    assert abs(a.v[0] - 0.5) <= ROUNDOFF
    # the area gradient at corner c is ½ n × (opposite side): at x0 it is (-1/2, -1/2, 0)
    assert np.allclose(a.g[0, :3], [-0.5, -0.5, 0.0], atol=ROUNDOFF)
    rng = np.random.default_rng(1)
    _check(area, rng.standard_normal((6, 3, 3)))


def test_products_quotients_and_atan2():
    rng = np.random.default_rng(2)
    P = rng.standard_normal((5, 3, 3)) + np.array([0, 0, 3.0])   # keep the quotient away from 0

    def f(p):
        a, b = p[1] - p[0], p[2] - p[0]
        d = J.dot(a, b)
        n = J.norm(J.cross(a, b))
        return J.atan2(n, d) + d * n / J.dot(p[2], p[2]) - J.dot(p[0] * d, p[1])
    _check(f, P)
    # the angle at corner 0 from atan2(|a×b|, a·b)
    Q = np.array([[[0, 0, 0], [2, 0, 0], [1, 1, 0]]], float)
    p = J.points(Q)
    ang = J.atan2(J.norm(J.cross(p[1] - p[0], p[2] - p[0])), J.dot(p[1] - p[0], p[2] - p[0]))
    assert abs(ang.v[0] - np.pi / 4) <= ROUNDOFF


def test_vector_jet_scaled_by_a_scalar_jet_and_cross_const():
    rng = np.random.default_rng(3)
    P = rng.standard_normal((4, 2, 3))
    c = rng.standard_normal((4, 3))
    w = rng.standard_normal((4, 3))

    def g(p):
        s = J.dot(p[0], p[1])
        V = (p[1] - p[0]) * s
        W = J.cross_const(V, c)
        const = J.V(w, np.zeros((len(w), 3, 6)))
        return J.dot(W, const) + J.dot(V, V)
    _check(g, P)
    v = g(J.points(P)).v
    a = (P[:, 1] - P[:, 0]) * np.einsum("mk,mk->m", P[:, 0], P[:, 1])[:, None]
    assert np.allclose(v, np.einsum("mk,mk->m", np.cross(a, c), w) + (a * a).sum(1),
                       atol=ROUNDOFF * 100)
