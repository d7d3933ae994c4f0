"""A Surface from arrays (pyevolver/model/arrays.py) equals the same mesh
loaded from a datafile."""
import io

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.datafile.reader import read_datafile
from pyevolver.model.arrays import surface_from_arrays, triangle_edges
from pyevolver.model.build import build_surface
from pyevolver.studies.meshes import fe_text, icosphere

# the regular octahedron, outward-oriented triangles
X = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
              [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])

# the same octahedron written by hand as a datafile (edges in another order)
OCTA_FE = """
vertices
1 1 0 0
2 -1 0 0
3 0 1 0
4 0 -1 0
5 0 0 1
6 0 0 -1

edges
1 1 3
2 3 2
3 2 4
4 4 1
5 1 5
6 3 5
7 2 5
8 4 5
9 1 6
10 3 6
11 2 6
12 4 6

faces
1 1 6 -5
2 2 7 -6
3 3 8 -7
4 4 5 -8
5 -1 9 -10
6 -2 10 -11
7 -3 11 -12
8 -4 12 -9

bodies
1 1 2 3 4 5 6 7 8
"""


def _pairs(s):
    return sorted(tuple(sorted(e)) for e in s.E.tolist())


def test_octahedron_from_arrays_equals_the_datafile(tmp_path):
    path = tmp_path / "octa.fe"
    path.write_text(OCTA_FE)
    ref = Session.load(str(path), out=io.StringIO()).surface
    s = surface_from_arrays(X, F, body=True)
    t, tr = s.evaluate(), ref.evaluate()
    assert t.total_area == pytest.approx(tr.total_area, rel=1e-15)
    assert t.total_area == pytest.approx(8 * np.sqrt(3) / 2, rel=1e-15)
    assert t.volumes[0] == pytest.approx(tr.volumes[0], rel=1e-15)
    assert t.volumes[0] == pytest.approx(4 / 3, rel=1e-15)
    assert t.energy == pytest.approx(tr.energy, rel=1e-15)
    assert (s.nv, s.ne, s.nf, s.bodies.n) == (6, 12, 8, 1)
    assert _pairs(s) == _pairs(ref)
    np.testing.assert_array_equal(s.X, ref.X)


def test_arrays_equal_the_fe_text_of_the_same_arrays():
    """Element for element the surface of the datafile the mesh writes as."""
    Xi, Fi = icosphere(2)
    a = surface_from_arrays(Xi, Fi)
    b = build_surface(read_datafile("x.fe", fe_text(Xi, Fi)))
    for k in ("X", "E", "F"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    for attrs in ("vattr", "eattr", "fattr"):
        A, B = getattr(a, attrs), getattr(b, attrs)
        assert A.keys() == B.keys()
        for k in A:
            np.testing.assert_array_equal(A[k], B[k])
    assert a.evaluate().energy == b.evaluate().energy


def test_fixed_tension_and_2d_points():
    s = surface_from_arrays(X[:, :2][[0, 1, 2]], [[0, 1, 2]], fixed=[1, 0, 0], tension=[2.0])
    assert s.X[:, 2].tolist() == [0, 0, 0]
    assert s.vattr["fixed"].tolist() == [True, False, False]
    assert s.evaluate().energy == pytest.approx(2.0 * 1.0)     # area 1, tension 2


def test_bad_arrays_are_refused():
    with pytest.raises(ValueError):
        surface_from_arrays(X, [[0, 1, 6]])
    with pytest.raises(ValueError):
        surface_from_arrays(np.zeros((3, 4)), [[0, 1, 2]])


def test_triangle_edges():
    E, idx = triangle_edges(F)
    assert E.shape == (12, 2) and np.all(E[:, 0] < E[:, 1])
    for f, sides in zip(F, idx):
        for k in range(3):
            assert sorted(E[sides[k]]) == sorted((f[k], f[(k + 1) % 3]))
    E0, idx0 = triangle_edges(np.zeros((0, 3), int))
    assert E0.shape == (0, 2) and idx0.shape == (0, 3)
