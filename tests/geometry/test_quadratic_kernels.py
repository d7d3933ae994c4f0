"""The quadratic-model kernels (pyevolver.geometry.quadratic): the rules'
exactness, the shape functions, and a quadratic-patch sphere whose area
converges to 4π at the quadratic model's order (closed-form geometry)."""
import math

import numpy as np

from pyevolver.geometry import quadratic as Q
from tolerances import ROUNDOFF


def test_rules_integrate_their_degree_exactly():
    # ∫ l1^i l2^j over the unit triangle = 2 i! j! / (i+j+2)!  (weights sum to 1)
    for i in range(6):
        for j in range(6 - i):
            exact = 2 * math.factorial(i) * math.factorial(j) / math.factorial(i + j + 2)
            got = np.sum(Q.TRI7_W * Q.TRI7_B[:, 1] ** i * Q.TRI7_B[:, 2] ** j)
            assert abs(got - exact) < ROUNDOFF
    for k in range(6):
        assert abs(np.sum(Q.GL3_W * Q.GL3_T ** k) - 1 / (k + 1)) < ROUNDOFF


def test_shape_functions_interpolate_the_nodes():
    nodes = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [.5, .5, 0], [0, .5, .5], [.5, 0, .5]])
    N, Nu, Nv = Q.tri6_shape(nodes)
    assert np.allclose(N, np.eye(6))
    # derivatives sum to zero (a constant field), values to one anywhere
    assert np.allclose(Q.TRI7_N.sum(1), 1) and np.allclose(Q.TRI7_NU.sum(1), 0)
    N, Nt = Q.edge3_shape(np.array([0.0, 1.0, 0.5]))
    assert np.allclose(N, np.eye(3)) and np.allclose(Nt.sum(1), 0)


def test_parabola_edge_length():
    # the curve through (0,0), (1/2, 1/8), (1, 0): y = x(1-x)/2, length by formula
    P = np.array([[[0, 0, 0], [1, 0, 0], [0.5, 0.125, 0]]], float)
    X, Xt = Q.edge_frames(P)
    assert np.allclose(X[0, :, 1], X[0, :, 0] * (1 - X[0, :, 0]) / 2)
    L = np.linalg.norm(Xt, axis=2) @ Q.GL3_W
    exact = (math.asinh(0.5) + 0.5 * math.sqrt(1.25))    # ∫_0^1 sqrt(1 + (1/2 - x)^2) dx
    assert abs(L[0] - exact) < 1e-4


def _octa_sphere(level):
    """Quadratic patches of the octahedron split ``level`` times, all nodes on
    the unit sphere: (nf, 6, 3)."""
    V = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1]], float)
    F = [[0, 1, 2], [1, 3, 2], [3, 4, 2], [4, 0, 2], [1, 0, 5], [3, 1, 5], [4, 3, 5], [0, 4, 5]]
    T = np.array([[V[a], V[b], V[c]] for a, b, c in F])
    for _ in range(level):
        a, b, c = T[:, 0], T[:, 1], T[:, 2]
        ab, bc, ca = (a + b) / 2, (b + c) / 2, (c + a) / 2
        T = np.concatenate([np.stack(t, 1) for t in
                            ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
        T /= np.linalg.norm(T, axis=2)[..., None]
    P = np.concatenate([T, (T + np.roll(T, -1, axis=1)) / 2], axis=1)
    return P / np.linalg.norm(P, axis=2)[..., None]


def test_sphere_area_converges_to_4pi():
    errs = []
    for level in range(1, 5):
        X, Xu, Xv = Q.patch_frames(_octa_sphere(level))
        A = np.linalg.norm(np.cross(Xu, Xv), axis=2) @ (Q.TRI7_W / 2)
        errs.append(abs(A.sum() - 4 * math.pi))
    assert errs[-1] < 1e-4
    # the quadratic model's order: the error falls ~16-fold per halving (h^4)
    rates = [errs[k] / errs[k + 1] for k in range(len(errs) - 1)]
    assert min(rates[1:]) > 12, rates
    Q6 = Q.patch_points(_octa_sphere(1), np.array([[1 / 3, 1 / 3, 1 / 3]]))
    assert Q6.shape == (32, 1, 3)
