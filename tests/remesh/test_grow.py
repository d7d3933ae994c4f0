"""Direct tests of pyevolver.remesh.grow.grow: new elements appended with
the inheritance rules (spec §6.2), the input left untouched."""
import os

import numpy as np

import pyevolver
from pyevolver.remesh.grow import grow

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def _cube():
    return pyevolver.load(CUBE).surface


def test_grow_appends_zeroed_rows_and_new_ids():
    s = _cube()
    X0 = s.X.copy()
    t = grow(s, v_from_edge=[0, 1], e_from_edge=[0], f_from_facet=[2, 3])
    assert (t.nv, t.ne, t.nf) == (s.nv + 2, s.ne + 1, s.nf + 2)
    assert np.array_equal(t.X[:s.nv], X0)
    assert np.all(t.X[s.nv:] == 0)
    # ids continue after the largest
    assert t.ids("vertex")[-2:].tolist() == [s.nv + 1, s.nv + 2]
    assert t.ids("facet")[-2:].tolist() == [s.nf + 1, s.nf + 2]
    # per-element attributes have the new lengths
    for arr in t.vattr.values():
        assert len(arr) == t.nv
    for arr in t.eattr.values():
        assert len(arr) == t.ne
    for arr in t.fattr.values():
        assert len(arr) == t.nf
    # the input is not changed
    assert (s.nv, s.ne, s.nf) == (14, 36, 24)
    assert np.array_equal(s.X, X0)


def test_grow_inherits_attributes():
    s = _cube()
    s.eattr["fixed"] = s.eattr["fixed"].copy()
    s.eattr["fixed"][5] = True
    s.fattr["tension"] = s.fattr["tension"].copy()
    s.fattr["tension"][7] = 2.5
    s.fattr["fixed"] = s.fattr["fixed"].copy()
    s.fattr["fixed"][7] = True
    t = grow(s, v_from_edge=[5, 6], v_from_facet=[7], e_from_edge=[5], e_from_facet=[7],
             f_from_facet=[7, 8])
    nv, ne, nf = s.nv, s.ne, s.nf
    # a vertex born on an edge takes its FIXED; one born in a facet the facet's
    assert t.vattr["fixed"][nv:].tolist() == [True, False, True]
    # edges: from the edge, from the facet
    assert t.eattr["fixed"][ne:].tolist() == [True, True]
    # facets copy everything
    assert t.fattr["tension"][nf:].tolist() == [2.5, 1.0]
    assert t.fattr["fixed"][nf:].tolist() == [True, False]


def test_grow_new_facets_join_their_parents_body():
    s = _cube()
    t = grow(s, f_from_facet=[3])
    M = t.bodies.facet_matrix.toarray()
    assert M.shape == (1, s.nf + 1)
    assert M[0, s.nf] == M[0, 3] != 0
