"""Direct tests of pyevolver.remesh.refine: ``refine`` and ``split_edges``
on a Surface (counts V+E, 2E+3F, 4F; flat faces keep area and volume)."""
import os

import numpy as np
import pytest

import pyevolver
from comparison import consistent
from pyevolver.remesh.refine import refine, split_edges
from tolerances import ROUNDOFF

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def _cube():
    return pyevolver.load(CUBE).surface


def _euler(s):
    return s.nv - s.ne + s.nf


def test_refine_counts_and_keeps_cube_area_volume():
    s = _cube()
    nv, ne, nf = s.nv, s.ne, s.nf
    t = refine(s)
    assert (t.nv, t.ne, t.nf) == (nv + ne, 2 * ne + 3 * nf, 4 * nf)
    consistent(t)
    assert _euler(t) == _euler(s) == 2
    tot = t.evaluate()
    # flat faces: subdividing them changes neither area nor volume
    assert tot.total_area == pytest.approx(6.0, rel=ROUNDOFF)
    assert tot.volumes[0] == pytest.approx(1.0, rel=ROUNDOFF)
    # every facet a quarter of its parent (cube.fe: 24 congruent triangles)
    assert np.allclose(tot.facet_area, 6.0 / 96, rtol=ROUNDOFF)


def test_refine_new_vertices_are_edge_midpoints_and_input_untouched():
    s = _cube()
    X0, E0, FE0 = s.X.copy(), s.E.copy(), s.FE.copy()
    t = refine(s)
    mids = 0.5 * (X0[E0[:, 0]] + X0[E0[:, 1]])
    assert np.allclose(t.X[s.nv:], mids, atol=ROUNDOFF)
    assert np.array_equal(t.X[:s.nv], X0)
    # the original surface is left as it was (the session can restore it)
    assert np.array_equal(s.X, X0) and np.array_equal(s.E, E0) and np.array_equal(s.FE, FE0)
    # every edge is halved: the tail half keeps the edge id, the head half is new
    assert np.array_equal(t.E[:s.ne, 0], E0[:, 0])
    assert np.array_equal(t.E[s.ne:2 * s.ne, 1], E0[:, 1])


def test_refine_twice_quadruples_again():
    t = refine(refine(_cube()))
    assert t.nf == 24 * 16
    consistent(t)
    assert _euler(t) == 2
    assert t.evaluate().total_area == pytest.approx(6.0, rel=ROUNDOFF)


def test_split_one_edge_bisects_its_two_facets():
    s = _cube()
    mask = np.zeros(s.ne, bool)
    mask[0] = True
    t = split_edges(s, mask)
    # one new vertex, the new half plus one cut per facet on the edge
    assert (t.nv, t.ne, t.nf) == (s.nv + 1, s.ne + 3, s.nf + 2)
    consistent(t)
    assert _euler(t) == 2
    assert np.allclose(t.X[s.nv], 0.5 * (s.X[s.E[0, 0]] + s.X[s.E[0, 1]]))
    tot = t.evaluate()
    assert tot.total_area == pytest.approx(6.0, rel=ROUNDOFF)
    assert tot.volumes[0] == pytest.approx(1.0, rel=ROUNDOFF)


def test_no_refine_edges_are_not_split():
    s = _cube()
    s.eattr["no_refine"] = s.eattr["no_refine"].copy()
    s.eattr["no_refine"][:] = True
    t = refine(s)
    assert (t.nv, t.ne, t.nf) == (s.nv, s.ne, s.nf)
    consistent(t)
