"""``O``: pop non-minimal edges of a soap film (manual: O, pop).

An edge with four facets is not minimal: in cross-section it is an X where
four films meet, which a soap film splits into two Y's joined by a short
film.  The Evolver does this as follows (reproduced from its output on
octa.fe and on single four-facet edges of varied shapes, sizes and facet
numbering; every rule below was checked against evolver-nox-d):

1. The facets round the edge ``e = a -> b`` are taken in the cyclic order of
   a right-handed turn about ``e``, starting at the edge's first facet (the
   first datafile face listing the edge, followed through the splits).
   Each facet's direction off the edge is the unit vector ``u`` from the
   edge towards the facet's third corner, perpendicular to the edge.
2. Of the four pairs of neighbouring facets, the pair ``(p, q)`` with the
   smallest angle between its ``u`` is chosen (ties: the first in loop order).
3. Two vertices are added: ``M1`` at the edge midpoint and ``M2`` at the
   midpoint moved by ``0.005 |b - a| (u_p + u_q)`` into the wedge of the
   pair.  The pair's facets are cut along ``M2``, the other two along
   ``M1``, and two thin triangles ``a M1 M2`` and ``M1 b M2`` join the two
   new triple edges ``a M1 b`` and ``a M2 b``.
4. Numbering: ``e`` keeps its id for ``a -> M2``; new edges ``M2 -> b``,
   the four cuts ``M -> c`` (loop order), ``M1 -> M2``, ``a -> M1``,
   ``M1 -> b``; each cut facet keeps its id for the triangle at ``b`` and
   its other half is new (loop order), then the two thin triangles, oriented
   against the second facet of the pair along ``e``.

Edges are popped in id order, each seeing the surface the previous pops
left.  Configurations whose behaviour was not checked against the Evolver
are refused by name (edges with more than four facets, FIXED or constrained
edges, multiple edges running through a vertex, bodies, facets of unequal
tension), as are exact ties between angles when the loop start is not known
(after an operation that does not record it).
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import UnsupportedError, dimension_error
from ..model.records import edge_first_facet, record_edge_first_facet
from .grow import grow, reorder_new_edges

TIE = 1e-12          # angles (radians) closer than this count as equal


def _valence(s):
    a = np.where(s.FE >= 0, s.FE, ~s.FE).ravel()
    return np.bincount(a, minlength=s.ne)


def _check(s, cand, val):
    """Refuse the configurations not checked against the Evolver."""
    if s.periods is not None:
        raise UnsupportedError("O (edge popping) in the torus model")
    if s.bodies.n:
        raise UnsupportedError("O (edge popping) on a surface with bodies",
                               "which body the new facets belong to is not implemented")
    if (val[cand] > 4).any():
        e = int(s.ids("edge")[cand[val[cand] > 4][0]])
        raise UnsupportedError("O on an edge with more than four facets", f"edge {e}")
    eid = s.ids("edge")
    bad = s.eattr["fixed"][cand]
    if bad.any():
        raise UnsupportedError("O on a FIXED edge with four facets", f"edge {eid[cand[bad][0]]}")
    for cid, on in s.econ.items():
        if (on[cand] != 0).any():
            raise UnsupportedError("O on an edge on a constraint", f"constraint {cid}")
    if "boundary" in s.eattr and (s.eattr["boundary"][cand] != 0).any():
        raise UnsupportedError("O on an edge on a boundary")
    for q in s.quantities.values():
        if any(sgn is not None and et in ("edge", "facet") for (_, et, _, sgn) in q.methods):
            raise UnsupportedError("O on a surface whose quantities list edges or facets",
                                   f"quantity {q.name}")
    # a multiple edge running on through a free vertex (its pop would spread
    # along the chain, manual: O) is not implemented
    ends = s.E[cand].ravel()
    multi = np.bincount(ends, minlength=s.nv)
    chain = (multi == 2) & ~s.vattr["fixed"]
    if chain[ends].any():
        v = int(s.ids("vertex")[ends[chain[ends]][0]])
        raise UnsupportedError("O on a multiple edge continuing through a vertex",
                               f"vertex {v}")


def _loop(s, e, first):
    """Facets on edge ``e`` in the Evolver's loop order, with their signs on
    ``e``, third corners and unit directions off the edge."""
    if s.X.shape[1] > 3:
        raise dimension_error(s.sdim, "edge popping", "needs")
    absFE = np.where(s.FE >= 0, s.FE, ~s.FE)
    fs = np.nonzero((absFE == e).any(axis=1))[0]
    a, b = s.E[e]
    d = s.X[b] - s.X[a]
    L = float(np.linalg.norm(d))
    d = d / L
    F = s.F
    sign = np.array([1 if e in s.FE[f] else -1 for f in fs])
    c = np.array([next(v for v in F[f] if v != a and v != b) for f in fs])
    w = s.X[c] - s.X[a]
    u = w - np.outer(w @ d, d)
    n = np.linalg.norm(u, axis=1)
    eid = int(s.ids("edge")[e])
    if (n <= 0).any():
        raise UnsupportedError("O on an edge with a degenerate facet", f"edge {eid}")
    u = u / n[:, None]
    start = first[e] if first is not None else -1
    k0 = int(np.nonzero(fs == start)[0][0]) if start in fs else 0
    ref = u[k0]
    side = np.cross(d, ref)
    theta = np.mod(np.arctan2(u @ side, u @ ref), 2 * math.pi)
    theta[k0] = 0.0
    order = np.argsort(theta, kind="stable")
    order = np.roll(order, -int(np.nonzero(order == k0)[0][0]))
    th = theta[order]
    gaps = np.diff(np.append(th, 2 * math.pi))
    k = int(np.argmin(gaps))
    ties = np.nonzero(gaps <= gaps[k] + TIE)[0]
    if len(ties) > 1 and start not in fs:
        raise UnsupportedError(
            "O on an edge whose facet angles tie", f"edge {eid}: the Evolver breaks the tie by "
            "the order of the facets round the edge, which is not known after this surface's "
            "last mesh operation")
    k = int(ties[0])
    return fs[order], sign[order], c[order], u[order], k, L


def _pop_one(s, e, first):
    """Pop edge ``e`` (index) of ``s``; returns the new surface and the
    updated first-facet array."""
    fs, sg, c, u, k, L = _loop(s, e, first)
    p, q = k, (k + 1) % 4
    pair = np.zeros(4, bool)
    pair[[p, q]] = True
    a, b = (int(x) for x in s.E[e])
    nv, ne, nf = s.nv, s.ne, s.nf
    ten = s.fattr["tension"][fs]
    if not np.all(ten == ten[0]):
        raise UnsupportedError("O on an edge whose facets have unequal tensions",
                               f"edge {int(s.ids('edge')[e])}")
    # grow order: edge-born [M2->b, a->M1, M1->b], facet-born [cuts x4, M1->M2]
    t = grow(s, v_from_edge=[e, e], e_from_edge=[e, e, e],
             e_from_facet=list(fs) + [int(fs[p])],
             f_from_facet=list(fs) + [int(fs[q]), int(fs[q])])
    # the Evolver's order: M2->b, cuts x4, M1->M2, a->M1, M1->b
    reorder_new_edges(t, ne, [0, 3, 4, 5, 6, 7, 1, 2])
    M1, M2 = nv, nv + 1
    mid = 0.5 * (s.X[a] + s.X[b])
    t.X[M1] = mid
    t.X[M2] = mid + 0.005 * L * (u[p] + u[q])
    E1, cut, E6, E7, E8 = ne, ne + 1 + np.arange(4), ne + 5, ne + 6, ne + 7
    M = np.where(pair, M2, M1)
    t.E[e] = (a, M2)
    t.E[E1] = (M2, b)
    t.E[cut] = np.stack([M, c], axis=1)
    t.E[E6] = (M1, M2)
    t.E[E7] = (a, M1)
    t.E[E8] = (M1, b)
    fr = np.empty(ne + 8, np.int64)
    fr[:len(first)] = first
    fr[len(first):] = -1
    for j in range(4):
        f, g, S = int(fs[j]), nf + j, int(cut[j])
        ha, hb = (e, E1) if pair[j] else (E7, E8)
        row = [int(x) for x in s.FE[f]]
        i = row.index(e if sg[j] > 0 else ~e)
        x, y = row[(i + 1) % 3], row[(i + 2) % 3]
        if sg[j] > 0:       # a->b, b->c (x), c->a (y)
            t.FE[f] = (~S, hb, x)
            t.FE[g] = (ha, S, y)
            moved = y
        else:               # b->a, a->c (x), c->b (y)
            t.FE[f] = (S, y, ~hb)
            t.FE[g] = (~ha, x, ~S)
            moved = x
        m = moved if moved >= 0 else ~moved
        if fr[m] == f:
            fr[m] = g
        fr[S] = -1
    s1, s2 = nf + 4, nf + 5
    if sg[q] > 0:
        t.FE[s1] = (E7, E6, ~e)
        t.FE[s2] = (E8, ~E1, ~E6)
    else:
        t.FE[s1] = (~E7, e, ~E6)
        t.FE[s2] = (~E8, E6, E1)
    if "original" in t.fattr:
        t.fattr["original"][[s1, s2]] = 0        # REF lists no original for them
    fr[e] = -1
    t.__dict__.pop("_topo", None)
    t.__dict__.pop("_corners", None)
    record_edge_first_facet(t, fr)
    return t, fr


def pop_edges(s, which=None):
    """``O``: pop every edge with four facets (in id order); ``which``
    (edge indices, ``pop edge[...]``) restricts the candidates.

    Returns
    -------
    (Surface, int)
        The new surface and the number of edges popped (the Evolver's
        ``Edges popped: %d``).  Each pop adds 2 vertices, 8 edges and 6
        facets.
    """
    if s.nf == 0:
        raise UnsupportedError("O (edge popping) in the string model")
    val = _valence(s)
    ok = val >= 4
    if which is not None:
        keep = np.zeros(s.ne, bool)
        keep[np.asarray(which, np.int64)] = True
        ok &= keep
    cand = np.nonzero(ok)[0]
    if not len(cand):
        return s, 0
    _check(s, cand, val)
    first = edge_first_facet(s)
    if first is None:
        first = np.full(s.ne, -1, np.int64)
    for e in cand:
        s, first = _pop_one(s, int(e), first)
    return s, len(cand)
