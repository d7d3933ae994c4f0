"""Direct tests of pyevolver.remesh.notch: ``notch_edges``, ``notch`` and
``split_facets_at_centre`` on cube.fe (flat faces, right-angle edges)."""
import os

import numpy as np
import pytest

import pyevolver
from comparison import consistent
from pyevolver.remesh.notch import notch, notch_edges, split_facets_at_centre
from tolerances import ROUNDOFF

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def _cube():
    return pyevolver.load(CUBE).surface


def test_notch_edges_finds_the_twelve_cube_edges():
    s = _cube()
    edges, facets = notch_edges(s, 0.1)
    # cube.fe: every face is 4 triangles round a centre vertex; only the
    # 12 edges of the cube itself have a (right) dihedral angle
    assert len(edges) == 12 and facets.shape == (12, 2)
    P = s.X[s.E[edges]]
    d = np.abs(P[:, 1] - P[:, 0])
    assert np.allclose(np.sort(d, axis=1), [[0, 0, 1]] * 12)
    # a right angle is not above 2 radians
    assert len(notch_edges(s, 2.0)[0]) == 0
    # and is above 1.5 (< pi/2)
    assert len(notch_edges(s, 1.5)[0]) == 12


def test_notch_cube_subdivides_every_facet_and_keeps_geometry():
    s = _cube()
    t, n = notch(s, 0.1)
    # each of the 24 facets has one side on a cube edge
    assert n == 24
    assert (t.nv, t.ne, t.nf) == (s.nv + 24, s.ne + 72, s.nf + 48)
    consistent(t)
    assert t.nv - t.ne + t.nf == 2
    tot = t.evaluate()
    assert tot.total_area == pytest.approx(6.0, rel=ROUNDOFF)
    assert tot.volumes[0] == pytest.approx(1.0, rel=ROUNDOFF)


def test_notch_with_large_angle_does_nothing():
    s = _cube()
    t, n = notch(s, 2.0)
    assert n == 0
    assert (t.nv, t.ne, t.nf) == (s.nv, s.ne, s.nf)


def test_split_facets_at_centre_puts_vertex_at_centroid():
    s = _cube()
    F = s.F
    t = split_facets_at_centre(s, [3, 5, 3])        # duplicates ignored
    assert (t.nv, t.ne, t.nf) == (s.nv + 2, s.ne + 6, s.nf + 4)
    consistent(t)
    assert np.allclose(t.X[s.nv:], s.X[F[[3, 5]]].mean(axis=1), atol=ROUNDOFF)
    # three thirds of the parent's area
    A = t.evaluate().facet_area
    a0 = s.evaluate().facet_area[3]
    assert A[3] + A[s.nf] + A[s.nf + 1] == pytest.approx(a0, rel=ROUNDOFF)
    assert t.evaluate().total_area == pytest.approx(6.0, rel=ROUNDOFF)
    # no facets: the same surface back
    assert split_facets_at_centre(s, []) is s


def test_notching_in_five_dimensions(tmp_path):
    """SPACE_DIMENSION 5: nothing to notch without two-facet edges
    (relaxed.fe, as REF: 0); otherwise refused by name, the surface kept."""
    from conftest import example
    from pyevolver.errors import PyEvolverError
    here = os.path.dirname(__file__)
    sess = pyevolver.load(example("relaxed.fe"))
    assert notch(sess.surface, 0.5)[1] == 0
    sess = pyevolver.load(os.path.join(here, "..", "data", "elastic5d.fe"))
    X0 = sess.surface.X.copy()
    with pytest.raises(PyEvolverError, match="notching in SPACE_DIMENSION 5"):
        sess.run("n 0.4")
    assert np.array_equal(sess.surface.X, X0) and sess.surface.nf == 3
