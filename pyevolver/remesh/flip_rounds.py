"""The equiangulation pass in rounds of independent visits.

The Evolver's pass (:func:`pyevolver.remesh.equiangulate.equiangulate`)
visits the candidate edges one by one in id order.  A visit reads the edge's
two facets (the lengths of their sides, the heads of two of them) and
whether the new diagonal's ends are already joined; a flip writes those two
facets, the edge, the facet records of its four outer sides and the set of
joined pairs.

Here every candidate edge (an *item*) is visited once, in rounds: in a round
the items are visited that are the lowest undecided item of both their
facets (deterministic reservations).  Items of one round share no facet,
and every facet is visited by items in increasing id order, so each visit
reads of its facets what the sequential pass reads.  The joined pairs are
not local to facets: every test and every change of a pair is logged with
its round, and the result is the sequential pass's when no change of a pair
came, relative to a test of that pair by another item, on the other side of
the id order (:func:`_pairs_in_order`).  A pair is joined when an edge of
the surface at the time joins it: the same as the sequential pass's set of
pairs until a flip takes away one of two edges joining the same vertices.
When a change came out of order, or at such a flip, :func:`flip_rounds`
returns None and the caller runs the sequential pass.
"""
from __future__ import annotations

import numpy as np


def facet_terms(FEabs: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """(n, 3) the criterion's term ``(b² + c² − a²)/(bc)`` of each side of
    the facets ``FEabs`` (rows of unsigned edge ids), ``a`` the side's
    length and ``b``, ``c`` the other two (IEEE results for zero lengths).

    Parameters
    ----------
    FEabs : (n, 3) int array
        The facets' unsigned edge ids.
    lengths : (ne,) float array
        Edge lengths.

    Returns
    -------
    (n, 3) float array
    """
    L = lengths[FEabs]
    L0, L1, L2 = L[:, 0], L[:, 1], L[:, 2]
    S0, S1, S2 = L0 * L0, L1 * L1, L2 * L2
    out = np.empty_like(L)
    with np.errstate(all="ignore"):
        np.divide((S1 + S2) - S0, L1 * L2, out=out[:, 0])
        np.divide((S2 + S0) - S1, L2 * L0, out=out[:, 1])
        np.divide((S0 + S1) - S2, L0 * L1, out=out[:, 2])
    return out


def initial_criterion(FEabs: np.ndarray, ef: np.ndarray, ek: np.ndarray,
                      items: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """The flip criterion's sum of the two facets' terms for ``items``
    (edges with two facets ``ef`` at sides ``ek``), the same numbers as a
    visit computes.

    Parameters
    ----------
    FEabs : (nf, 3) int array
        The facets' unsigned edge ids.
    ef, ek : (ne, 2) int arrays
        Each edge's two facets and its sides in them (:func:`edge_facets`).
    items : (m,) int array
        The edges.
    lengths : (ne,) float array
        Edge lengths.

    Returns
    -------
    (m,) float array
    """
    T = facet_terms(FEabs, lengths)
    return T[ef[items, 0], ek[items, 0]] + T[ef[items, 1], ek[items, 1]]


def _key(a: np.ndarray, b: np.ndarray, nv: int) -> np.ndarray:
    return np.minimum(a, b) * nv + np.maximum(a, b)


def _pairs_in_order(tests: list, writes: list) -> bool:
    """True when every change of a joined pair is on the same side of every
    other item's test of that pair in the rounds as in the id order: a change
    by a lower item in an earlier round, by a higher one in the same or a
    later round.  ``tests`` and ``writes``: lists of (keys, items, round)."""
    if not tests or not writes:
        return True
    tk = np.concatenate([t[0] for t in tests])
    ti = np.concatenate([t[1] for t in tests])
    tr = np.concatenate([np.full(len(t[0]), t[2]) for t in tests])
    wk = np.concatenate([w[0] for w in writes])
    wi = np.concatenate([w[1] for w in writes])
    wr = np.concatenate([np.full(len(w[0]), w[2]) for w in writes])
    o = np.argsort(wk, kind="stable")
    wk, wi, wr = wk[o], wi[o], wr[o]
    lo = np.searchsorted(wk, tk)
    hi = np.searchsorted(wk, tk, "right")
    n = hi - lo
    if not n.any():
        return True
    rep = np.repeat(np.arange(len(tk)), n)
    j = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n) + lo[rep]
    e, r, x, rx = ti[rep], tr[rep], wi[j], wr[j]
    bad = ((x < e) & (rx >= r)) | ((x > e) & (rx < r))
    return not bad.any()


def flip_rounds(X: np.ndarray, E: np.ndarray, FE: np.ndarray, ef: np.ndarray,
                val: np.ndarray, items: np.ndarray, first: np.ndarray,
                lengths: np.ndarray, threshold: float, maybe: np.ndarray):
    """Run the equiangulation pass over ``items`` in rounds, changing ``E``,
    ``FE``, ``ef`` and ``lengths`` in place as the sequential pass would.

    Parameters
    ----------
    X : (nv, 3) float array
        Vertex coordinates (no torus wrap, no symmetry group).
    E, FE : int arrays
        The surface's edges (ne, 2) and facets' signed edges (nf, 3).
    ef : (ne, 2) int array
        Each edge's two facets (:func:`pyevolver.model.records.edge_facets`).
    val : (ne,) int array
        Each edge's number of facets.
    items : (m,) int array
        The candidate edges, increasing (two facets, not fixed, ...).
    first : (ne,) bool array
        The facet running along the edge comes first in its loop (the new
        edge's direction, :func:`pyevolver.model.records.along_first`).
    lengths : (ne,) float array
        Edge lengths.
    threshold : float
        Flip when the criterion is below it (``inf``: always).
    maybe : (ne,) bool array
        The items that may pass the criterion now (the others do not);
        changed in place.

    Returns
    -------
    list of (edges, old tails, old heads) or None
        The flips, a block per round; None when the rounds cannot tell the
        sequential pass's result (the caller runs that pass instead, on
        fresh copies of the arrays).
    """
    nv, nf = len(X), len(FE)
    mark = np.zeros(nv, bool)
    finite = bool(np.isfinite(threshold))
    fmin = np.empty(nf, np.int64)
    tests, writes, moves = [], [], []
    U = np.asarray(items, np.int64)
    rnd = 0
    while len(U):
        Fa, Fb = ef[U, 0], ef[U, 1]
        # each facet's lowest undecided item (the last write wins)
        fmin[np.stack([Fb, Fa], 1).ravel()[::-1]] = np.repeat(U, 2)[::-1]
        ready = (fmin[Fa] == U) & (fmin[Fb] == U)
        R = U[ready]
        U = U[~ready]
        P = R[maybe[R]]
        if len(P):
            flips = _visit(X, E, FE, ef, val, first, lengths, threshold, finite,
                           mark, P, maybe, tests, writes, rnd)
            if flips is None:
                return None
            if len(flips[0]):
                moves.append(flips)
        rnd += 1
    if not _pairs_in_order(tests, writes):
        return None
    return moves


def _visit(X, E, FE, ef, val, first, lengths, threshold, finite, mark, P, maybe,
           tests, writes, rnd):
    """Visit the items ``P`` of one round (no facet in common): test and
    flip them.  Returns (flipped edges, old tails, old heads), or None when
    a flip would move one edge twice (a degenerate quadrilateral)."""
    fa, fb = ef[P, 0], ef[P, 1]
    rowa, rowb = FE[fa], FE[fb]
    col = P[:, None]
    ka = np.argmax((rowa == col) | (rowa == ~col), axis=1)
    kb = np.argmax((rowb == col) | (rowb == ~col), axis=1)
    n = np.arange(len(P))
    swap = rowa[n, ka] < 0
    sw = swap[:, None]
    fa, fb = np.where(swap, fb, fa), np.where(swap, fa, fb)
    ka, kb = np.where(swap, kb, ka), np.where(swap, ka, kb)
    rowa, rowb = np.where(sw, rowb, rowa), np.where(sw, rowa, rowb)
    good = (rowa[n, ka] >= 0) & (rowb[n, kb] < 0)
    b1, c1 = rowa[n, (ka + 1) % 3], rowa[n, (ka + 2) % 3]
    b2, c2 = rowb[n, (kb + 1) % 3], rowb[n, (kb + 2) % 3]
    ub1, uc1 = np.where(b1 >= 0, b1, ~b1), np.where(c1 >= 0, c1, ~c1)
    ub2, uc2 = np.where(b2 >= 0, b2, ~b2), np.where(c2 >= 0, c2, ~c2)
    maybe[P] = False
    if finite:
        A = lengths[P]
        lb, lc, ld, le = lengths[ub1], lengths[uc1], lengths[ub2], lengths[uc2]
        AA = A * A
        with np.errstate(all="ignore"):
            crit = (lb * lb + lc * lc - AA) / (lb * lc) + (ld * ld + le * le - AA) / (ld * le)
        good &= crit < threshold
    r = np.where(b1 >= 0, E[ub1, 1], E[ub1, 0])          # head of b1
    sv = np.where(b2 >= 0, E[ub2, 1], E[ub2, 0])         # head of b2
    good &= r != sv
    nv = len(X)
    g = np.nonzero(good)[0]
    if not len(g):
        return P[:0], P[:0], P[:0]
    keys = _key(r[g], sv[g], nv)
    p, q = E[P[g], 0], E[P[g], 1]
    old = _key(p, q, nv)
    # the edges joining two of these vertices: is the new diagonal one of
    # them, is the old one the only edge joining its ends
    for v in (r[g], sv[g], p, q):
        mark[v] = True
    near = np.nonzero(mark[E[:, 0]] & mark[E[:, 1]])[0]
    mark[:] = False
    have = np.sort(_key(E[near, 0], E[near, 1], nv))
    present = np.searchsorted(have, keys, "right") > np.searchsorted(have, keys)
    tests.append((keys, P[g], rnd))
    keep = ~present
    flip, keys, p, q, old = g[keep], keys[keep], p[keep], q[keep], old[keep]
    if not len(flip):
        return P[:0], P[:0], P[:0]
    if np.any(np.searchsorted(have, old, "right") - np.searchsorted(have, old) > 1):
        return None                 # two edges join the ends of one (the set of pairs)
    I = P[flip]
    fa, fb, b1, c1, b2, c2, r, sv = (x[flip] for x in (fa, fb, b1, c1, b2, c2, r, sv))
    ub1, uc1, ub2, uc2 = ub1[flip], uc1[flip], ub2[flip], uc2[flip]
    al = first[I]
    mv1, mv2 = np.where(al, ub1, uc1), np.where(al, ub2, uc2)     # fa -> fb, fb -> fa
    if np.any(mv1 == mv2):
        return None
    writes.append((np.concatenate([old, keys]), np.concatenate([I, I]), rnd))
    # as REF: when fa comes first in the edge's facet loop the new edge runs
    # s->r, fa = (a, c1, b2), fb = (~a, c2, b1); when fb does, r->s,
    # fa = (a, c2, b1), fb = (~a, c1, b2)
    E[I, 0] = np.where(al, sv, r)
    E[I, 1] = np.where(al, r, sv)
    a2 = al[:, None]
    FE[fa] = np.where(a2, np.stack([I, c1, b2], 1), np.stack([I, c2, b1], 1))
    FE[fb] = np.where(a2, np.stack([~I, c2, b1], 1), np.stack([~I, c1, b2], 1))
    i = np.concatenate([mv1, mv2])
    o = np.concatenate([fa, fb])
    w = np.concatenate([fb, fa])
    two = val[i] == 2
    i, o, w = i[two], o[two], w[two]
    m0, m1 = ef[i, 0] == o, ef[i, 1] == o
    ef[i[m0], 0] = w[m0]
    ef[i[m1], 1] = w[m1]
    d = X[r] - X[sv]
    d0, d1, d2 = d[:, 0], d[:, 1], d[:, 2]
    lengths[I] = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    # the outer sides' facets changed: the undecided ones may pass now
    maybe[np.concatenate([ub1, uc1, ub2, uc2])] = True
    return I, p, q
