"""pyevolver.remesh.group_delete: edge deletion in a symmetry group other
than the torus: the eliminated vertex moves to its copy next to the kept
one and its edges' codes follow, so that every other edge keeps its vector;
an edge whose ends another edge joins is left (REF's comparisons:
tests/model/test_symmetry_groups.py)."""
import os

import numpy as np

import pyevolver
from pyevolver.remesh import delete_edges as DEL
from pyevolver.remesh import group_delete as GD

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "symmetry_groups")


def test_wrapped_edge_deleted_keeps_the_other_edges():
    s = pyevolver.load(os.path.join(DATA, "rotate.fe")).surface
    e = 5                                              # 6 -> 4, wrap -1: both ends free
    assert s.eattr["wrap_code"][e] == -1 and not s.vattr["fixed"][s.E[e]].any()
    d = DEL._Deleter(s)
    keep, elim = (int(x) for x in s.E[e])           # the head (4) is eliminated
    before = {x: d.vec(x) for x in range(s.ne)}
    mid = s.X[keep] + 0.5 * GD.edge_vector(d, e)
    assert d.delete(e)
    assert np.allclose(d.X[keep], mid)
    for x in range(s.ne):
        if d.ealive[x] and keep not in d.E[x]:
            assert np.allclose(d.vec(x), before[x])
    # the eliminated vertex's far neighbours, seen from the kept frame: g_delta
    # of where they were seen from the eliminated vertex
    A, b = d.group.affine([s.eattr["wrap_code"][e]])
    for x in np.nonzero(d.ealive & (s.E[:, 0] == elim))[0]:
        far = A[0] @ (before[x] + s.X[elim]) + b[0]
        assert np.allclose(d.vec(x) + d.X[keep], far)
    t = d.result()
    assert t.ne < s.ne and "wrap_code" in t.eattr


def test_parallel_edge_leaves_the_edge():
    s = pyevolver.load(os.path.join(DATA, "rotate.fe")).surface
    d = DEL._Deleter(s)
    a, b = (int(x) for x in s.E[3])
    assert not GD.parallel_edge(d, 3, a, b)
    d.E[7] = (b, a)                                   # a second edge between the ends
    assert GD.parallel_edge(d, 3, a, b)
    assert not d.delete(3)
