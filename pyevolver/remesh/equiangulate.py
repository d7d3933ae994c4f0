"""``u``: equiangulation by edge flips (spec §8.2).

One pass over the edges in id order.  An edge with exactly two facets,
opposite sides (b, c) and (d, e), is flipped to the other diagonal when

    (b² + c² − a²)/(bc) + (d² + e² − a²)/(de) < −0.001

i.e. when its two opposite angles sum to more than about π (the Delaunay
criterion, Dyn–Hormann–Kim–Levin 2001; the Evolver's "equiangulation").
The criterion is evaluated for every edge at once; only the edges that pass
it, and the edges whose facets a flip changed, are then visited one by one
in id order, so the result is that of the Evolver's sequential pass.
"""
from __future__ import annotations

import copy
import heapq
import math

import numpy as np

from ..geometry import kernels as G
from ..model.groups import group_of
from ..model.records import (along_first, edge_facets, record_along_first,
                             record_vertex_rings, settle_records)
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
    Runs of flips with no vertex in common are replayed at once.  The rings
    are computed when first read (:func:`record_vertex_rings`)."""
    settle_records(s)                     # (no chain of surfaces kept for later)
    E, nv = t.E.copy() if E is None else E, t.nv
    record_vertex_rings(t, lambda: _rings_after_flips(s, E, nv, moves), E)


def _rings_after_flips(s, E, nv, moves):
    """The rank of :func:`_flip_rings` (``E``, ``nv``: the new surface's)."""
    g = Rings(s, len(E), nv)
    I = np.concatenate([m[0] for m in moves])
    o = np.argsort(I, kind="stable")
    I = I[o]
    p = np.concatenate([m[1] for m in moves])[o]
    q = np.concatenate([m[2] for m in moves])[o]
    x, y = E[I, 0], E[I, 1]
    quads = np.stack([p, q, x, y], 1).tolist()
    start, used = 0, set()
    for k in range(len(I) + 1):
        if k < len(I) and not used.intersection(quads[k]):
            used.update(quads[k])
            continue
        b = slice(start, k)
        g.remove(p[b], 2 * I[b])
        g.remove(q[b], 2 * I[b] + 1)
        g.insert(x[b], 2 * I[b])
        g.insert(y[b], 2 * I[b] + 1)
        if k < len(I):
            start, used = k, set(quads[k])
    return g.rank()


def _flat(a):
    """A one-dimensional memoryview of C-contiguous array ``a`` (writes go
    into ``a``)."""
    if not a.flags.c_contiguous:
        raise ValueError("_flat: the array must be C-contiguous")
    return memoryview(a.reshape(-1))


def _quads(E, FE, ef, edges):
    """For each edge of ``edges`` (two facets of opposite orientations): its
    facets ``fa`` (running along the edge) and ``fb``, the other sides
    ``b1, c1`` of fa and ``b2, c2`` of fb (signed, in facet order after the
    edge) and the opposite vertices ``r`` (of fa) and ``sv`` (of fb).
    Edges whose facets do not run opposite ways are dropped (None if none)."""
    fa, fb = ef[edges, 0], ef[edges, 1]
    A = np.where(FE[fa] >= 0, FE[fa], ~FE[fa])
    ka = np.argmax(A == edges[:, None], axis=1)
    B = np.where(FE[fb] >= 0, FE[fb], ~FE[fb])
    kb = np.argmax(B == edges[:, None], axis=1)
    sa = FE[fa, ka]
    swap = sa < 0
    fa, fb = np.where(swap, fb, fa), np.where(swap, fa, fb)
    ka, kb = np.where(swap, kb, ka), np.where(swap, ka, kb)
    if not (np.all(FE[fa, ka] >= 0) and np.all(FE[fb, kb] < 0)):
        return None
    b1, c1 = FE[fa, (ka + 1) % 3], FE[fa, (ka + 2) % 3]
    b2, c2 = FE[fb, (kb + 1) % 3], FE[fb, (kb + 2) % 3]

    def head(x):
        return np.where(x >= 0, E[np.where(x >= 0, x, 0), 1], E[np.where(x < 0, ~x, 0), 0])
    return fa, fb, b1, c1, b2, c2, head(b1), head(b2)


def _passes(FEabs, ef, edges, lengths, threshold, ek=None):
    """The flip criterion of each edge of ``edges`` (bool), from the facets'
    unsigned edges ``FEabs`` and the edge lengths; always true for
    ``threshold = inf``.  ``ek``
    (the edges' sides in their facets, from :func:`edge_facets`) saves the
    search when the facets are those ``edge_facets`` saw."""
    if not np.isfinite(threshold):
        return np.ones(len(edges), bool)
    a = lengths[edges]
    tot = np.zeros(len(edges))
    rows = np.arange(len(edges))
    for j in (0, 1):
        A = FEabs[ef[edges, j]]
        k = ek[edges, j] if ek is not None else np.argmax(A == edges[:, None], axis=1)
        b = lengths[A[rows, (k + 1) % 3]]
        c = lengths[A[rows, (k + 2) % 3]]
        with np.errstate(all="ignore"):
            tot += (b * b + c * c - a * a) / (b * c)
    return tot < threshold


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
    """
    if s.nf == 0:
        return s, 0
    t = copy.copy(s)
    t.E = s.E.copy()
    t.FE = s.FE.copy()
    t.eattr = dict(s.eattr)
    if "wrap" in s.eattr:
        t.eattr["wrap"] = s.eattr["wrap"].copy()
    t.__dict__.pop("_lift_cache", None)
    E, FE = t.E, t.FE
    wrap = t.eattr.get("wrap")
    ef, ekk, val = edge_facets(s)          # (s: its topology is cached; the same as t's)
    first = along_first(s)
    wv = t.wrap_shift()
    group = group_of(t)
    if group is None:
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
    cand = np.nonzero(ok)[0]
    if len(cand):
        cand = cand[_passes(s.topology()[0], ef, cand, lengths, threshold, ekk)]
    if not len(cand):
        return s, 0

    # Candidates whose quadrilaterals share no vertex with another
    # candidate's cannot interact with any other visit of the pass (their
    # flips change only facets and edges among their own four vertices), so
    # they are flipped at once; the rest go through the sequential pass.
    nv = t.nv
    heap = cand
    flips_at_once = 0
    moves = []              # (edges, old tails, old heads) in the order flipped
    # adjacency for the "already joined" test
    pairs = set((np.minimum(E[:, 0], E[:, 1]) * nv + np.maximum(E[:, 0], E[:, 1])).tolist())
    if wrap is None:
        quad = _quads(E, FE, ef, cand)
        if quad is not None:
            fa, fb, b1, c1, b2, c2, r, sv = quad
            use = np.bincount(np.concatenate([E[cand, 0], E[cand, 1], r, sv]), minlength=nv)
            iso = ((use[E[cand, 0]] == 1) & (use[E[cand, 1]] == 1) & (use[r] == 1)
                   & (use[sv] == 1) & (r != sv))
            k = np.minimum(r, sv) * nv + np.maximum(r, sv)
            iso &= np.array([x not in pairs for x in k.tolist()], bool)   # r, sv not joined
            if iso.any():
                I = cand[iso]
                fa, fb, b1, c1, b2, c2, r, sv = (x[iso] for x in quad)
                moves.append((I, E[I, 0].copy(), E[I, 1].copy()))
                pairs.difference_update((np.minimum(E[I, 0], E[I, 1]) * nv
                                         + np.maximum(E[I, 0], E[I, 1])).tolist())
                pairs.update(k[iso].tolist())
                al = first[I][:, None]
                E[I, 0], E[I, 1] = np.where(al[:, 0], sv, r), np.where(al[:, 0], r, sv)
                FE[fa] = np.where(al, np.stack([I, c1, b2], 1), np.stack([I, c2, b1], 1))
                FE[fb] = np.where(al, np.stack([~I, c2, b1], 1), np.stack([~I, c1, b2], 1))
                mv1, mv2 = np.where(al[:, 0], b1, c1), np.where(al[:, 0], b2, c2)
                for side, old, new in ((mv1, fa, fb), (mv2, fb, fa)):
                    i = np.where(side >= 0, side, ~side)
                    two = val[i] == 2
                    i, old, new = i[two], old[two], new[two]
                    ef[i, 0] = np.where(ef[i, 0] == old, new, ef[i, 0])
                    ef[i, 1] = np.where(ef[i, 1] == old, new, ef[i, 1])
                lengths[I] = np.linalg.norm(t.X[r] - t.X[sv], axis=1)
                flips_at_once = len(I)
                # their outer sides, visited after them, are visited again
                # if they pass now (if not, only a later flip next to them
                # can make them pass, and that flip puts them back)
                outer = np.stack([c1, b2, c2, b1], 1)
                outer = np.where(outer >= 0, outer, ~outer)
                later = outer > I[:, None]
                again = np.sort(outer[later])         # (repeats: skipped when popped)
                okd = np.zeros(len(again), bool)
                sel = ok[again]
                okd[sel] = _passes(np.where(FE >= 0, FE, ~FE), ef, again[sel], lengths,
                                    threshold)
                heap = np.concatenate([cand[~iso], again[okd]])

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
    t.__dict__.pop("_topo", None)          # E and FE were changed
    if flips + flips_at_once:
        # an edge's facet loop keeps its start through the flips (REF, ee.facet)
        copies = (t.FE.copy(), t.E.copy())    # (one copy for both records)
        record_along_first(t, first, copies)
        if seq_moves:               # (one block, in the order flipped)
            sm = np.array(seq_moves, dtype=np.int64).reshape(-1, 3)
            moves.append((sm[:, 0], sm[:, 1], sm[:, 2]))
        _flip_rings(s, t, moves, copies[1])
    t.topology_version = getattr(s, "topology_version", 0) + 1
    return t, flips + flips_at_once
