"""Direct tests of pyevolver.remesh.shrink.subset: dropping elements and
renumbering (ids kept, body facets and areas follow)."""
import os

import numpy as np
import pytest

import pyevolver
from comparison import consistent
from pyevolver.remesh.shrink import subset
from tolerances import ROUNDOFF

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def _cube():
    return pyevolver.load(CUBE).surface


def _all(n):
    return np.ones(n, bool)


def test_keep_everything_is_a_copy():
    s = _cube()
    t = subset(s, s.E, s.FE, _all(s.nv), _all(s.ne), _all(s.nf))
    assert t is not s
    assert np.array_equal(t.X, s.X) and np.array_equal(t.E, s.E)
    assert np.array_equal(t.FE, s.FE)
    consistent(t)
    assert t.evaluate().volumes[0] == pytest.approx(1.0, rel=ROUNDOFF)


def test_drop_one_facet():
    s = _cube()
    a0 = s.evaluate().facet_area[0]
    fkeep = _all(s.nf)
    fkeep[0] = False
    t = subset(s, s.E, s.FE, _all(s.nv), _all(s.ne), fkeep)
    assert t.nf == s.nf - 1
    consistent(t)
    assert t.ids("facet").tolist() == list(range(2, s.nf + 1))    # a gap at id 1
    assert np.array_equal(t.FE, s.FE[1:])
    assert t.evaluate().total_area == pytest.approx(6.0 - a0, rel=ROUNDOFF)
    assert t.bodies.facet_matrix.shape == (1, s.nf - 1)


def test_drop_vertex_renumbers_edges_and_facets():
    s = _cube()
    # remove the last vertex with its edges and facets
    v = s.nv - 1
    ekeep = ~np.any(s.E == v, axis=1)
    fk = np.all(ekeep[np.where(s.FE >= 0, s.FE, ~s.FE)], axis=1)
    vkeep = _all(s.nv)
    vkeep[v] = False
    t = subset(s, s.E, s.FE, vkeep, ekeep, fk)
    assert (t.nv, t.ne, t.nf) == (s.nv - 1, int(ekeep.sum()), int(fk.sum()))
    consistent(t)
    # the same edges, endpoints renumbered (all kept vertices precede v)
    assert np.array_equal(t.E, s.E[ekeep])
    assert np.allclose(t.X[t.E], s.X[s.E[ekeep]])


def test_kept_edge_on_dropped_vertex_raises():
    s = _cube()
    vkeep = _all(s.nv)
    vkeep[s.E[0, 0]] = False
    with pytest.raises(ValueError):
        subset(s, s.E, s.FE, vkeep, _all(s.ne), _all(s.nf))
