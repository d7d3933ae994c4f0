"""Per-element records the Evolver keeps beside the arrays: each edge's first
facet, the order of the edges and facets at a vertex, CONVEX edges and the
torus lift of each body's facets."""
from __future__ import annotations

from collections import deque
from typing import Any

import numpy as np

from ..geometry import kernels as G
from .surface import Surface


def first_facets_on_load(FE: np.ndarray, parent: np.ndarray, ne: int) -> np.ndarray:
    """(ne,) index of each edge's first facet, -1 where unknown.

    The Evolver keeps the facets round an edge in a cyclic loop that starts
    at the first face of the datafile listing the edge (checked with ``O`` on
    octa.fe and on single four-facet edges, where the loop start breaks ties
    between equal angles).  ``parent`` (nf,) is the datafile face position of
    each facet; an edge whose first face was split on load into several
    triangles containing it (a spoke) gets -1.
    """
    nf = len(FE)
    e = np.where(FE >= 0, FE, ~FE).ravel()
    f = np.repeat(np.arange(nf), 3)
    p = np.asarray(parent)[f]
    order = np.lexsort((f, p, e))
    del f                       # (one array at a time: the load's peak memory)
    e = e[order]
    p = p[order]
    f = order // 3              # (= the repeated facet numbers, reordered)
    del order
    head = np.ones(len(e), bool)
    head[1:] = e[1:] != e[:-1]
    first = np.full(ne, -1, np.int64)
    h = np.nonzero(head)[0]
    nxt = h + 1
    tie = (nxt < len(e)) & (e[np.minimum(nxt, len(e) - 1)] == e[h]) & \
        (p[np.minimum(nxt, len(e) - 1)] == p[h])
    first[e[h]] = np.where(tie, -1, f[h])
    return first


def record_edge_first_facet(s: Surface, first: np.ndarray) -> None:
    """Attach the first facet of every edge's loop to ``s``, valid while its
    connectivity stays what it is now (any change to ``E`` or ``FE`` drops
    it; only the operations that know how the loop start moves keep it)."""
    s._edge_first = (s.FE.copy(), s.E.copy(), np.asarray(first, np.int64))


def edge_first_facet(s: Surface) -> np.ndarray:
    """(ne,) first facet of each edge's loop (-1 unknown), or None when the
    connectivity changed since it was recorded."""
    c = s.__dict__.get("_edge_first")
    if c is None:
        return None
    FE, E, first = c
    if FE.shape != s.FE.shape or E.shape != s.E.shape or \
            not np.array_equal(FE, s.FE) or not np.array_equal(E, s.E):
        return None
    return first


def record_along_first(s: Surface, along: np.ndarray, copies: tuple | None = None) -> None:
    """Attach to ``s`` which edges have the facet running along them first
    in their facet loop (``along`` (ne,) bool), valid while its connectivity
    stays what it is now.  ``copies``: copies of ``(s.FE, s.E)`` already made
    (shared with other records; nothing may write into them).  ``along``
    may be a function of no arguments, called when first read (``r``)."""
    FE, E = copies if copies is not None else (s.FE.copy(), s.E.copy())
    s._along_first = (FE, E, along if callable(along) else np.asarray(along, bool))


def along_first(s: Surface) -> np.ndarray:
    """(ne,) bool: the facet running along the edge comes first in the
    edge's facet loop (REF's ``ee.facet`` order of a two-facet edge).

    Recorded by ``r`` (:func:`record_along_first`); on a loaded surface from
    :func:`edge_first_facet`; where neither is known, True (the facet along
    the edge first, as ``ee.facet`` lists it)."""
    c = s.__dict__.get("_along_first")
    if c is not None and c[0].shape == s.FE.shape and c[1].shape == s.E.shape and \
            np.array_equal(c[0], s.FE) and np.array_equal(c[1], s.E):
        if callable(c[2]):
            c = s._along_first = (c[0], c[1], np.asarray(c[2](), bool))
        return c[2].copy()
    out = np.ones(s.ne, bool)
    first = edge_first_facet(s)
    if first is None:
        return out
    known = np.nonzero(first >= 0)[0]
    # the edge's occurrences in its first facet: forwards minus backwards
    FEf = s.FE[first[known]]
    k = known[:, None]
    d = (FEf == k).astype(np.int8)
    d -= FEf == ~k
    out[known] = ((d[:, 0] + d[:, 1] + d[:, 2]) if d.shape[1] == 3 else d.sum(axis=1)) >= 0
    return out


def record_vertex_rings(s: Surface, rank: Any, E: np.ndarray | None = None) -> None:
    """Attach REF's edge rings to ``s``: ``rank`` (ne, 2) is the position of
    each edge in the ring of its tail (column 0) and head (column 1) vertex
    (:func:`vertex_edge_rank`), valid while the edges stay what they are.
    ``rank`` may be a function of no arguments that computes it, called
    the first time the rings are read (``r`` leaves them to the first
    ``u``, ``V`` or ``vv.edge`` that needs them).  ``E``: a copy of
    ``s.E`` already made (shared with other records)."""
    E = s.E.copy() if E is None else E
    s._rings = (E, rank if callable(rank) else np.asarray(rank, np.int64))


def settle_records(s: Surface) -> None:
    """Compute now the rings and loop starts of ``s`` recorded as functions,
    so that a new surface's functions can depend on them without keeping a
    chain of older surfaces alive (``K`` bisects in rounds, each a new
    surface)."""
    c = s.__dict__.get("_rings")
    if c is not None and callable(c[1]):
        vertex_edge_rank(s)
    c = s.__dict__.get("_along_first")
    if c is not None and callable(c[2]):
        along_first(s)


def vertex_edge_rank(s: Surface) -> np.ndarray:
    """(ne, 2) position of each edge in the edge ring of its tail (column 0)
    and head (column 1) vertex: REF's ``vv.edge`` order.

    The Evolver keeps the edges at a vertex in a cyclic list read from the
    vertex's first edge; a new edge goes in right after the first.  On a
    freshly loaded surface edges join in id order, so the list reads: the
    lowest-numbered edge, then the others newest first (as in the string
    model, ``string_model.init_rings``).  Rings recorded by an operation
    that knows how they change (:func:`record_vertex_rings`; ``r``) are used
    while the edges are unchanged, otherwise the freshly loaded order.
    """
    ne, nv = s.ne, s.nv
    c = s.__dict__.get("_rings")
    if c is not None and c[0].shape == s.E.shape and np.array_equal(c[0], s.E):
        if callable(c[1]):
            c = s._rings = (c[0], np.asarray(c[1](), np.int64))
        return c[1]
    ids = np.asarray(s.ids("edge"))
    v = s.E.ravel()
    v = v.astype(np.int32 if nv < 2 ** 31 else np.int64, copy=False)
    if ne < 2 or bool(np.all(ids[1:] > ids[:-1])):
        # (ids in order: a loaded file's) the flat ends are in edge order,
        # so a stable sort by vertex lists each vertex's edges oldest first
        order = np.argsort(v, kind="stable")
        key = order >> 1
    else:
        t = np.empty(ne, np.int64)
        t[np.argsort(ids, kind="stable")] = np.arange(ne)
        order = np.argsort(v.astype(np.int64) * ne + np.repeat(t, 2), kind="stable")
        key = np.repeat(t, 2)[order]
    # at each vertex: its first edge (rank 0), then the others newest first:
    # the j-th oldest (j >= 1) of a vertex's n edges has rank n - j
    cnt = np.bincount(v, minlength=nv)
    start = np.cumsum(cnt) - cnt
    vs = v[order]
    j = np.arange(2 * ne) - start[vs]
    rk = cnt[vs] - j
    rk[key == key[start[vs]]] = 0            # (both ends of a loop edge that is first)
    pos = np.empty(2 * ne, np.int64)
    pos[order] = rk
    pos = pos.reshape(ne, 2)
    pos.flags.writeable = False          # (kept: the next call while E is unchanged)
    record_vertex_rings(s, pos)
    return pos


def vertex_facet_rank(s: Surface) -> np.ndarray:
    """(nf, 3) position of each facet in the facet order of its corner k:
    REF's ``vv.facet`` order, which its ``vertex_normal`` follows.

    Measured with evolver-nox-d (catbody.fe, column.fe after ``g 5; r``,
    boundary vertices included): the facets come in the ring order
    (:func:`vertex_edge_rank`) of the edge along which each leaves the
    vertex (facet side k leaves corner k).
    """
    idx, sgn, _ = s.topology()
    return vertex_edge_rank(s)[idx, np.where(sgn > 0, 0, 1)]


def convex_edges(s: Surface) -> list[tuple[object, np.ndarray]]:
    """``[(constraint, edge indices)]`` of edges on CONVEX constraints (gap energy)."""
    out = []
    for cid, sign in s.econ.items():
        c = s.constraints[cid]
        idx = np.nonzero(sign)[0]
        if "convex" in c.flags and len(idx):
            out.append((c, idx))
    return out




def torus_lift_shifts(s: Surface) -> np.ndarray:
    """Per body, the period shift of each facet that makes its facets a
    consistently lifted surface (so the divergence theorem gives its volume).

    Each facet is unwrapped from its first vertex; across every edge shared
    by two facets of a body the two lifts of the edge must coincide, which
    fixes the relative shift (a breadth-first walk over the body's facets).
    Depends on topology and wraps only, so it is cached.
    Returns ``(nb, nf, 3)`` shifts already multiplied by the body's facet sign.
    """
    key = (s.nf, s.ne, id(s.FE), id(s.eattr.get("wrap")))
    cache = getattr(s, "_lift_cache", None)
    if cache is not None and cache[0] == key:
        return cache[1]
    P = s.periods
    wrap = s.eattr["wrap"]
    idx, sgn = G.edge_index(s.FE)
    wv = wrap @ P                                   # (ne, 3)
    # offset of the tail of each oriented edge in the facet's own lift
    A = np.zeros((s.nf, 3, 3))
    A[:, 1] = wv[idx[:, 0]] * sgn[:, 0, None]
    A[:, 2] = A[:, 1] + wv[idx[:, 1]] * sgn[:, 1, None]
    # offset of the edge's own tail in the facet's lift
    O = A - np.where(sgn[..., None] < 0, wv[idx], 0.0)
    occ_b, occ_f, occ_s = s.bodies.occurrences
    ev = G.edge_vectors(s.X, s.E, wv)
    dvec = ev[idx] * sgn[..., None]                 # oriented edge vectors (nf, 3, 3)
    N2 = np.cross(dvec[:, 0], dvec[:, 0] + dvec[:, 1])
    out = np.zeros((s.bodies.n, s.nf, 3))
    for b in range(s.bodies.n):
        sel = np.nonzero(occ_b == b)[0]
        facets = occ_f[sel]
        signs = occ_s[sel]
        # occurrences by (edge, direction in which the body's side traverses it)
        by_edge = {}
        for o, (f, sg) in enumerate(zip(facets, signs)):
            for k in range(3):
                by_edge.setdefault((idx[f, k], sgn[f, k] * sg > 0), []).append((o, k))
        # pair the occurrences at every edge: going round the edge from a
        # facet towards the body's side, the next facet of the body met is
        # its partner (this separates a body's wall with its own image)
        partner = {}
        groups = {}
        for (e, d), lst in by_edge.items():
            groups.setdefault(e, []).extend(lst)
        for e, lst in groups.items():
            if len(lst) == 2:
                (o, k), (o2, j) = lst
                partner[(o, k)] = (o2, j)
                partner[(o2, j)] = (o, k)
                continue
            t = ev[e] / np.linalg.norm(ev[e])
            a = np.cross(t, [1.0, 0, 0] if abs(t[0]) < 0.9 else [0, 1.0, 0])
            a /= np.linalg.norm(a)
            bvec = np.cross(t, a)
            ang = []
            for o, k in lst:
                f = facets[o]
                w = -dvec[f, (k + 2) % 3]
                u = w - (w @ t) * t
                th = np.arctan2(u @ bvec, u @ a)
                side = -signs[o] * N2[f]
                rot = 1.0 if side @ np.cross(t, u) > 0 else -1.0
                ang.append((th, rot))
            for m, (o, k) in enumerate(lst):
                th, rot = ang[m]
                best, bestd = None, None
                for m2, (o2, j) in enumerate(lst):
                    if m2 == m or facets[o2] == facets[o] or ang[m2][1] != -rot:
                        continue
                    dth = ((ang[m2][0] - th) * rot) % (2 * np.pi)
                    if bestd is None or dth < bestd:
                        best, bestd = (o2, j), dth
                if best is not None:
                    partner[(o, k)] = best
        D = [None] * len(facets)
        for root in range(len(facets)):
            if D[root] is not None:
                continue
            D[root] = np.zeros(3)
            dq = deque([root])
            while dq:
                o = dq.popleft()
                f = facets[o]
                for k in range(3):
                    p = partner.get((o, k))
                    if p is None or D[p[0]] is not None:
                        continue
                    o2, j = p
                    D[o2] = D[o] + O[f, k] - O[facets[o2], j]
                    dq.append(o2)
        for o, (f, sg) in enumerate(zip(facets, signs)):
            out[b, f] += sg * D[o]
    s._lift_cache = (key, out)
    return out


def edge_facets(s: Surface) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ne, 2) the two facets of each edge and their sides, valence (ne,).

    Rows are filled for edges with exactly two facets (first and last
    occurrence in facet order), ``-1`` elsewhere.
    """
    idx = s.topology()[0]
    flat_e = idx.ravel()
    k = idx.shape[1] if idx.ndim == 2 else 3
    val = np.bincount(flat_e, minlength=s.ne)
    j = np.arange(len(flat_e))
    at = np.empty((s.ne, 2), np.int64)         # first and last place in FE's flat order
    at[flat_e[::-1], 0] = j[::-1]              # (later writes win: the first occurrence)
    at[flat_e, 1] = j
    del j
    other = val != 2
    ef, ek = np.divmod(at, k)
    ef[other] = -1
    ek[other] = -1
    return ef, ek, val
