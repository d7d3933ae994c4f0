"""Mesh operations of the string model (surface dimension 1): ``r`` splits
edges (:func:`split_edges`), ``V`` averages vertices (:func:`vertex_average`),
keeping REF's edge rings (:mod:`pyevolver.model.string`)."""
from __future__ import annotations

import copy

import numpy as np

from ..methods import metric as MT
from ..constraints import constrained_vertices, project_tangent, project_to_constraints
from ..geometry.kernels import edge_vectors
from .grow import grow
from .refine import boundary_midpoints


def _ring_split(s, t, R, mid, half):
    """Update the rings for edges ``R`` split at new vertices ``mid`` with
    new head halves ``half`` (REF's order after ``r``, measured on
    popstr.fe): edges are processed in order; the new vertex gets the new
    half first, then the old edge; at the old head vertex the old edge
    leaves its ring and the new half joins it."""
    times = t.eattr["ring_time"]
    head = t.vattr["ring_head"]
    clock = int(times.max()) + 1 if len(times) else 0
    # the edges as they are while the splits are done one after the other
    E = np.vstack([s.E, np.full((len(R), 2), -1, np.int64)])
    for e, m, n in zip(R.tolist(), mid.tolist(), half.tolist()):
        h = int(E[e, 1])
        E[e, 1] = m
        head[m] = n
        times[n, 0] = clock
        times[e, 1] = clock + 1
        if head[h] == e:
            # the next in the ring: the newest of the others
            at = np.nonzero((E == h).any(axis=1))[0]
            if len(at):
                tt = np.where(E[at, 0] == h, times[at, 0], times[at, 1])
                head[h] = at[np.argmax(tt)]
            else:
                head[h] = n
        E[n] = (m, h)
        times[n, 1] = clock + 2
        clock += 3


# ---------------------------------------------------------------------------
# mesh operations


def split_edges(s, R):
    """Bisect the edges ``R`` (indices): midpoint vertices numbered in edge
    order, the original edge keeps its tail half and the head halves are new
    edges in the same order; each facet chain gets the new half next to its
    parent (REF's numbering, ``list facets`` after ``r``)."""
    R = np.asarray(R, np.int64)
    k = len(R)
    t = grow(s, v_from_edge=R, e_from_edge=R)
    nv, ne = s.nv, s.ne
    mid = nv + np.arange(k)
    half = ne + np.arange(k)
    if s.metric is not None:              # REF's split in a metric: methods.metric
        t.X[mid] = s.X[s.E[R, 0]] + MT.split_fractions(s, R)[:, None] * (
            s.X[s.E[R, 1]] - s.X[s.E[R, 0]])
    elif s.periods is None:
        t.X[mid] = 0.5 * (s.X[s.E[R, 0]] + s.X[s.E[R, 1]])
    else:       # the mean of the tail and the head as seen from the tail (REF's rounding)
        t.X[mid] = 0.5 * (s.X[s.E[R, 0]] + (s.X[s.E[R, 1]] + s.wrap_shift()[R]))
    if "wrap" in t.eattr:
        t.eattr["wrap"][R] = 0.0          # the tail half stays in the tail's cell
    t.E[half, 0] = mid
    t.E[half, 1] = s.E[R, 1]
    t.E[R, 1] = mid
    if "ring_time" in s.eattr:
        t.eattr["ring_time"] = t.eattr["ring_time"].copy()
        t.vattr["ring_head"] = t.vattr["ring_head"].copy()
        _ring_split(s, t, R, mid, half)
    # facet chains: e -> e, h ; ~e -> ~h, ~e
    newh = np.full(ne, -1, np.int64)
    newh[R] = half
    enc = s.sf_enc
    fwd = enc >= 0
    e = np.where(fwd, enc, ~enc)
    split = newh[e] >= 0
    reps = np.where(split, 2, 1)
    out = np.empty(int(reps.sum()), np.int64)
    pos = np.cumsum(reps) - reps
    out[pos] = np.where(split & ~fwd, ~newh[e], enc)
    sp = np.nonzero(split)[0]
    out[pos[sp] + 1] = np.where(fwd[sp], newh[e[sp]], enc[sp])
    owner = np.repeat(np.arange(len(s.sf_ptr) - 1), np.diff(s.sf_ptr))
    t.sf_enc = out
    t.sf_ptr = np.concatenate([[0], np.cumsum(np.bincount(owner, weights=reps,
                                                           minlength=len(s.sf_ptr) - 1))]
                              ).astype(np.int64)
    # on a parametric boundary: the curve point nearest the chord's midpoint
    # (as in the soapfilm model; knotty.fe after r)
    boundary_midpoints(t, s.E[R, 0], s.E[R, 1], mid)
    sel = mid[constrained_vertices(t)[mid]]
    if len(sel):
        project_to_constraints(t, sel)
    return t


def vertex_average(s, mode="V"):
    """``V`` / ``rawv`` / ``rawestv`` on a string (measured on REF): a vertex
    with two or more usable edges moves by a quarter of the mean of its
    neighbours minus itself, ``D = Σ_e (x_e - x_v) / n``, ``x += D/4``;
    ``V`` moves only vertices with exactly two edges and keeps only the
    component of D along the chord between the two neighbours (the tangent:
    the area is kept to first order).  Vertices that are FIXED, on a
    boundary or at the end of a string do not move; for ``V`` and ``rawv`` a
    vertex on constraints uses only edges on the same constraints (as in
    the soapfilm model) and is projected back."""
    nv, ne = s.nv, s.ne
    v = np.concatenate([s.E[:, 0], s.E[:, 1]])
    other = np.concatenate([s.E[:, 1], s.E[:, 0]])
    use = np.ones(2 * ne, bool)
    if mode != "rawest" and s.vcon:
        e = np.concatenate([np.arange(ne), np.arange(ne)])
        for c, on_v in s.vcon.items():
            on_e = s.econ.get(c)
            on_e = np.zeros(ne, bool) if on_e is None else (on_e != 0)
            use &= ~on_v[v] | on_e[e]
    deg = np.bincount(v, minlength=nv)
    cnt = np.bincount(v, weights=use.astype(float), minlength=nv)
    ev = edge_vectors(s.X, s.E, s.wrap_shift())
    vec = np.concatenate([ev, -ev])
    D = np.zeros((nv, 3))
    for k in range(3):
        D[:, k] = np.bincount(v, weights=np.where(use, vec[:, k], 0.0), minlength=nv)
    movable = ~s.vattr["fixed"] & (cnt >= 2)
    if mode == "V":
        movable &= (cnt == 2) & (deg == 2)
    bnd = s.vattr.get("boundary")
    if bnd is not None:
        movable &= bnd == 0
    D[~movable] = 0.0
    D[movable] /= cnt[movable, None]
    if mode == "V":
        mv = np.nonzero(movable)[0]
        # the chord between the two neighbours, as seen from the vertex
        # (torus wraps included)
        order = np.argsort(v, kind="stable")
        first = np.searchsorted(v[order], mv)
        ch = vec[order[first + 1]] - vec[order[first]]
        n2 = np.einsum("ij,ij->i", ch, ch)
        with np.errstate(all="ignore"):
            tang = np.where(n2[:, None] > 0, ch * (np.einsum("ij,ij->i", D[mv], ch) / n2)[:, None],
                            0.0)
        D[mv] = tang
        (D,) = project_tangent(s, [D])
    new = copy.copy(s)
    new.X = s.X + D / 4.0
    if new.vcon:
        project_to_constraints(new, np.nonzero(movable)[0])
    return new
