"""Append elements to a surface with the Evolver's inheritance rules.

Every topology-changing operation (``r``, ``refine edges``, ``notch``, ...)
builds a *new* :class:`~pyevolver.model.surface.Surface` with :func:`grow` and
then fills in the coordinates and connectivity of the new elements.  The old
surface object is left untouched, so a failing command can hand the session
back its previous surface (spec §6.2 for the inheritance).
"""
from __future__ import annotations

import copy

import numpy as np

from ..errors import CommandError
from .. import limits
from ..model.facet_csr import with_copied_columns


def _zeros_like_rows(arr, n):
    return np.zeros((n,) + arr.shape[1:], dtype=arr.dtype)


def _append_rows(arr, rows):
    return np.concatenate([arr, rows]) if len(rows) else arr.copy()


def remap_quantities(s, t, remap):
    """Quantities of ``s`` carried over to the new surface ``t``: global
    methods cover all of t's elements, the others' member lists go through
    ``remap(etype, idx, sgn) -> (idx, sgn)``."""
    sizes = {"vertex": t.nv, "edge": t.ne, "facet": t.nf}
    out = {}
    for name, q in s.quantities.items():
        q2 = copy.copy(q)
        q2.methods = []
        for (m, etype, idx, sgn) in q.methods:
            if sgn is None:
                q2.methods.append((m, etype, np.arange(sizes[etype]), None))
            else:
                q2.methods.append((m, etype) + tuple(remap(etype, idx, sgn)))
        out[name] = q2
    return out


def _new_ids(ids, n):
    """Ids for ``n`` new elements after the existing ``ids``."""
    top = int(ids.max()) if len(ids) else 0
    return np.arange(top + 1, top + 1 + n)


def grow(s, v_from_edge=(), v_from_facet=(), e_from_edge=(), e_from_facet=(),
         f_from_facet=(), bodies=None):
    """A copy of ``s`` with new vertices, edges and facets appended.

    Parameters
    ----------
    s : Surface
    v_from_edge, v_from_facet : (k,) int arrays
        Parents of the new vertices (new vertices are appended in this
        order: edge-born first, then facet-born).
    e_from_edge, e_from_facet : (k,) int arrays
        Parents of the new edges (same ordering rule).
    f_from_facet : (k,) int array
        Parents of the new facets.
    bodies : Bodies, optional
        The new surface's bodies when the caller has made them (``r``:
        :func:`pyevolver.remesh.refine._split_bodies`); by default every
        occurrence of a parent facet gains one of each of its children.

    Returns
    -------
    Surface
        New surface.  Coordinates of new vertices are zero, connectivity rows
        of new edges/facets are zero: the caller fills them in.  Attributes,
        constraints, boundaries, quantity memberships and body memberships
        are inherited (spec §6.2): a vertex or edge born inside a facet takes
        the facet's FIXED, NO_REFINE, constraints and boundary; a vertex born
        on an edge takes the edge's FIXED, constraints and boundary; a new
        edge or facet born from one of its own kind copies everything.
    """
    ve = np.asarray(v_from_edge, np.int64)
    vf = np.asarray(v_from_facet, np.int64)
    ee = np.asarray(e_from_edge, np.int64)
    ef = np.asarray(e_from_facet, np.int64)
    ff = np.asarray(f_from_facet, np.int64)
    nv_new, ne_new, nf_new = len(ve) + len(vf), len(ee) + len(ef), len(ff)
    if max(s.nv + nv_new, s.ne + ne_new, s.nf + nf_new) > limits.MAX_ELEMENTS:
        raise CommandError(f"the surface would grow to {s.nv + nv_new} vertices, "
                           f"{s.ne + ne_new} edges and {s.nf + nf_new} facets, beyond the "
                           f"{limits.MAX_ELEMENTS} elements of each kind allowed; the surface is "
                           f"unchanged")
    t = copy.copy(s)
    for name in ("_lift_cache", "_topo"):
        t.__dict__.pop(name, None)
    t.X = _append_rows(s.X, np.zeros((nv_new, s.X.shape[1])))
    t.E = _append_rows(s.E, np.zeros((ne_new, 2), np.int64))
    t.FE = _append_rows(s.FE, np.zeros((nf_new, 3), np.int64))
    efixed = s.eattr["fixed"]
    ffixed = s.fattr["fixed"]

    # -- vertices
    vattr = dict(s.vattr)
    if "boundary" not in vattr and ("boundary" in s.eattr or "boundary" in s.fattr):
        npar = max((b.nparams for b in s.boundaries.values()), default=1)
        vattr["boundary"] = np.zeros(s.nv, np.int64)
        vattr["params"] = np.zeros((s.nv, npar))
    va = {}
    for key, arr in vattr.items():
        rows = _zeros_like_rows(arr, nv_new)
        if key == "fixed":
            rows[:len(ve)] = efixed[ve]
            rows[len(ve):] = ffixed[vf]
        elif key == "boundary":
            rows[:len(ve)] = s.eattr["boundary"][ve] if "boundary" in s.eattr else 0
            rows[len(ve):] = s.fattr["boundary"][vf] if "boundary" in s.fattr else 0
        elif key == "id":
            rows[:] = _new_ids(arr, nv_new)
        va[key] = _append_rows(arr, rows)
    t.vattr = va
    def inherited(cid):
        # new vertices are on a constraint when the edge or facet they come from is
        return np.concatenate([
            s.econ[cid][ve] != 0 if cid in s.econ else np.zeros(len(ve), bool),
            s.fcon[cid][vf] if cid in s.fcon else np.zeros(len(vf), bool)])
    t.vcon = {}
    for cid, on in s.vcon.items():
        if "global" in s.constraints[cid].flags:
            add = np.ones(nv_new, bool)
        else:
            add = inherited(cid)
        t.vcon[cid] = _append_rows(on, add)
    for cid in set(s.econ) | set(s.fcon):
        if cid not in t.vcon:
            add = inherited(cid)
            if add.any():
                t.vcon[cid] = np.concatenate([np.zeros(s.nv, bool), add])

    # -- edges
    ea = {}
    for key, arr in s.eattr.items():
        rows = _zeros_like_rows(arr, ne_new)
        rows[:len(ee)] = arr[ee]
        if key == "fixed":
            rows[len(ee):] = ffixed[ef]
        elif key == "no_refine":
            rows[len(ee):] = s.fattr["no_refine"][ef]
        elif key == "boundary" and "boundary" in s.fattr:
            rows[len(ee):] = s.fattr["boundary"][ef]
        elif key == "original":
            rows[len(ee):] = 0          # edge halves keep their parent's, as REF's `list`
        elif key == "id":
            rows[:] = _new_ids(arr, ne_new)
        ea[key] = _append_rows(arr, rows)
    t.eattr = ea
    t.econ = {}
    for cid, sign in s.econ.items():
        if "global" in s.constraints[cid].flags:
            add = np.ones(ne_new, np.int8)
        else:
            add = np.concatenate([
                sign[ee],
                s.fcon[cid][ef].astype(np.int8) if cid in s.fcon else np.zeros(len(ef), np.int8)])
        t.econ[cid] = _append_rows(sign, add)
    for cid, on in s.fcon.items():
        if cid not in t.econ and on[ef].any():
            t.econ[cid] = np.concatenate([np.zeros(len(ee) + s.ne, np.int8),
                                          on[ef].astype(np.int8)])

    # -- facets
    fa = {}
    for key, arr in s.fattr.items():
        rows = arr[ff].copy()           # "original" too: REF lists `original 1` for them
        if key == "id":
            rows[:] = _new_ids(arr, nf_new)
        fa[key] = _append_rows(arr, rows)
    t.fattr = fa
    t.fcon = {cid: _append_rows(on, on[ff]) for cid, on in s.fcon.items()}

    # -- extra attributes
    extra = {}
    for (etype, name), arr in s.extra.items():
        if etype == "vertex":
            extra[(etype, name)] = _append_rows(arr, _zeros_like_rows(arr, nv_new))
        elif etype == "edge":
            rows = _zeros_like_rows(arr, ne_new)
            rows[:len(ee)] = arr[ee]
            extra[(etype, name)] = _append_rows(arr, rows)
        elif etype == "facet":
            extra[(etype, name)] = _append_rows(arr, arr[ff])
        else:
            extra[(etype, name)] = arr.copy()
    t.extra = extra

    # -- bodies
    b = copy.copy(s.bodies) if bodies is None else bodies
    if b.n and bodies is None:
        # (as CSR arrays: no scipy.sparse import for a refinement, facet_csr)
        b.facet_matrix = with_copied_columns(s.bodies.facet_csr, ff)
        ob, of, osg = s.bodies.occurrences
        if nf_new:
            # every occurrence of a parent facet gains one of each child
            order = np.argsort(ff, kind="stable")
            fs = ff[order]
            lo = np.searchsorted(fs, of, "left")
            hi = np.searchsorted(fs, of, "right")
            cnt = hi - lo
            rep = np.repeat(np.arange(len(of)), cnt)
            # the ranges lo[i]:hi[i] one after the other (without a loop)
            kid = order[np.repeat(lo, cnt) + np.arange(len(rep))
                        - np.repeat(np.cumsum(cnt) - cnt, cnt)] \
                if len(rep) else np.zeros(0, np.int64)
            b.occurrences = (np.concatenate([ob, ob[rep]]),
                             np.concatenate([of, s.nf + kid]),
                             np.concatenate([osg, osg[rep]]))
        b.volume = None
    t.bodies = b

    # -- quantities
    parents = {"edge": (ee, s.ne), "facet": (ff, s.nf)}

    def add_children(etype, idx, sgn):
        # every member element's children become members with its sign
        if etype not in parents or not len(parents[etype][0]):
            return idx, sgn
        par, base = parents[etype]
        where = np.full(base, -1, np.int64)
        where[idx] = np.arange(len(idx))
        hit = where[par]
        kids = np.nonzero(hit >= 0)[0]
        return np.concatenate([idx, base + kids]), np.concatenate([sgn, sgn[hit[kids]]])
    t.quantities = remap_quantities(s, t, add_children)
    t.topology_version = getattr(s, "topology_version", 0) + 1
    return t


def reorder_new_edges(t, start, perm):
    """Reorder, in place, the edges that :func:`grow` appended to ``t`` from
    index ``start`` on: new edge ``start + j`` becomes the one grow put at
    ``start + perm[j]`` (grow appends edge-born edges before facet-born ones;
    an operation numbering them interleaved, as the Evolver does, permutes
    them before filling in the connectivity).  Ids stay in index order."""
    perm = np.asarray(perm, np.int64)
    idx = np.concatenate([np.arange(start), start + perm])
    inv = np.argsort(idx)
    t.E = t.E[idx]
    t.eattr = {k: (a if k == "id" else a[idx]) for k, a in t.eattr.items()}
    t.econ = {c: a[idx] for c, a in t.econ.items()}
    t.extra = {(et, n): (a[idx] if et == "edge" else a) for (et, n), a in t.extra.items()}

    def move(etype, i, sgn):
        return (inv[i], sgn) if etype == "edge" else (i, sgn)
    t.quantities = remap_quantities(t, t, move)
