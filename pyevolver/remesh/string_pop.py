"""Popping in the string model: ``o`` / ``pop vertex`` and autopop's edge
deletion (measured on evolver-nox-d; the manual: "In the string model,
vertices with more than three edges are popped").

Vertex pop (:func:`pop_vertices`): while a vertex that is not FIXED, not on
a constraint or boundary has more than three edges, the two of its edges
with the smallest angle between them (the first such pair in REF's ring
order ``vv.edge`` on exact ties) are moved to a new vertex placed at
``0.1 * min(length of the two)`` from the old one along the bisector of
their directions; a new edge runs from the old vertex to the new one.  Each
such split counts one pop ("Vertices popped: N").  Facet chains that went
from one moved edge to an edge left at the old vertex get the new edge
inserted.  Measured on popstr.fe and on hand-written 4- and 5-valent
junctions (positions, ids, edge ends).

Edge deletion (:func:`delete_short_edges`, autopop): an edge shorter than
the critical length is deleted by merging its head into its tail (the
tail when the head may not go: FIXED or other constraints), the kept
vertex moving to the edge's midpoint when both could go.
"""
from __future__ import annotations

import numpy as np

from ..errors import UnsupportedError
from ..geometry.kernels import edge_vectors
from .grow import grow, remap_quantities
from .shrink import subset

#: the new vertex of a pop lies this fraction of the shorter moved edge off
POP_FRACTION = 0.1


def _dec(x):
    return x if x >= 0 else ~x


def edge_vecs(s):
    """Edge vectors (torus wraps included)."""
    return _edge_vecs(s)


def _edge_vecs(s):
    return edge_vectors(s.X, s.E, s.wrap_shift())


def _movable(s):
    """Vertices that may be popped or eliminated: not FIXED, on no
    constraint or boundary."""
    ok = ~s.vattr["fixed"].astype(bool)
    for on in s.vcon.values():
        ok &= ~on
    bnd = s.vattr.get("boundary")
    if bnd is not None:
        ok &= bnd == 0
    return ok


def _ring_order(s, v, edges):
    """``edges`` (ends at ``v``: (edge, +1 tail / -1 head)) in REF's ring order."""
    if "ring_time" not in s.eattr:
        return edges
    times = s.eattr["ring_time"]
    head = int(s.vattr["ring_head"][v])
    big = np.iinfo(np.int64).max

    def key(item):
        e, sg = item
        return -(big if e == head else int(times[e, 0 if sg > 0 else 1]))
    return sorted(edges, key=key)


def _ends_at(E, v):
    rows, cols = np.nonzero(E == v)
    return [(int(e), 1 if c == 0 else -1) for e, c in zip(rows, cols)]


def _facet_pairs(s, v):
    """The pairs of edges (indices) that follow each other in a facet chain
    through vertex ``v``."""
    enc, ptr = s.sf_enc, s.sf_ptr
    pairs = set()
    for f in range(len(ptr) - 1):
        chain = [int(x) for x in enc[ptr[f]:ptr[f + 1]]]
        m = len(chain)
        closed = m > 1 and _head(s, chain[-1]) == _tail(s, chain[0])
        for k in range(m if closed else m - 1):
            x, y = chain[k], chain[(k + 1) % m]
            if _head(s, x) == v and _dec(x) != _dec(y):
                pairs.add(frozenset((_dec(x), _dec(y))))
    return pairs


def _pop_one(s, v):
    """Split one pair of edges off vertex ``v``: a new surface.  The pair:
    the smallest angle among the pairs that follow each other in a facet
    (cell) at ``v`` (all pairs when no facet passes ``v``): on a tangled
    100grain.fe (``m 0.05; g 1``) REF passes over a smaller angle between
    two edges of no common cell."""
    ends = _ring_order(s, v, _ends_at(s.E, v))
    ev = _edge_vecs(s)
    out = np.array([ev[e] * sg for e, sg in ends])          # from v outwards
    lens = np.linalg.norm(out, axis=1)
    units = out / lens[:, None]
    fp = _facet_pairs(s, v)
    best, pair = -np.inf, (0, 1)
    for i in range(len(ends)):
        for j in range(i + 1, len(ends)):
            if fp and frozenset((ends[i][0], ends[j][0])) not in fp:
                continue
            c = float(out[i] @ out[j]) / float(lens[i] * lens[j])
            if c > best:
                best, pair = c, (i, j)
    i, j = pair
    bis = units[i] + units[j]
    nb = np.linalg.norm(bis)
    if nb == 0:
        raise UnsupportedError("popping a vertex with opposite edges only",
                               "REF's placement for this case was not measured")
    d = POP_FRACTION * min(lens[i], lens[j]) * bis / nb
    moved = [ends[i], ends[j]]
    a = moved[0][0]
    t = grow(s, v_from_edge=[a], e_from_edge=[a])
    w, n = s.nv, s.ne
    t.X[w] = s.X[v]
    t.X[w, :s.sdim] += d[:s.sdim]
    for key, arr in t.vattr.items():
        if key == "id":
            continue
        arr[w] = arr[v]
    if "original" in t.vattr:
        t.vattr["original"][w] = s.ids("vertex")[v]
    for cid, on in t.vcon.items():
        on[w] = bool(s.vcon[cid][v]) if cid in s.vcon else False
    t.E[n] = (v, w)
    if "original" in t.eattr:
        t.eattr["original"][n] = 0
    if "wrap" in t.eattr:
        t.eattr["wrap"][n] = 0
    for e, sg in moved:
        t.E[e, 0 if sg > 0 else 1] = w
    if "ring_time" in t.eattr:
        times = t.eattr["ring_time"] = t.eattr["ring_time"].copy()
        head = t.vattr["ring_head"] = t.vattr["ring_head"].copy()
        clock = int(times.max()) + 1 if len(times) else 0
        times[n] = (clock, clock + 3)       # the new edge joins v's ring
        for k, (e, sg) in enumerate(moved):
            times[e, 0 if sg > 0 else 1] = clock + 1 + k
        head[w] = moved[0][0]
        if head[v] in (moved[0][0], moved[1][0]):
            head[v] = n
    # facet chains: a step between a moved edge and one left at v goes via n
    moved_set = {e for e, _ in moved}
    enc = s.sf_enc
    ptr = s.sf_ptr
    out_enc, out_ptr = [], [0]
    for f in range(len(ptr) - 1):
        chain = [int(x) for x in enc[ptr[f]:ptr[f + 1]]]
        closed = len(chain) > 1 and _head(s, chain[-1]) == _tail(s, chain[0])
        new = []
        m = len(chain)
        for k, x in enumerate(chain):
            new.append(x)
            if k == m - 1 and not closed:
                break
            y = chain[(k + 1) % m]
            if _head(s, x) != v or _tail(s, y) != v:
                continue
            xm, ym = _dec(x) in moved_set, _dec(y) in moved_set
            if xm and not ym:
                new.append(~n)                  # w -> v
            elif ym and not xm:
                new.append(n)                   # v -> w
        out_enc.extend(new)
        out_ptr.append(len(out_enc))
    t.sf_enc = np.array(out_enc, np.int64)
    t.sf_ptr = np.array(out_ptr, np.int64)
    return t


def _tail(s, x):
    return int(s.E[x, 0]) if x >= 0 else int(s.E[~x, 1])


def _head(s, x):
    return int(s.E[x, 1]) if x >= 0 else int(s.E[~x, 0])


def _check(s):
    if getattr(s, "order", 1) == 2:
        raise UnsupportedError("popping in the quadratic string model",
                               "only the linear model is implemented")


def pop_vertices(s, verts=None, parents=None):
    """Pop the vertices ``verts`` (indices; all by default) that have more
    than three edges: ``(new surface, number of pops)``; ``parents``, a
    list, gets ``(new vertex, old vertex)`` for each pop."""
    _check(s)
    cand = np.arange(s.nv) if verts is None else np.asarray(verts, np.int64)
    n = 0
    for v in cand.tolist():
        while True:
            deg = np.count_nonzero(s.E == v)
            if deg <= 3 or not _movable(s)[v]:
                break
            if parents is not None:
                parents.append((s.nv, v))
            s = _pop_one(s, v)
            n += 1
    return s, n


def _compact(s, vkeep, ekeep):
    """Drop vertices and edges (string model): survivors keep their ids."""
    nv_ = np.full(s.nv, -1, np.int64)
    nv_[vkeep] = np.arange(int(vkeep.sum()))
    ne_ = np.full(s.ne, -1, np.int64)
    ne_[ekeep] = np.arange(int(ekeep.sum()))
    t = grow(s)
    t.vattr = {k: a[vkeep].copy() for k, a in t.vattr.items()}
    t.eattr = {k: a[ekeep].copy() for k, a in t.eattr.items()}
    t.vattr["id"] = s.ids("vertex")[vkeep].copy()
    t.eattr["id"] = s.ids("edge")[ekeep].copy()
    if "ring_head" in t.vattr:
        h = t.vattr["ring_head"]
        t.vattr["ring_head"] = np.where(h >= 0, ne_[np.maximum(h, 0)], -1)
    t.X = s.X[vkeep].copy()
    t.E = nv_[s.E[ekeep]]
    t.vcon = {c: a[vkeep].copy() for c, a in s.vcon.items()}
    t.econ = {c: a[ekeep].copy() for c, a in s.econ.items()}
    keep = {"vertex": vkeep, "edge": ekeep}
    t.extra = {(et, nm): (a[keep[et]].copy() if et in keep else a.copy())
               for (et, nm), a in s.extra.items()}
    enc = s.sf_enc
    e = np.where(enc >= 0, enc, ~enc)
    ok = ekeep[e]
    ne2 = ne_[e[ok]]
    t.sf_enc = np.where(enc[ok] >= 0, ne2, ~ne2)
    owner = np.repeat(np.arange(len(s.sf_ptr) - 1), np.diff(s.sf_ptr))[ok]
    t.sf_ptr = np.concatenate([[0], np.cumsum(np.bincount(
        owner, minlength=len(s.sf_ptr) - 1))]).astype(np.int64)
    newidx = {"vertex": nv_, "edge": ne_}

    def drop(etype, idx, sgn):
        if etype not in keep:
            return idx, sgn
        good = keep[etype][idx]
        return newidx[etype][idx[good]], sgn[good]
    t.quantities = remap_quantities(s, t, drop)
    if (t.E < 0).any():
        raise ValueError("string compaction: an edge refers to a dropped vertex")
    return t, nv_


def _same_cons(s, v, e):
    for c, on in s.vcon.items():
        on_e = s.econ.get(c)
        if on[v] and (on_e is None or on_e[e] == 0):
            return False
    return True


def delete_short_edges(s, crit, candidates=None, merges=None):
    """Delete the edges shorter than ``crit`` (of ``candidates`` if given;
    edge order, each seeing the previous deletions): ``(new surface, number deleted, old->new vertex
    map)``."""
    _check(s)
    X = s.X.copy()
    E = s.E.copy()
    wrap = s.eattr["wrap"].copy() if "wrap" in s.eattr and s.periods is not None else None
    ealive = np.ones(s.ne, bool)
    valive = np.ones(s.nv, bool)
    fixed = s.vattr["fixed"].astype(bool)
    efixed = s.eattr["fixed"].astype(bool)
    shift = None if wrap is None else s.periods
    efacets = None
    if len(s.sf_ptr) > 1:
        owner = np.repeat(np.arange(len(s.sf_ptr) - 1), np.diff(s.sf_ptr))
        enc = s.sf_enc
        efacets = [set() for _ in range(s.ne)]
        for ed, f in zip(np.where(enc >= 0, enc, ~enc).tolist(), owner.tolist()):
            efacets[ed].add(f)

    nfac = len(s.sf_ptr) - 1
    chains = [[int(x) for x in s.sf_enc[s.sf_ptr[f]:s.sf_ptr[f + 1]]] for f in range(nfac)]
    fdrop = np.zeros(nfac, bool)

    def vfacets(v):
        out = set()
        for x in np.nonzero((E == v).any(axis=1) & ealive)[0].tolist():
            out |= efacets[x]
        return out
    n = 0

    def head(e):
        h = X[E[e, 1]]
        if wrap is not None:
            h = h.copy()
            h[:shift.shape[1]] += wrap[e] @ shift
        return h
    eorder = np.argsort(s.ids("edge"), kind="stable")     # REF visits in id order
    if candidates is not None:
        eorder = eorder[np.isin(eorder, candidates)]
    for e in eorder.tolist():
        if not ealive[e] or efixed[e]:
            continue
        a, b = int(E[e, 0]), int(E[e, 1])
        if a == b:
            continue
        hx = head(e)
        d = hx - X[a]
        if candidates is None and np.linalg.norm(d) >= crit:
            continue                    # (candidates: chosen before any deletion)
        can_b = not fixed[b] and _same_cons(s, b, e)
        can_a = not fixed[a] and _same_cons(s, a, e)
        if efacets is not None:
            # a vertex on a facet the edge is not on stays (100grain.fe after
            # r: a junction keeps its place and absorbs the midpoint vertex);
            # when neither end may go by that rule, the head goes; only on an
            # edge of two facets, as t (string_dissolve4.fe)
            fa, fb = vfacets(a), vfacets(b)
            ok_a, ok_b = fa <= efacets[e], fb <= efacets[e]
            if can_a and can_b and (ok_a or ok_b) and len(efacets[e]) >= 2:
                can_a, can_b = ok_a, ok_b
        if not (can_a or can_b):
            continue
        if s.vcon and any(on[a] or on[b] for on in s.vcon.values()):
            raise UnsupportedError("autopop of an edge on a constraint",
                                   "REF's rule there was not measured")
        keep_v, gone = (a, b) if can_b else (b, a)
        if merges is not None:
            merges.append((keep_v, gone, bool(can_a and can_b)))
        if can_a and can_b:             # the midpoint, rounded as REF's
            X[a] = 0.5 * (X[a] + hx)    # (both may go: the tail is kept)
        we = None if wrap is None else (wrap[e] if keep_v == a else -wrap[e])
        ealive[e] = False
        at = np.nonzero((E == gone).any(axis=1) & ealive)[0]
        for x in at.tolist():
            if E[x, 0] == gone:
                E[x, 0] = keep_v
                if we is not None:
                    wrap[x] = wrap[x] + we
            if E[x, 1] == gone:
                E[x, 1] = keep_v
                if we is not None:
                    wrap[x] = wrap[x] - we
        valive[gone] = False
        n += 1
        if efacets is not None:
            for f in sorted(efacets[e]):
                _dissolve(f, chains, fdrop, efacets, ealive, E, wrap, set(at.tolist()))
    if not n:
        return s, 0, np.arange(s.nv)
    t = grow(s)
    t.X = X
    t.E = E
    if fdrop.any():
        t.sf_enc = np.array([x for f, ch in enumerate(chains) if not fdrop[f] for x in ch],
                            np.int64)
        t.sf_ptr = np.concatenate([[0], np.cumsum(
            [0 if fdrop[f] else len(ch) for f, ch in enumerate(chains)])]).astype(np.int64)
    if wrap is not None:
        t.eattr["wrap"] = wrap
    if "ring_time" in t.eattr:
        head = t.vattr["ring_head"] = t.vattr["ring_head"].copy()
        for v in np.nonzero(valive)[0].tolist():
            h = head[v]
            if h < 0 or not ealive[h] or v not in E[h]:
                at = np.nonzero((E == v).any(axis=1) & ealive)[0]
                head[v] = at[0] if len(at) else -1
    t, nv_ = _compact(t, valive, ealive)
    if fdrop.any():
        t = _drop_facets(t, ~fdrop)
    return t, n, nv_


def _dissolve(f, chains, fdrop, efacets, ealive, E, wrap, gone_sides):
    """A facet left with two sides between the same two vertices goes
    (REF: 100grain.fe ``m 0.05; g 2``, facet_count 98): the side that was
    at the eliminated vertex stays and takes the other's place in the
    other chains."""
    if fdrop[f]:
        return
    rest = [x for x in chains[f] if ealive[_dec(x)]]
    if len(rest) != 2:
        return
    r0, r1 = _dec(rest[0]), _dec(rest[1])
    if r0 == r1 or sorted(E[r0].tolist()) != sorted(E[r1].tolist()):
        return
    if (r0 in gone_sides) == (r1 in gone_sides):
        raise UnsupportedError("autopop leaving a facet of two edges with no side at the "
                               "eliminated vertex",
                               "REF's choice of the side kept was not measured")
    keep_side, dead = (r0, r1) if r0 in gone_sides else (r1, r0)
    same = E[dead, 0] == E[keep_side, 0]
    if wrap is not None and not np.array_equal(wrap[dead], wrap[keep_side] if same
                                               else -wrap[keep_side]):
        raise UnsupportedError("autopop leaving a facet of two edges around the torus",
                               "REF's handling was not measured")
    fwd = keep_side if same else ~keep_side
    fdrop[f] = True
    for g in efacets[dead]:
        chains[g] = [fwd if x == dead else ~fwd if x == ~dead else x for x in chains[g]]
    efacets[keep_side] |= efacets[dead] - {f}
    ealive[dead] = False


def _drop_facets(s, fkeep):
    """The string surface ``s`` without the facets not in ``fkeep``."""
    chains = [s.sf_enc[s.sf_ptr[f]:s.sf_ptr[f + 1]] for f in range(len(fkeep)) if fkeep[f]]
    dummy = np.zeros((len(fkeep), 3), np.int64)
    t = subset(s, s.E, dummy, np.ones(s.nv, bool), np.ones(s.ne, bool), fkeep)
    t.FE = np.zeros((0, 3), np.int64)
    t.sf_enc = np.concatenate(chains).astype(np.int64) if chains else np.zeros(0, np.int64)
    t.sf_ptr = np.concatenate([[0], np.cumsum([len(c) for c in chains])]).astype(np.int64)
    return t


def after_move_lengths(s):
    """Edge lengths (torus wraps included)."""
    return np.linalg.norm(_edge_vecs(s), axis=1)


def stretch_rates(s, vel):
    """``e . (vel[head] - vel[tail])`` per edge, ``e`` the edge vector
    (torus wraps included): the sign of autopop's test."""
    ev = _edge_vecs(s)
    dv = vel[s.E[:, 1]] - vel[s.E[:, 0]]
    return np.einsum("ij,ij->i", ev[:, :dv.shape[1]], dv[:, :ev.shape[1]])


def predicted_lengths(s, vel, scale):
    """The edge lengths one more move ``scale * vel`` would give, to first
    order (REF's autochop test, measured on a junction whose edges grow):
    ``|e| + scale * (e/|e|) . (vel[head] - vel[tail])``."""
    ev = _edge_vecs(s)
    L = np.linalg.norm(ev, axis=1)
    dv = vel[s.E[:, 1]] - vel[s.E[:, 0]]
    with np.errstate(all="ignore"):
        grow_ = np.einsum("ij,ij->i", ev[:, :dv.shape[1]], dv[:, :ev.shape[1]]) / L
    return L + scale * np.where(L > 0, grow_, 0.0)
