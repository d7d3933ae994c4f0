"""pyevolver.methods.attributes: whole-array element attributes.

Analytic values on the regular octahedron (|x|=1 vertices): at every vertex
the area gradient is F = 4/√3 along the radius, the area-vector sum N = 2
and the star area A = 2√3, so ``mean_curvature`` = 3 F·N / (2 N·N) = √3,
``sqcurve`` = (3|F| / 2A)² = 1 (effective area: 3; normal: 3), and the
edge ``dihedral`` is π − acos(−1/3) = acos(1/3).  evolver-nox-d prints
1.7320508075688776, 1.0000000000000004 and 1.2309594173407747 for them.
"""
import io

import numpy as np

from tolerances import PRINTED, ROUNDOFF
import pyevolver
from pyevolver import Session
from pyevolver.methods import attributes as A

OCT_X = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
OCT_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def test_octahedron_star_sums_and_curvatures():
    s = pyevolver.Surface.from_arrays(OCT_X, OCT_F, body=True)
    t = s.evaluate()
    Ar, F, N = A.star_sums_projected(s, t)
    assert np.allclose(Ar, 2 * np.sqrt(3), atol=ROUNDOFF)
    assert np.allclose(F, OCT_X * 4 / np.sqrt(3), atol=ROUNDOFF)
    assert np.allclose(N, OCT_X * 2, atol=ROUNDOFF)
    assert np.allclose(A.vertex_mean_curvature(s, t), np.sqrt(3), rtol=PRINTED)
    assert np.allclose(A.vertex_sqcurve(s, t), 1.0, rtol=PRINTED)
    assert np.allclose(A.vertex_sqcurve(s, t, "eff"), 3.0, rtol=PRINTED)
    assert np.allclose(A.vertex_sqcurve(s, t, "norm"), 3.0, rtol=PRINTED)
    assert np.allclose(A.edge_dihedral(s, t), np.arccos(1 / 3), rtol=PRINTED)
    # the reversed orientation flips the sign of mean_curvature only
    r = pyevolver.Surface.from_arrays(OCT_X, OCT_F[:, ::-1])
    tr = r.evaluate()
    assert np.allclose(A.vertex_mean_curvature(r, tr), -np.sqrt(3), rtol=PRINTED)
    assert np.allclose(A.vertex_sqcurve(r, tr), 1.0, rtol=PRINTED)


def test_fixed_vertices_have_no_sqcurve():
    fixed = np.array([1, 0, 0, 0, 1, 0])
    s = pyevolver.Surface.from_arrays(OCT_X, OCT_F, fixed=fixed)
    t = s.evaluate()
    h2 = A.vertex_sqcurve(s, t)
    assert np.array_equal(h2 == 0, fixed == 1)
    assert np.allclose(A.vertex_mean_curvature(s, t), np.sqrt(3))     # all vertices


def test_cube_edge_dihedrals():
    """cube.fe: each square face is split into four triangles at its centre;
    the 12 cube edges have dihedral π/2, the 24 edges inside faces 0."""
    s = Session.load("datafiles/cube.fe", out=io.StringIO()).surface
    d = A.edge_dihedral(s, s.evaluate())
    assert len(d) == 36
    assert np.sum(np.isclose(d, np.pi / 2, atol=1e-12)) == 12
    assert np.sum(np.abs(d) < 1e-7) == 24


def test_string_vertex_dihedral_of_a_square(tmp_path):
    p = tmp_path / "sq.fe"
    p.write_text("STRING\nSPACE_DIMENSION 2\nvertices\n1 0 0\n2 1 0\n3 1 1\n4 0 1\n5 0 3\n"
                 "edges\n1 1 2\n2 2 3\n3 3 4\n4 4 1\n5 4 5\n")
    s = Session.load(str(p), out=io.StringIO()).surface
    d = A.string_vertex_dihedral(s, s.evaluate())
    # corners 1-3: a right turn, |u_out - u_in| = √2, 2 asin(√2/2) = π/2;
    # vertex 4 has three edges (|F| = |(0,-1) + (0,1) + (1,0)| = 1: 2 asin(1/2) = π/3);
    # vertex 5 ends the spur
    assert np.allclose(d, [np.pi / 2, np.pi / 2, np.pi / 2, np.pi / 3, 0.0], atol=ROUNDOFF)


def test_attr_cache_computes_once_until_touched():
    sess = Session.load("datafiles/cube.fe", out=io.StringIO())
    cache = A.AttrCache()
    calls = []

    def fn(s, t):
        calls.append(t)
        return A.edge_dihedral(s, t)
    a = cache.get(sess, "dihedral", fn)
    b = cache.get(sess, "dihedral", fn)
    assert a is b and len(calls) == 1
    assert calls[0] is sess.totals                  # no coordinate changed yet
    sess.surface.X[0] += 0.1
    cache.touch(sess)
    c = cache.get(sess, "dihedral", fn)
    assert len(calls) == 2 and calls[1] is not sess.totals       # a fresh geometry
    assert not np.allclose(a, c)
