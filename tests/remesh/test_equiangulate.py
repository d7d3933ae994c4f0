"""Direct tests of pyevolver.remesh.equiangulate: the Delaunay flip of a
diamond's shared edge, ``only`` / ``threshold=inf`` (edgeswap), FIXED."""
import numpy as np
import pytest

import pyevolver
from comparison import consistent
from pyevolver.remesh.equiangulate import equiangulate
from tolerances import ROUNDOFF


def _diamond(h):
    """Two triangles in the plane z=0 sharing the edge (-1,0)-(1,0), apexes
    (0, ±h): for h < 1 the shared edge is the long diagonal."""
    X = np.array([[-1.0, 0, 0], [1.0, 0, 0], [0, h, 0], [0, -h, 0]])
    F = np.array([[0, 1, 2], [1, 0, 3]])
    return pyevolver.Surface.from_arrays(X, F)


def _shared(s):
    idx = s.topology()[0]
    val = np.bincount(idx.ravel(), minlength=s.ne)
    (e,) = np.nonzero(val == 2)[0]
    return int(e)


def _area(s):
    return s.evaluate().total_area


def test_skinny_diamond_flips_long_diagonal():
    s = _diamond(0.1)
    e = _shared(s)
    t, n = equiangulate(s)
    assert n == 1
    consistent(t)
    assert sorted(t.E[e].tolist()) == [2, 3]          # now the short diagonal
    assert sorted(s.E[e].tolist()) == [0, 1]          # input untouched
    assert (t.nv, t.ne, t.nf) == (4, 5, 2)
    # a convex planar quadrilateral: the same area (2 * 0.1) either way
    assert _area(t) == pytest.approx(0.2, rel=ROUNDOFF)
    # both facets keep their orientation (normals +z as before)
    N = t.evaluate().facet_N2
    assert np.all(np.asarray(N)[:, 2] > 0)
    # the short diagonal satisfies the criterion: a second pass does nothing
    assert equiangulate(t)[1] == 0


def test_fat_diamond_is_left_alone():
    s = _diamond(2.0)
    t, n = equiangulate(s)
    assert n == 0
    assert t is s


def test_only_mask_and_infinite_threshold():
    s = _diamond(0.1)
    e = _shared(s)
    none = np.zeros(s.ne, bool)
    assert equiangulate(s, only=none)[1] == 0
    # edgeswap: threshold inf flips the chosen edge whatever its angles
    fat = _diamond(2.0)
    only = np.zeros(fat.ne, bool)
    only[e] = True
    t, n = equiangulate(fat, threshold=np.inf, only=only)
    assert n == 1
    consistent(t)
    assert sorted(t.E[e].tolist()) == [2, 3]
    assert _area(t) == pytest.approx(4.0, rel=ROUNDOFF)


def test_fixed_edge_is_not_flipped():
    s = _diamond(0.1)
    s.eattr["fixed"] = s.eattr["fixed"].copy()
    s.eattr["fixed"][_shared(s)] = True
    assert equiangulate(s)[1] == 0


def test_unequal_tension_is_not_flipped():
    s = _diamond(0.1)
    s.fattr["tension"] = np.array([1.0, 2.0])
    assert equiangulate(s)[1] == 0


def test_edge_lengths_are_the_norms_to_the_bit():
    from pyevolver.remesh.equiangulate import _edge_lengths
    rng = np.random.default_rng(1)
    X = rng.normal(size=(500, 3)) * 10.0 ** rng.uniform(-6, 6, (500, 1))
    E = rng.integers(0, 500, (20000, 2))
    want = np.linalg.norm(X[E[:, 1]] - X[E[:, 0]], axis=1)
    assert np.array_equal(_edge_lengths(X, E), want)
