"""Direct tests of pyevolver.remesh.vertex_average on small meshes: a square
of four triangles round a movable centre vertex, corners FIXED."""
import numpy as np
import pytest

import pyevolver
from pyevolver.remesh.vertex_average import vertex_average
from tolerances import ROUNDOFF

CORNERS = [[1, 1, 0], [-1, 1, 0], [-1, -1, 0], [1, -1, 0]]
FACETS = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])


def _square(centre):
    X = np.array(CORNERS + [centre], float)
    fixed = np.array([True] * 4 + [False])
    return pyevolver.Surface.from_arrays(X, FACETS, fixed=fixed)


def _tri_area(P):
    return 0.5 * np.linalg.norm(np.cross(P[1] - P[0], P[2] - P[0]))


def _expected_centre(X):
    """Spec §8.3: edge weights w_e = summed area of the facets on the edge,
    D = sum w_e^2 (x_e - x_v) / sum w_e^2, x_v += D / 4."""
    c = X[4]
    A = [_tri_area(X[f]) for f in FACETS]
    D, W = np.zeros(3), 0.0
    for k in range(4):                    # edge corner k -> centre: facets k-1 and k
        w = A[k] + A[k - 1]
        D += w * w * (X[k] - c)
        W += w * w
    return c + D / W / 4


def test_symmetric_centre_does_not_move():
    s = _square([0, 0, 0])
    for mode in ("V", "raw", "rawest"):
        t = vertex_average(s, mode)
        assert np.allclose(t.X, s.X, atol=ROUNDOFF)


def test_offset_centre_moves_by_area_weighted_quarter_step():
    s = _square([0.3, 0.1, 0])
    exp = _expected_centre(s.X)
    for mode in ("V", "raw", "rawest"):
        t = vertex_average(s, mode)
        assert np.allclose(t.X[4], exp, atol=1e-14)
        assert np.array_equal(t.X[:4], s.X[:4])      # FIXED corners stay
        assert t.X[4, 2] == 0.0                       # stays in the plane
    # the input keeps its coordinates
    assert np.array_equal(s.X[4], [0.3, 0.1, 0])
    # and the centre came closer to the middle
    assert np.linalg.norm(exp[:2]) < np.linalg.norm([0.3, 0.1])


def test_V_removes_normal_component_rawest_does_not():
    # a pyramid apex: the average pulls it straight down, along its normal
    s = _square([0, 0, 0.5])
    t = vertex_average(s, "V")
    assert np.allclose(t.X[4], [0, 0, 0.5], atol=ROUNDOFF)
    r = vertex_average(s, "rawest")
    # D = (0, 0, -0.5) by symmetry; x += D/4
    assert np.allclose(r.X[4], [0, 0, 0.375], atol=ROUNDOFF)


def test_fixed_vertex_does_not_move():
    X = np.array(CORNERS + [[0.3, 0.1, 0]], float)
    s = pyevolver.Surface.from_arrays(X, FACETS, fixed=np.ones(5, bool))
    t = vertex_average(s, "rawest")
    assert np.array_equal(t.X, s.X)
