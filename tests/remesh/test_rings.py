"""Direct tests of pyevolver.remesh.rings: the linked edge rings at the
vertices (REF's ``vv.edge`` order) and ``rounds``."""
import os

import numpy as np

import pyevolver
from pyevolver.model.records import vertex_edge_rank
from pyevolver.remesh.rings import Rings, rounds

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def _cube():
    return pyevolver.load(CUBE).surface


def _ring(g, v):
    """Slots of vertex v's ring, read from its first edge."""
    h = int(g.head[v])
    out = [h]
    x = int(g.nxt[h])
    while x != h:
        out.append(x)
        x = int(g.nxt[x])
        assert len(out) <= len(g.nxt)
    return out


def _slots_at(s, v):
    return sorted((2 * e + k) for e in range(s.ne) for k in (0, 1) if s.E[e, k] == v)


def test_fresh_rings_lowest_edge_then_newest_first():
    s = _cube()
    g = Rings(s, s.ne, s.nv)
    assert np.array_equal(g.rank(), vertex_edge_rank(s))
    for v in range(s.nv):
        slots = _slots_at(s, v)
        ring = _ring(g, v)
        assert sorted(ring) == slots                  # every edge once
        # load order: the lowest id first, the others newest first
        assert ring == [slots[0]] + sorted(slots[1:], reverse=True)
        # prv is the inverse of nxt
        assert all(g.prv[g.nxt[x]] == x for x in ring)


def test_remove_makes_the_next_edge_first_and_insert_goes_after_it():
    s = _cube()
    g = Rings(s, s.ne + 2, s.nv)
    v = np.array([0, 13])
    before = [_ring(g, int(x)) for x in v]
    first = np.array([r[0] for r in before])
    g.remove(v, first)
    after = [_ring(g, int(x)) for x in v]
    for b, a in zip(before, after):
        assert a == b[1:]
    new = np.array([2 * s.ne, 2 * s.ne + 2])          # two slots of the spare edges
    g.insert(v, new)
    for b, a, y in zip(before, [_ring(g, int(x)) for x in v], new):
        assert a == [b[1], int(y)] + b[2:]
    # the ranks follow the rings
    rank = g.rank().ravel()
    for x in v:
        assert [rank[y] for y in _ring(g, int(x))] == list(range(len(_ring(g, int(x)))))


def test_set_pair():
    s = _cube()
    g = Rings(s, s.ne + 2, s.nv + 1)
    g.set_pair(np.array([s.nv]), np.array([2 * s.ne]), np.array([2 * s.ne + 3]))
    assert _ring(g, s.nv) == [2 * s.ne, 2 * s.ne + 3]


def test_rounds_one_item_per_vertex_per_group():
    v = np.array([3, 1, 3, 3, 1, 2])
    items = np.array([10, 11, 7, 12, 5, 0])
    groups = rounds(v, items)
    assert len(groups) == 3                          # vertex 3 has three items
    seen = np.concatenate(groups)
    assert sorted(seen.tolist()) == list(range(len(v)))
    for j, gr in enumerate(groups):
        assert len(set(v[gr].tolist())) == len(gr)
        # group j holds each vertex's j-th item in item order
        for i in gr:
            mine = np.sort(items[v == v[i]])
            assert items[i] == mine[j]
    assert rounds(np.array([], np.int64), np.array([], np.int64)) == []
