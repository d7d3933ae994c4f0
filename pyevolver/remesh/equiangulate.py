"""``u``: equiangulation by edge flips (spec §8.2).

One pass over the edges in id order.  An edge with exactly two facets,
opposite sides (b, c) and (d, e), is flipped to the other diagonal when

    (b² + c² − a²)/(bc) + (d² + e² − a²)/(de) < −0.001

i.e. when its two opposite angles sum to more than about π (the Delaunay
criterion, Dyn–Hormann–Kim–Levin 2001; the Evolver's "equiangulation").
The criterion is evaluated for every edge at once; the pass then runs in
rounds of visits that cannot influence each other
(:mod:`pyevolver.remesh.flip_rounds`), or, on a torus, with a symmetry
group and where the rounds cannot tell, visits the edges that pass and the
edges whose facets a flip changed one by one in id order: either way the
result is that of the Evolver's sequential pass.
"""
from __future__ import annotations

import copy
import heapq
import math
from types import SimpleNamespace

import numpy as np

from ..geometry import kernels as G
from ..model.groups import group_of
from ..model.records import (along_first, edge_facets, record_along_first,
                             record_vertex_rings, settle_records)
from .flip_rounds import flip_rounds, initial_criterion
from .rings import Rings


def _div(a, b):
    """``a / b`` with IEEE results for ``b == 0`` (as the Evolver's C): a
    zero-length side makes the criterion infinite or NaN, not an error."""
    if b == 0:
        if a == 0 or a != a:
            return math.nan
        return math.copysign(math.inf, a) * math.copysign(1.0, b)
    return a / b


def _flip_rings(s, t, moves, E=None):
    """Record REF's edge rings (:mod:`pyevolver.remesh.rings`) of ``t``, ``s``
    with edges flipped: ``moves`` lists (edges, old tails, old heads).
    The pass flips in edge id order; each flip takes the edge out of the
    rings of its old ends and puts it in those of its new ends (measured
    with ``vv.edge`` after ``u`` on catbody.fe, column.fe and quad.fe).
    Flips with no vertex in common are replayed at once
    (:func:`_rings_after_flips`).  The rings are computed when first read
    (:func:`record_vertex_rings`)."""
    settle_records(s)                     # (no chain of surfaces kept for later)
    E, nv = t.E.copy() if E is None else E, t.nv
    record_vertex_rings(t, lambda: _rings_after_flips(s, E, nv, moves), E)


def _rings_after_flips(s, E, nv, moves):
    """The rank of :func:`_flip_rings` (``E``, ``nv``: the new surface's).

    The flips are replayed in rounds: a flip goes in a round when no
    earlier flip not yet replayed has one of its four vertices (changes of
    the rings of distinct vertices commute, so this is the replay in id
    order)."""
    g = Rings(s, len(E), nv)
    I = np.concatenate([m[0] for m in moves])
    o = np.argsort(I, kind="stable")
    I = I[o]
    p = np.concatenate([m[1] for m in moves])[o]
    q = np.concatenate([m[2] for m in moves])[o]
    x, y = E[I, 0], E[I, 1]
    V = np.stack([p, q, x, y], 1)
    low = np.empty(nv, np.int64)
    pend = np.arange(len(I))
    while len(pend):
        W = V[pend]
        low[W.ravel()[::-1]] = np.repeat(pend, 4)[::-1]     # (the last write wins: the lowest)
        ready = (low[W] == pend[:, None]).all(axis=1)
        b = pend[ready]
        pend = pend[~ready]
        g.remove(p[b], 2 * I[b])
        g.remove(q[b], 2 * I[b] + 1)
        g.insert(x[b], 2 * I[b])
        g.insert(y[b], 2 * I[b] + 1)
    return g.rank()


def _flat(a):
    """A one-dimensional memoryview of C-contiguous array ``a`` (writes go
    into ``a``)."""
    if not a.flags.c_contiguous:
        raise ValueError("_flat: the array must be C-contiguous")
    return memoryview(a.reshape(-1))


def _edge_lengths(X, E):
    """Edge lengths, axis by axis: the numbers of
    ``np.linalg.norm(X[E[:, 1]] - X[E[:, 0]], axis=1)`` (the squares summed
    in axis order), without its (ne, 3) temporaries."""
    e0, e1 = E[:, 0], E[:, 1]
    acc = None
    for c in range(X.shape[1]):
        x = X[e1, c] - X[e0, c]
        x *= x
        acc = x if acc is None else np.add(acc, x, out=acc)
    return np.sqrt(acc, out=acc)


def _signature(s):
    """Per edge and per facet, an integer key of constraint/boundary sets."""
    ek = np.zeros(s.ne, np.int64)
    fk = np.zeros(s.nf, np.int64)
    for n, cid in enumerate(sorted(set(s.econ) | set(s.fcon))):
        bit = np.int64(1) << np.int64(n % 62)
        if cid in s.econ:
            ek |= np.where(s.econ[cid] != 0, bit, 0)
        if cid in s.fcon:
            fk |= np.where(s.fcon[cid], bit, 0)
    eb = s.eattr.get("boundary")
    fb = s.fattr.get("boundary")
    if eb is not None:
        ek = ek * 1000003 + eb
    if fb is not None:
        fk = fk * 1000003 + fb
    elif eb is not None:
        fk = fk * 1000003
    return ek, fk


def _group_vectors(t, group, idx):
    """``g(x_head) - x_tail`` of the edges ``idx`` in a symmetry group."""
    A, b = group.affine(t.eattr["wrap_code"][idx])
    E = t.E[idx]
    return np.einsum("eij,ej->ei", A, t.X[E[:, 1]]) + b - t.X[E[:, 0]]


def equiangulate(s, threshold=-0.001, only=None):
    """One equiangulation pass; returns ``(new surface, number of flips)``.

    With ``only`` (a (ne,) bool mask) just those edges are candidates, and
    with ``threshold=inf`` they are flipped whatever the angles
    (``edgeswap``); the topological conditions are the same.

    A surface without torus wraps or a symmetry group goes through the pass
    in rounds of independent visits (:mod:`pyevolver.remesh.flip_rounds`);
    the others, and the rare surfaces the rounds cannot decide, visit the
    candidates one by one.
    """
    if s.nf == 0:
        return s, 0
    t, c = _prepare(s, threshold, only)
    if c is None:
        return s, 0
    moves = None
    if c.wrap is None and c.group is None:
        moves = flip_rounds(t.X, t.E, t.FE, c.ef, c.val, c.cand_items, c.first, c.lengths,
                            threshold, c.maybe)
        if moves is None:               # (the rounds could not tell: one by one)
            t, c = _prepare(s, threshold, only)
    if moves is None:
        moves = _sequential(t, c, threshold)
    t.__dict__.pop("_topo", None)          # E and FE were changed
    flips = sum(len(m[0]) for m in moves)
    if flips:
        # an edge's facet loop keeps its start through the flips (REF, ee.facet)
        copies = (t.FE, t.E)    # (t's own arrays, never written again: refine.split_edges)
        record_along_first(t, c.first, copies)
        _flip_rings(s, t, moves, copies[1])
    t.topology_version = getattr(s, "topology_version", 0) + 1
    return t, flips


def _prepare(s, threshold, only):
    """A copy ``t`` of ``s`` whose ``E``, ``FE`` (and wraps) the pass may
    change, and the pass's arrays (None when no edge passes the test)."""
    t = copy.copy(s)
    t.E = s.E.copy()
    t.FE = s.FE.copy()
    t.eattr = dict(s.eattr)
    if "wrap" in s.eattr:
        t.eattr["wrap"] = s.eattr["wrap"].copy()
    t.__dict__.pop("_lift_cache", None)
    E = t.E
    wrap = t.eattr.get("wrap")
    ef, ekk, val = edge_facets(s)          # (s: its topology is cached; the same as t's)
    wv = t.wrap_shift()
    group = group_of(t)
    if group is None and wv is None and t.X.shape[1] == 3:
        lengths = _edge_lengths(t.X, E)
    elif group is None:
        lengths = np.linalg.norm(G.edge_vectors(t.X, E, wv), axis=1)
    else:                       # a symmetry group's codes (model.groups): sequential pass
        wrap = t.eattr["wrap_code"] = s.eattr["wrap_code"].copy()
        lengths = np.linalg.norm(_group_vectors(t, group, np.arange(t.ne)), axis=1)
    tension = t.fattr["tension"]
    esig, fsig = _signature(t)

    # vectorized first test: which edges pass the criterion now
    eligible = (val == 2) & ~t.eattr["fixed"]
    if only is not None:
        eligible &= only
    f0, f1 = ef[:, 0], ef[:, 1]
    ok = eligible & (f0 >= 0)
    ok[ok] &= np.abs(tension[f0[ok]] - tension[f1[ok]]) <= 1e-10
    ok[ok] &= (fsig[f0[ok]] == esig[ok]) & (fsig[f1[ok]] == esig[ok])
    items = np.nonzero(ok)[0]
    FEabs = s.topology()[0]
    if not np.isfinite(threshold):
        passing = np.ones(len(items), bool)
    else:
        with np.errstate(all="ignore"):
            passing = initial_criterion(FEabs, ef, ekk, items, lengths) < threshold
    cand = items[passing]
    if not len(cand):
        return t, None
    maybe = np.zeros(t.ne, bool)
    maybe[cand] = True
    return t, SimpleNamespace(ef=ef, val=val, ok=ok, cand_items=items, cand=cand,
                              maybe=maybe, first=along_first(s), lengths=lengths,
                              wrap=wrap, wv=wv, group=group)


def _sequential(t, c, threshold):
    """The pass visiting the candidates one by one in id order, changing
    ``t`` (and ``c``'s arrays) in place; returns the flips as one block
    (edges, old tails, old heads)."""
    E, FE, ef, val, ok, first = t.E, t.FE, c.ef, c.val, c.ok, c.first
    wrap, wv, group, nv = c.wrap, c.wv, c.group, t.nv
    lengths = c.lengths
    # adjacency for the "already joined" test
    pairs = set((np.minimum(E[:, 0], E[:, 1]) * nv + np.maximum(E[:, 0], E[:, 1])).tolist())
    heap = c.cand
    heap = np.asarray(heap).tolist()
    heapq.heapify(heap)
    flips = 0
    finite = bool(np.isfinite(threshold))
    Xl = t.X                     # read with .item(): scalar access without array temporaries
    # memoryviews of the arrays for the sequential part: indexing them gives
    # and takes Python numbers as fast as a list's, without converting the
    # whole arrays to lists and back (E, FE, ef and lengths change in place)
    okl = _flat(ok)
    vall = _flat(val)
    lengths = _flat(lengths)
    El = _flat(E)
    FEl = _flat(FE)
    efl = _flat(ef)
    firstl = _flat(np.ascontiguousarray(first))

    def dec(x):
        return x if x >= 0 else ~x

    last = -1
    seq_moves = []
    pop, push = heapq.heappop, heapq.heappush
    while heap:
        ed = pop(heap)
        if ed == last:              # pops come in increasing order: a repeat is adjacent
            continue
        last = ed
        if not okl[ed]:
            continue
        fa, fb = efl[2 * ed], efl[2 * ed + 1]
        row_a = FEl[3 * fa], FEl[3 * fa + 1], FEl[3 * fa + 2]
        row_b = FEl[3 * fb], FEl[3 * fb + 1], FEl[3 * fb + 2]
        ned = ~ed
        x = row_a[0]
        ka = 0 if (x == ed or x == ned) else (1 if (row_a[1] == ed or row_a[1] == ned) else 2)
        x = row_b[0]
        kb = 0 if (x == ed or x == ned) else (1 if (row_b[1] == ed or row_b[1] == ned) else 2)
        if row_a[ka] < 0:
            fa, fb, ka, kb, row_a, row_b = fb, fa, kb, ka, row_b, row_a
        if row_a[ka] < 0 or row_b[kb] >= 0:
            continue            # the two facets do not have opposite orientations
        b1, c1 = row_a[(ka + 1) % 3], row_a[(ka + 2) % 3]
        b2, c2 = row_b[(kb + 1) % 3], row_b[(kb + 2) % 3]
        # (the tests have no side effects: the criterion, the most selective, first)
        if finite:
            A = lengths[ed]
            lb = lengths[b1 if b1 >= 0 else ~b1]
            lc = lengths[c1 if c1 >= 0 else ~c1]
            ld = lengths[b2 if b2 >= 0 else ~b2]
            le = lengths[c2 if c2 >= 0 else ~c2]
            d1, d2 = lb * lc, ld * le
            if d1 and d2:
                crit = (lb * lb + lc * lc - A * A) / d1 + (ld * ld + le * le - A * A) / d2
            else:
                crit = _div(lb * lb + lc * lc - A * A, d1) + _div(ld * ld + le * le - A * A, d2)
            if not crit < threshold:
                continue
        r = El[2 * b1 + 1] if b1 >= 0 else El[2 * ~b1]          # head of b1
        sv = El[2 * b2 + 1] if b2 >= 0 else El[2 * ~b2]         # head of b2
        if r == sv:
            continue
        key = r * nv + sv if r < sv else sv * nv + r
        if key in pairs:
            continue
        # flip: a was p->q in fa = (a, b1: q->r, c1: r->p), fb = (~a, b2: p->s, c2: s->q).
        # As REF (list edges / list facets after u): when fa comes first in the
        # edge's facet loop the new edge runs s->r, fa = (a, c1, b2) and
        # fb = (~a, c2, b1); when fb does, r->s, fa = (a, c2, b1), fb = (~a, c1, b2)
        p, q = El[2 * ed], El[2 * ed + 1]
        seq_moves.append((ed, p, q))
        pairs.discard(min(p, q) * nv + max(p, q))
        pairs.add(key)
        al = firstl[ed]
        if group is not None:
            def o(x):
                return wrap[x] if x >= 0 else int(group.inverse(wrap[~x]))
            # through p: s -> p -> r when the new edge runs s -> r, else r -> p -> s
            wrap[ed] = int(group.compose(group.inverse(o(b2)), group.inverse(o(c1)))) if al \
                else int(group.compose(o(c1), o(b2)))
        elif wrap is not None:
            def w(x):
                return wrap[x] if x >= 0 else -wrap[~x]
            wrap[ed] = (-1 if al else 1) * (w(c1) + w(b2))       # through p
        if al:
            El[2 * ed], El[2 * ed + 1] = sv, r
            FEl[3 * fa], FEl[3 * fa + 1], FEl[3 * fa + 2] = ed, c1, b2
            FEl[3 * fb], FEl[3 * fb + 1], FEl[3 * fb + 2] = ~ed, c2, b1
            moved = ((b1, fa, fb), (b2, fb, fa))
        else:
            El[2 * ed], El[2 * ed + 1] = r, sv
            FEl[3 * fa], FEl[3 * fa + 1], FEl[3 * fa + 2] = ed, c2, b1
            FEl[3 * fb], FEl[3 * fb + 1], FEl[3 * fb + 2] = ~ed, c1, b2
            moved = ((c1, fa, fb), (c2, fb, fa))
        for side, old, new in moved:
            i = dec(side)
            if vall[i] == 2:
                if efl[2 * i] == old:
                    efl[2 * i] = new
                if efl[2 * i + 1] == old:
                    efl[2 * i + 1] = new
        if group is not None:
            E[ed] = (El[2 * ed], El[2 * ed + 1])
            lengths[ed] = float(np.linalg.norm(_group_vectors(t, group, np.array([ed]))[0]))
        elif wv is None:
            dx = Xl.item(r, 0) - Xl.item(sv, 0)
            dy = Xl.item(r, 1) - Xl.item(sv, 1)
            dz = Xl.item(r, 2) - Xl.item(sv, 2)
            lengths[ed] = math.sqrt(dx * dx + dy * dy + dz * dz)
        else:
            E[ed] = (El[2 * ed], El[2 * ed + 1])
            lengths[ed] = float(np.linalg.norm(G.edge_vectors(
                t.X, E[ed:ed + 1], wrap[ed:ed + 1] @ t.periods), axis=1)[0])
        flips += 1
        # edges of the changed facets come up again if not yet visited
        for x in (c1, b2, c2, b1):
            i = x if x >= 0 else ~x
            if i > ed:                # not yet visited (visits go in id order)
                push(heap, i)
    if not seq_moves:
        return []
    sm = np.array(seq_moves, dtype=np.int64).reshape(-1, 3)
    return [(sm[:, 0], sm[:, 1], sm[:, 2])]
