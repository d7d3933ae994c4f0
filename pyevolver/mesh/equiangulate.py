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

import heapq

import numpy as np

from .. import geometry as G


def edge_facets(s):
    """(ne, 2) the two facets of each edge and their sides, valence (ne,)."""
    idx, sgn, _ = s.topology()
    flat_e = idx.ravel()
    flat_f = np.repeat(np.arange(s.nf), 3)
    flat_k = np.tile(np.arange(3), s.nf)
    val = np.bincount(flat_e, minlength=s.ne)
    order = np.argsort(flat_e, kind="stable")
    start = np.concatenate([[0], np.cumsum(val)[:-1]])
    ef = np.full((s.ne, 2), -1, np.int64)
    ek = np.full((s.ne, 2), -1, np.int64)
    two = np.nonzero(val == 2)[0]
    ef[two, 0] = flat_f[order[start[two]]]
    ef[two, 1] = flat_f[order[start[two] + 1]]
    ek[two, 0] = flat_k[order[start[two]]]
    ek[two, 1] = flat_k[order[start[two] + 1]]
    return ef, ek, val


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


def equiangulate(s, threshold=-0.001, only=None):
    """One equiangulation pass; returns ``(new surface, number of flips)``.

    With ``only`` (a (ne,) bool mask) just those edges are candidates, and
    with ``threshold=inf`` they are flipped whatever the angles
    (``edgeswap``); the topological conditions are the same.
    """
    import copy
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
    ef, ekk, val = edge_facets(t)
    wv = t.wrap_shift()
    lengths = np.linalg.norm(G.edge_vectors(t.X, E, wv), axis=1)
    tension = t.fattr["tension"]
    esig, fsig = _signature(t)

    def opposite(e, f, k):
        """Lengths of the other two sides of facet f (e at side k), the
        encoded sides and the vertex opposite e."""
        s1 = FE[f, (k + 1) % 3]
        s2 = FE[f, (k + 2) % 3]
        i1 = s1 if s1 >= 0 else ~s1
        v = E[i1, 1] if s1 >= 0 else E[i1, 0]
        return s1, s2, v

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
        idx = t.topology()[0]

        def sides(fs, ks):
            return (lengths[idx[fs, (ks + 1) % 3]], lengths[idx[fs, (ks + 2) % 3]])
        a = lengths[cand]
        b, c = sides(f0[cand], ekk[cand, 0])
        d, e = sides(f1[cand], ekk[cand, 1])
        with np.errstate(all="ignore"):
            crit = (b * b + c * c - a * a) / (b * c) + (d * d + e * e - a * a) / (d * e)
        if np.isfinite(threshold):
            cand = cand[crit < threshold]
    if not len(cand):
        return s, 0

    # adjacency for the "already joined" test
    nv = t.nv
    pairs = set((np.minimum(E[:, 0], E[:, 1]) * nv + np.maximum(E[:, 0], E[:, 1])).tolist())
    heap = cand.tolist()
    heapq.heapify(heap)
    seen = set()
    flips = 0
    while heap:
        ed = heapq.heappop(heap)
        if ed in seen:
            continue
        seen.add(ed)
        if not ok[ed]:
            continue
        fa, fb = int(ef[ed, 0]), int(ef[ed, 1])
        ka = int(np.nonzero((FE[fa] == ed) | (FE[fa] == ~ed))[0][0])
        kb = int(np.nonzero((FE[fb] == ed) | (FE[fb] == ~ed))[0][0])
        if FE[fa, ka] < 0:
            fa, fb, ka, kb = fb, fa, kb, ka
        if FE[fa, ka] < 0 or FE[fb, kb] >= 0:
            continue            # the two facets do not have opposite orientations
        b1, c1, r = opposite(ed, fa, ka)
        b2, c2, sv = opposite(ed, fb, kb)
        if r == sv:
            continue
        key = min(r, sv) * nv + max(r, sv)
        if key in pairs:
            continue
        A = lengths[ed]
        lb, lc = lengths[b1 if b1 >= 0 else ~b1], lengths[c1 if c1 >= 0 else ~c1]
        ld, le = lengths[b2 if b2 >= 0 else ~b2], lengths[c2 if c2 >= 0 else ~c2]
        crit = (lb * lb + lc * lc - A * A) / (lb * lc) + (ld * ld + le * le - A * A) / (ld * le)
        if np.isfinite(threshold) and not crit < threshold:
            continue
        # flip: a was p->q in fa = (a, b1: q->r, c1: r->p), fb = (~a, b2: p->s, c2: s->q)
        p, q = int(E[ed, 0]), int(E[ed, 1])
        pairs.discard(min(p, q) * nv + max(p, q))
        pairs.add(key)
        if wrap is not None:
            def w(x):
                return wrap[x] if x >= 0 else -wrap[~x]
            wrap[ed] = -w(c1) - w(b2)          # s -> r through p
        E[ed] = (sv, r)
        FE[fa] = (c1, b2, ed)
        FE[fb] = (~ed, c2, b1)
        # b1 moved from fa to fb, b2 from fb to fa
        for side, old, new in ((b1, fa, fb), (b2, fb, fa)):
            i = side if side >= 0 else ~side
            if val[i] == 2:
                ef[i] = np.where(ef[i] == old, new, ef[i])
        new_len = np.linalg.norm(G.edge_vectors(t.X, E[ed:ed + 1],
                                                None if wv is None else
                                                (wrap[ed:ed + 1] @ t.periods)), axis=1)[0]
        lengths[ed] = new_len
        flips += 1
        # edges of the changed facets come up again if not yet visited
        for f in (fa, fb):
            for x in FE[f]:
                i = int(x if x >= 0 else ~x)
                if i > ed and i not in seen:
                    heapq.heappush(heap, i)
    t.__dict__.pop("_topo", None)          # E and FE were changed in place
    t.topology_version = getattr(s, "topology_version", 0) + 1
    return t, flips
