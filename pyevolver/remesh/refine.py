"""``r``: refine every edge and facet (spec §8.1), vectorized over the arrays.

Every edge without NO_REFINE is bisected (the original edge keeps the tail
half, the head half is a new edge); every facet is split across its refined
sides: into 4 triangles when all three are refined, 3 when two are, 2 when
one is.  New vertices on boundary edges are placed on the boundary curve
(:func:`boundary_midpoints`), new vertices on constraints are projected.
"""
from __future__ import annotations

import copy

import numpy as np

from ..methods import metric as MT
from ..geometry import kernels as G
from ..constraints import constrained_vertices, project_to_constraints
from ..model.records import (along_first, record_along_first, record_vertex_rings,
                             settle_records)
from ..model.facet_csr import PendingCSR
from ..model.groups import group_of
from . import group_refine as GR
from .grow import grow, reorder_new_edges
from .rings import Rings, rounds


def _enc(e, forward):
    """Encoded oriented edge: e forwards, ~e backwards."""
    return np.where(forward, e, ~e)


def boundary_midpoints(s, tails, heads, vnew, target=None):
    """Place the new vertices ``vnew`` (midpoints of ``edges``) on their
    parametric boundary: the curve point nearest the chord midpoint (or
    nearest ``target (len(vnew), 3)`` when given), by damped Gauss-Newton in
    parameter space started from the head vertex's parameters (at most 5
    outer steps, spec §6.3).  Vertices not on a boundary are left as they are."""
    if "boundary" not in s.vattr:
        return
    bnd = s.vattr["boundary"]
    env0 = s.param_env()
    for bid, b in s.boundaries.items():
        sel = np.nonzero(bnd[vnew] == bid)[0]
        if not len(sel):
            continue
        v, head, tail = vnew[sel], heads[sel], tails[sel]
        if target is not None:
            goal = target[sel]
        elif s.periods is not None:
            # the torus: the new vertex already sits at the wrapped edge's
            # midpoint (tail + half the edge vector), not at the chord's
            goal = s.X[v].copy()
        else:
            goal = 0.5 * (s.X[tail] + s.X[head])
        names = tuple(f"p{k + 1}" for k in range(b.nparams))

        def curve(P):
            env = {nm: P[:, k] for k, nm in enumerate(names)}
            X = np.stack([f.values(env0, env, len(P)) for f in b.coords[:3]], axis=1)
            J = np.stack([f.gradient(env0, env, len(P), names) for f in b.coords[:3]], axis=1)
            return X, J

        P = s.vattr["params"][head][:, :b.nparams].copy()
        X, J = curve(P)
        r = X - goal
        for _ in range(5):
            JtJ = np.einsum("nik,nil->nkl", J, J)
            Jtr = np.einsum("nik,ni->nk", J, r)
            with np.errstate(all="ignore"):
                dp = -np.linalg.solve(JtJ, Jtr[..., None])[..., 0]
            dp = np.where(np.isfinite(dp), dp, 0.0)
            lam = np.ones(len(P))
            cur = np.einsum("ni,ni->n", r, r)
            for _ in range(10):   # damping: halve until the distance drops (REF takes
                # a step that changes it by round-off: knotty.fe r; r vertex 32)
                Pn = P + lam[:, None] * dp
                Xn, Jn = curve(Pn)
                rn = Xn - goal
                worse = np.einsum("ni,ni->n", rn, rn) > cur * (1 + 1e-12) + 1e-300
                if not worse.any():
                    break
                lam = np.where(worse, lam * 0.5, lam)
            P, X, J, r = Pn, Xn, Jn, rn
        s.vattr["params"][v, :b.nparams] = P
        s.X[v] = X


def refine(s):
    """Return the refined copy of surface ``s`` (spec §8.1).

    Parameters
    ----------
    s : Surface

    Returns
    -------
    Surface
        ``V' = V + E``, ``E' = 2E + 3F``, ``F' = 4F`` when no element has
        NO_REFINE.
    """
    return split_edges(s, ~s.eattr["no_refine"])


def split_edges(s, ref, one_by_one=False, order=None, choosers=None):
    """Bisect the edges where ``ref`` (a (ne,) bool mask) is true and split
    every facet across its bisected sides (4, 3 or 2 triangles).

    A facet with one bisected side is cut from the midpoint to the opposite
    corner; with two, the corner between them is cut off first and the rest
    is cut from the first midpoint to the opposite corner (what bisecting
    the two sides one after the other gives).

    ``one_by_one`` (``refine edges``, ``l``; no facet may have two bisected
    sides): elements numbered and facets laid out as REF's edge division
    does one edge after the other (measured with ``list edges`` and
    ``ff.vertex[k]`` after ``refine edge where id == 1 or id == 3`` on
    cube.fe): per edge in id order its head half, then for each facet in the
    edge's facet loop the cut from the midpoint to the opposite corner and a
    new facet; the new facet is the triangle on the tail half and starts
    with it, the old facet keeps the head half's triangle and starts with
    the cut.  (The order of the corners decides ``ff.vertex[1]``, hence
    e.g. ``form_factors`` set from it in mylarcube.fe.)

    ``order`` (the chosen edges' indices) numbers the new elements in that
    order instead of by edge id (``K``: the order of the facets that chose
    them).  ``choosers`` (``K``, with ``order``: per edge the facet that
    chose it) is only passed on: :func:`pyevolver.remesh.edge_divide.edge_divide`
    moves the midpoints afterwards.
    """
    nv, ne, nf = s.nv, s.ne, s.nf
    ref = np.asarray(ref, bool)
    if order is None and not one_by_one and ne and ref.all() and "wrap" not in s.eattr \
            and group_of(s) is None and s.FE.shape[1] == 3:
        return _split_every_edge(s)
    R = np.nonzero(ref)[0] if order is None else np.asarray(order, np.int64)
    k = len(R)
    mid = np.full(ne, -1, np.int64)
    mid[R] = nv + np.arange(k)
    half = np.full(ne, -1, np.int64)
    half[R] = ne + np.arange(k)

    idx, sgn, _ = s.topology()                     # (nf, 3)
    fwd = sgn > 0
    rs = ref[idx]
    nref = rs.sum(axis=1)
    # rotate each facet so that the sides to refine come first:
    # 1 refined side -> it is side 0; 2 -> the unrefined one is side 2
    rot = np.zeros(nf, np.int64)
    one = nref == 1
    rot[one] = np.argmax(rs[one], axis=1)
    two = nref == 2
    rot[two] = (np.argmin(rs[two], axis=1) + 1) % 3
    if one_by_one and np.any(nref > 1):
        raise ValueError("split_edges(one_by_one=True): a facet with two bisected sides")
    perm = None
    f1 = np.nonzero(one)[0]
    if one_by_one and len(f1):
        # REF's order: per edge (id order), its facets in the edge's loop
        e_of = idx[f1, rot[f1]]
        fw_of = fwd[f1, rot[f1]]
        rank = np.zeros(ne, np.int64)
        rank[R] = np.arange(k)
        pos = np.where(fw_of == along_first(s)[e_of], 0, 1)
        order = np.lexsort((f1, pos, rank[e_of]))
        f1 = f1[order]
        r_of = rank[e_of[order]]
        cnt = np.bincount(r_of, minlength=k)
        start = np.cumsum(1 + cnt) - (1 + cnt)        # each edge's head half
        q = np.arange(len(f1)) - np.searchsorted(r_of, r_of)   # place in its loop
        cut = start[r_of] + 1 + q
        perm = np.empty(k + len(f1), np.int64)
        perm[start] = np.arange(k)
        perm[cut] = k + np.arange(len(f1))
        half[R] = ne + start
    cols = (np.arange(3)[None, :] + rot[:, None]) % 3
    I = np.take_along_axis(idx, cols, 1)
    FW = np.take_along_axis(fwd, cols, 1)
    S = np.take_along_axis(s.FE, cols, 1)
    RS = np.take_along_axis(rs, cols, 1)
    Mv = np.where(RS, mid[I], -1)                  # midpoint vertex of each side
    first = np.where(FW, I, ~np.where(RS, half[I], 0))     # corner j -> M_j
    second = np.where(FW, np.where(RS, half[I], 0), ~I)    # M_j -> corner j+1

    # interior edges and facets, case by case
    f3 = np.nonzero(nref == 3)[0]
    f2 = np.nonzero(two)[0]
    if perm is None:
        f1 = np.nonzero(one)[0]
    e_par = np.concatenate([np.repeat(f3, 3), np.repeat(f2, 2), f1])
    ne2 = ne + k
    base3 = ne2 + 3 * np.arange(len(f3))
    base2 = ne2 + 3 * len(f3) + 2 * np.arange(len(f2))
    base1 = ne2 + 3 * len(f3) + 2 * len(f2) + np.arange(len(f1))
    f_par = np.concatenate([np.repeat(f3, 3), np.repeat(f2, 2), f1])
    fb3 = nf + 3 * np.arange(len(f3))
    fb2 = nf + 3 * len(f3) + 2 * np.arange(len(f2))
    fb1 = nf + 3 * len(f3) + 2 * len(f2) + np.arange(len(f1))

    t = grow(s, v_from_edge=R, e_from_edge=R, e_from_facet=e_par, f_from_facet=f_par)
    if perm is not None:
        reorder_new_edges(t, ne, perm)
        base1 = ne + cut

    # -- geometry of midpoints (torus: in the tail's cell)
    wv = s.wrap_shift()
    group = group_of(s)
    ev = G.edge_vectors(s.X, s.E, wv) if group is None else GR.edge_vectors(s, group)
    frac = 0.5 if s.metric is None else MT.split_fractions(s, R)[:, None]
    t.X[nv:nv + k] = s.X[s.E[R, 0]] + frac * ev[R]      # a metric's split: methods.metric
    # -- edge halves
    t.E[R, 1] = mid[R]
    t.E[half[R], 0] = mid[R]
    t.E[half[R], 1] = s.E[R, 1]
    if "wrap" in t.eattr:
        t.eattr["wrap"][R] = 0.0          # tail half stays in the tail's cell
        # (the head half copied the whole wrap from its parent)

    E = t.E
    FE = t.FE
    new_edges = []       # (index array, from-vertex, to-vertex, facets, kind)

    # case 3, numbered as the Evolver does: interior edges b0: M0->M2,
    # b1: M1->M0, b2: M2->M1; the facet keeps its id for the middle triangle
    # (~b2, ~b0, ~b1) and its three new ids go to the corner triangles at
    # corners 0, 1, 2 (checked with `list facet` / `list edge` after r on
    # cube.fe)
    if len(f3):
        b0, b1, b2 = base3, base3 + 1, base3 + 2
        m0, m1, m2 = Mv[f3, 0], Mv[f3, 1], Mv[f3, 2]
        E[b0] = np.stack([m0, m2], 1)
        E[b1] = np.stack([m1, m0], 1)
        E[b2] = np.stack([m2, m1], 1)
        fi, se = first[f3], second[f3]
        FE[f3] = np.stack([~b2, ~b0, ~b1], 1)
        FE[fb3] = np.stack([fi[:, 0], b0, se[:, 2]], 1)
        FE[fb3 + 1] = np.stack([se[:, 0], fi[:, 1], b1], 1)
        FE[fb3 + 2] = np.stack([b2, se[:, 1], fi[:, 2]], 1)
        new_edges += [(b0, f3, ("m", 0), ("m", 2)), (b1, f3, ("m", 1), ("m", 0)),
                      (b2, f3, ("m", 2), ("m", 1))]
    # case 2 (sides 0, 1 refined): a: M0->M1 cuts corner 1, d: M0->c2
    if len(f2):
        a, d = base2, base2 + 1
        m0, m1 = Mv[f2, 0], Mv[f2, 1]
        c2 = np.where(FW[f2, 2], s.E[I[f2, 2], 0], s.E[I[f2, 2], 1])
        E[a] = np.stack([m0, m1], 1)
        E[d] = np.stack([m0, c2], 1)
        fi, se = first[f2], second[f2]
        FE[f2] = np.stack([fi[:, 0], d, S[f2, 2]], 1)
        FE[fb2] = np.stack([se[:, 0], fi[:, 1], ~a], 1)
        FE[fb2 + 1] = np.stack([a, se[:, 1], ~d], 1)
        new_edges += [(a, f2, ("m", 0), ("m", 1)), (d, f2, ("m", 0), ("c", 2))]
    # case 1 (side 0 refined): d: M0->c2
    if len(f1):
        d = base1
        m0 = Mv[f1, 0]
        c2 = np.where(FW[f1, 2], s.E[I[f1, 2], 0], s.E[I[f1, 2], 1])
        E[d] = np.stack([m0, c2], 1)
        fi, se = first[f1], second[f1]
        if perm is None:
            FE[f1] = np.stack([fi[:, 0], d, S[f1, 2]], 1)
            FE[fb1] = np.stack([se[:, 0], S[f1, 1], ~d], 1)
        else:
            # REF: the new facet is the tail half's triangle, starting with
            # it; the old one keeps the head half's, starting with the cut
            fw = FW[f1, 0][:, None]
            tail_tri = np.where(fw, np.stack([fi[:, 0], d, S[f1, 2]], 1),
                                np.stack([se[:, 0], S[f1, 1], ~d], 1))
            head_tri = np.where(fw, np.stack([~d, se[:, 0], S[f1, 1]], 1),
                                np.stack([d, S[f1, 2], fi[:, 0]], 1))
            FE[fb1] = tail_tri
            FE[f1] = head_tri
        new_edges += [(d, f1, ("m", 0), ("c", 2))]

    if "wrap" in t.eattr and new_edges:
        W = s.eattr["wrap"]
        # period offsets (in cells) of corners and midpoints in the facet's own lift
        off = np.zeros((nf, 3, W.shape[1]))
        sw = W[I] * np.where(FW, 1.0, -1.0)[..., None]
        off[:, 1] = sw[:, 0]
        off[:, 2] = sw[:, 0] + sw[:, 1]
        offc = off
        offm = np.where(FW[..., None], off, np.roll(off, -1, axis=1))

        def offset(kind, j, f):
            return (offc if kind == "c" else offm)[f, j]
        for eidx, f, p, q in new_edges:
            t.eattr["wrap"][eidx] = offset(q[0], q[1], f) - offset(p[0], p[1], f)

    if group is not None:                   # a symmetry group's codes (remesh.group_refine)
        GR.new_edge_codes(s, t, group, R, I, FW, new_edges)
    # the records compare the arrays they were made with to the surface's:
    # t's own (a finished surface's E and FE are never written in place:
    # operations make new arrays), not copies, 16 MB fewer at 327,680 facets
    copies = (t.FE, t.E)
    _split_rings(s, t, R, half, None if perm is None else np.sort(base1), copies[1])
    _split_loops(s, t, R, half, copies)
    new_v = np.arange(nv, nv + k)
    boundary_midpoints(t, s.E[R, 0], s.E[R, 1], new_v)
    sel = new_v[constrained_vertices(t)[new_v]]
    if len(sel):
        project_to_constraints(t, sel)
    return t


def _split_every_edge(s):
    """:func:`split_edges` with every edge bisected (``r``) on a surface
    without torus wraps or a symmetry group: the same surface, numbered
    the same way, made with slices (every facet is split into 4, so the
    new elements of facet ``f`` are rows ``3f .. 3f + 2`` of the appended
    blocks); it also keeps the new surface's topology (facet corners),
    which the evaluation after ``r`` reads, made from the old corners
    without gathering the new edges' ends."""
    nv, ne, nf = s.nv, s.ne, s.nf
    R = np.arange(ne)
    par = np.repeat(np.arange(nf), 3)
    # (the bodies made here when there are any: no sort of the facet matrix)
    t = grow(s, v_from_edge=R, e_from_edge=R, e_from_facet=par, f_from_facet=par,
             bodies=_split_bodies(s.bodies, nf))
    del par
    # -- midpoints and edge halves: edge e keeps its tail half, its head half
    # is edge ne + e, its midpoint vertex nv + e
    frac = 0.5 if s.metric is None else MT.split_fractions(s, R)[:, None]
    t.X[nv:] = s.X[s.E[:, 0]] + frac * G.edge_vectors(s.X, s.E)
    E, FE = t.E, t.FE
    E[:ne, 1] = nv + R
    E[ne:2 * ne, 0] = nv + R
    E[ne:2 * ne, 1] = s.E[:, 1]
    # -- the facets (as split_edges' case 3): side j of facet f runs from
    # corner j (C) through its midpoint M_j; inner edges b_j = 2ne + 3f + j,
    # b0: M0->M2, b1: M1->M0, b2: M2->M1
    idx, sgn, C = s.topology()
    fw = sgn > 0
    M = idx + nv
    H = idx + ne
    first = np.where(fw, idx, ~H)                  # corner j -> M_j
    second = np.where(fw, H, ~idx)                 # M_j -> corner j + 1
    del H, fw
    b = (2 * ne + 3 * np.arange(nf))[:, None] + np.arange(3)
    E3 = E[2 * ne:].reshape(nf, 3, 2)
    E3[:, :, 0] = M
    E3[:, :, 1] = M[:, [2, 0, 1]]
    FE[:nf] = ~b[:, [2, 0, 1]]                     # the middle triangle keeps the id
    F9 = FE[nf:].reshape(nf, 9)                    # corner triangles 0, 1, 2
    F9[:, [0, 4, 8]] = first
    F9[:, [2, 3, 7]] = second[:, [2, 0, 1]]
    F9[:, [1, 5, 6]] = b
    del first, second, b
    # the corners of the new facets (Surface.topology's third array)
    tails = np.empty((4 * nf, 3), np.int64)
    tails[:nf] = M[:, [1, 2, 0]]
    T9 = tails[nf:].reshape(nf, 9)
    T9[:, [0, 4, 8]] = C
    T9[:, [1, 2, 3, 5, 6, 7]] = M[:, [0, 2, 0, 1, 2, 1]]
    del M
    t._topo = (FE, E, G.edge_index(FE) + (tails,))
    copies = (FE, E)            # (t's own arrays: see split_edges)
    half = ne + R
    _split_rings(s, t, R, half, None, E)
    _split_loops(s, t, R, half, copies)
    new_v = nv + R
    boundary_midpoints(t, s.E[:, 0], s.E[:, 1], new_v)
    sel = new_v[constrained_vertices(t)[new_v]]
    if len(sel):
        project_to_constraints(t, sel)
    return t


def _split_bodies(b, nf):
    """The bodies of the surface :func:`_split_every_edge` makes, as
    :func:`pyevolver.remesh.grow.grow` makes them (every facet's three new
    children, facets ``nf + 3f + j``, in its bodies with its sign), built
    row by row from the canonical facet matrix (None when the matrix is
    not canonical: grow's way then)."""
    M = b.facet_csr
    if not b.n or M is None or getattr(M, "format", None) != "csr" or b.occurrences is None:
        return None
    data, ind, ptr = np.asarray(M.data), np.asarray(M.indices), np.asarray(M.indptr)
    nrow, ncol = int(M.shape[0]), int(M.shape[1])
    if ncol != nf or data.dtype.kind not in "f":
        return None
    cnt = np.diff(ptr).astype(np.int64)
    rows = np.repeat(np.arange(nrow), cnt)
    c = ind.astype(np.int64)
    if len(c) > 1 and not np.all((c[1:] > c[:-1]) | (rows[1:] != rows[:-1])):
        return None                     # (unsorted or repeated columns in a row)
    start = ptr[:-1].astype(np.int64)
    off = np.arange(len(c)) - start[rows]          # place in its row
    n = len(c)
    base = 4 * start[rows] + cnt[rows]             # the row's children after its facets
    new_c = np.empty(4 * n, np.int64)
    new_d = np.empty(4 * n, data.dtype)
    keep = np.arange(n) + 3 * start[rows]
    new_c[keep] = c
    new_d[keep] = data
    for j in range(3):
        at = base + 3 * off + j
        new_c[at] = nf + 3 * c + j
        new_d[at] = data
    idx = np.int32 if max(nrow, 4 * ncol, 4 * n) <= np.iinfo(np.int32).max else np.int64
    indptr = np.zeros(nrow + 1, idx)
    np.cumsum(4 * cnt, out=indptr[1:])
    out = copy.copy(b)
    out.facet_matrix = PendingCSR(new_d, new_c.astype(idx), indptr, (nrow, 4 * ncol))
    ob, of, osg = b.occurrences
    out.occurrences = (np.concatenate([ob, np.repeat(ob, 3)]),
                       np.concatenate([of, nf + 3 * np.repeat(of, 3) + np.tile(np.arange(3),
                                                                           len(of))]),
                       np.concatenate([osg, np.repeat(osg, 3)]))
    out.volume = None
    return out


def _split_loops(s, t, R, half, copies=None):
    """Record which edges of ``t`` have the facet along them first in their
    facet loop (:func:`pyevolver.model.records.along_first`): the tail half of a split edge
    keeps its edge's order, the head half has the other one, the edges
    cutting the facets have the facet along them first (measured with
    ``ee.facet`` after ``r`` on catbody.fe; it decides how ``u`` renumbers)."""
    ne, R, half = t.ne, R.copy(), half.copy()

    def later():                        # (when first read: along_first)
        out = np.ones(ne, bool)
        old = along_first(s)
        out[:s.ne] = old
        out[half[R]] = ~old[R]
        return out
    settle_records(s)
    record_along_first(t, later, copies)


def _split_rings(s, t, R, half, inner=None, E=None):
    """Record REF's edge rings (:mod:`pyevolver.remesh.rings`) at the vertices
    of ``t``: ``s`` with the edges ``R`` split (new head halves ``half[R]``)
    and its facets cut.

    Measured on catbody.fe and column.fe (``vv.edge`` after ``r``): the
    edges are split in order, each one's old head end leaving the ring of
    its head vertex and the new half joining it; a midpoint's ring is the
    new half (first), then the old edge; then the edges cutting the facets
    join the rings at both their ends, in id order.

    The rings are computed when first read (:func:`record_vertex_rings`),
    from ``s`` (kept until then) and copies of the arrays used here.
    """
    settle_records(s)                     # (no chain of surfaces kept for later)
    E = t.E.copy() if E is None else E
    R, half, nv = R.copy(), half.copy(), t.nv
    record_vertex_rings(t, lambda: _rings_after_split(s, E, nv, R, half, inner), E)


def _rings_after_split(s, E, nv, R, half, inner):
    """The rank of :func:`_split_rings` (``E``, ``nv``: the new surface's)."""
    ne, k = s.ne, len(R)
    g = Rings(s, len(E), nv)
    h_all = s.E[R, 1]
    for sel in rounds(h_all, R):
        g.remove(h_all[sel], 2 * R[sel] + 1)
        g.insert(h_all[sel], 2 * half[R[sel]] + 1)
    g.set_pair(E[R, 1], 2 * half[R], 2 * R + 1)
    if inner is None:
        inner = np.arange(ne + k, len(E))
    iv = E[inner].ravel()
    islot = 2 * np.repeat(inner, 2) + np.tile([0, 1], len(inner))
    for sel in rounds(iv, islot):
        g.insert(iv[sel], islot[sel])
    return g.rank()
