"""pyevolver.geometry.simplex: k-volumes and cone contents of simplices, and
their gradients against central differences."""
import math

import numpy as np
import pytest

from pyevolver.geometry import simplex as GS


def _fd(fn, P, h=1e-6):
    g = np.zeros_like(P)
    for idx in np.ndindex(*P.shape[1:]):
        Pp, Pm = P.copy(), P.copy()
        Pp[(slice(None),) + idx] += h
        Pm[(slice(None),) + idx] -= h
        g[(slice(None),) + idx] = (fn(Pp) - fn(Pm)) / (2 * h)
    return g


def test_unit_simplices():
    # the corner simplex of R^4 spanned by e1, e2, e3: volume 1/3! = 1/6
    P = np.zeros((1, 4, 4))
    P[0, 1:, :3] = np.eye(3)
    assert GS.simplex_areas(GS.simplex_sides(P))[0] == pytest.approx(1 / 6)
    # the regular tetrahedron of side sqrt(2) (e1..e4): sqrt(2)^3 / (6 sqrt(2)) = 1/3
    Q = np.eye(4)[None]
    assert GS.simplex_areas(GS.simplex_sides(Q))[0] == pytest.approx(1 / 3)
    # the cone from the origin over it: the 4-simplex, 1/4! = 1/24
    assert GS.cone_contents(Q)[0] == pytest.approx(1 / 24)
    # a triangle in R^3: half the cross product
    T = np.array([[[0, 0, 0], [2, 0, 0], [0, 3, 1.0]]])
    assert GS.simplex_areas(GS.simplex_sides(T))[0] == pytest.approx(
        0.5 * np.linalg.norm(np.cross([2, 0, 0], [0, 3, 1])))


@pytest.mark.parametrize("k,d", [(2, 3), (3, 4), (3, 5), (4, 5)])
def test_area_gradient_by_differences(k, d):
    rng = np.random.default_rng(k * 10 + d)
    P = rng.normal(size=(6, k + 1, d))
    A = GS.simplex_areas(GS.simplex_sides(P))
    g = GS.simplex_area_grad(GS.simplex_sides(P), A)
    fd = _fd(lambda Q: GS.simplex_areas(GS.simplex_sides(Q)), P)
    assert np.allclose(g, fd, atol=1e-7)


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_cone_gradient_by_differences(k):
    rng = np.random.default_rng(k)
    P = rng.normal(size=(5, k + 1, k + 1))
    assert np.allclose(GS.cone_content_grad(P), _fd(GS.cone_contents, P), atol=1e-8)
    # the cofactors: x_i . grad_i = det / (k+1)! for every corner
    g = GS.cone_content_grad(P)
    assert np.allclose(np.einsum("nid,nid->ni", P, g),
                       (np.linalg.det(P) / math.factorial(k + 1))[:, None])


def test_degenerate_and_empty():
    P = np.zeros((1, 4, 4))
    P[0, 1:, 0] = [1, 2, 3]                       # collinear corners
    S = GS.simplex_sides(P)
    A = GS.simplex_areas(S)
    assert A[0] == 0 and not np.any(GS.simplex_area_grad(S, A))
    E = np.zeros((0, 4, 4))
    assert GS.simplex_areas(GS.simplex_sides(E)).shape == (0,)
    assert GS.cone_contents(E).shape == (0,) and GS.cone_content_grad(E).shape == (0, 4, 4)
