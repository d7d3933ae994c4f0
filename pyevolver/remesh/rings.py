"""REF's edge rings at the vertices, as linked lists in arrays.

The Evolver keeps the edges at a vertex in a cyclic list read from the
vertex's first edge (``vv.edge``; :func:`pyevolver.model.records.vertex_edge_rank`).
Measured with evolver-nox-d (catbody.fe, column.fe, quad.fe after ``r`` and
``u``): an edge leaving a vertex's list makes the edge that followed it the
vertex's first edge; an edge joining a list goes in right after the first
edge.  Operations that change edges replay those changes here, vectorized
over vertices (one change per vertex and call), and record the result.

Slot ``2e`` is edge ``e`` at its tail, ``2e + 1`` at its head.
"""
from __future__ import annotations

import numpy as np

from ..model.records import vertex_edge_rank


class Rings:
    """The rings of surface ``s`` (``vertex_edge_rank``), room for ``ne``
    edges and ``nv`` vertices."""

    def __init__(self, s, ne, nv):
        self.nxt = np.arange(2 * ne)
        self.prv = np.arange(2 * ne)
        self.head = np.full(nv, -1, np.int64)
        v0 = s.E.ravel()
        order = np.lexsort((vertex_edge_rank(s).ravel(), v0))
        vs = v0[order]
        start = np.searchsorted(vs, np.arange(s.nv))
        stop = np.searchsorted(vs, np.arange(s.nv), side="right")
        pos = np.arange(len(order))
        succ = np.where(pos == stop[vs] - 1, start[vs], pos + 1)
        self.nxt[order] = order[succ]
        self.prv[order[succ]] = order
        has = stop > start
        self.head[:s.nv][has] = order[start[has]]

    def remove(self, v, x):
        """Slots ``x`` leave the rings of vertices ``v`` (distinct)."""
        p, q = self.prv[x], self.nxt[x]
        alone = q == x
        self.nxt[p] = np.where(alone, self.nxt[p], q)
        self.prv[q] = np.where(alone, self.prv[q], p)
        self.head[v] = np.where(alone, -1, q)

    def insert(self, v, y):
        """Slots ``y`` join the rings of vertices ``v`` (distinct), right
        after the first edge."""
        h = self.head[v]
        empty = h < 0
        hh = np.where(empty, y, h)
        s2 = np.where(empty, y, self.nxt[hh])
        self.nxt[hh] = y
        self.prv[y] = hh
        self.nxt[y] = s2
        self.prv[s2] = y
        self.head[v] = hh

    def set_pair(self, v, a, b):
        """Vertices ``v`` get the rings (a, b), ``a`` first."""
        self.nxt[a], self.prv[a], self.nxt[b], self.prv[b] = b, b, a, a
        self.head[v] = a

    def rank(self):
        """(ne, 2) position of every slot in its ring."""
        rank = np.zeros(len(self.nxt), np.int64)
        first = self.head[self.head >= 0]
        cur = first.copy()
        step = 0
        while len(cur):
            rank[cur] = step
            step += 1
            nx = self.nxt[cur]
            keep = nx != first
            cur, first = nx[keep], first[keep]
        return rank.reshape(-1, 2)


def rounds(v, items):
    """Indices into ``v``/``items`` grouped so that each group has one item
    per vertex: group j holds the j-th item (in ``items`` order) of every
    vertex."""
    o = np.lexsort((items, v))
    g = v[o]
    j = np.arange(len(g)) - np.searchsorted(g, g)
    return [o[j == r] for r in range(int(j.max()) + 1 if len(j) else 0)]
