"""``addload``: the elements of another surface appended to a surface.

The new elements are numbered after the existing ones.  Declarations of the
new datafile (parameters, constraints, boundaries, quantities, attributes)
override or join the existing ones, as the Evolver's addload does: a
quantity declared in both files gets the new elements as members, a global
method or constraint covers every element.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import UnsupportedError

_DEFAULTS = {("facet", "tension"): 1.0}


def _cat(kind, key, a, b, na, nb):
    """Concatenate per-element arrays (a missing side filled with defaults)."""
    if a is None and b is None:
        return None
    ref = a if a is not None else b
    fill = _DEFAULTS.get((kind, key), 0)

    def full(arr, n):
        if arr is not None:
            return arr
        return np.full((n,) + ref.shape[1:], fill, dtype=ref.dtype)

    a, b = full(a, na), full(b, nb)
    if a.ndim != b.ndim:                # a scalar attribute in one, an array in the other
        a, b = (x.reshape(len(x), -1) for x in (a, b))
    if a.ndim == 2 and b.ndim == 2 and a.shape[1] != b.shape[1]:
        w = max(a.shape[1], b.shape[1])
        a = np.pad(a, ((0, 0), (0, w - a.shape[1])))
        b = np.pad(b, ((0, 0), (0, w - b.shape[1])))
    return np.concatenate([a, b.astype(a.dtype, copy=False)])


def append_surface(old, new):
    """Return ``old`` with the elements of ``new`` appended (``old`` is
    modified in place; on a refusal nothing has been changed)."""
    if old.periods is not None or new.periods is not None:
        raise UnsupportedError("addload on a torus surface")
    if old.sdim != new.sdim:
        raise UnsupportedError("addload of a datafile with another space dimension")
    nv0, ne0, nf0, nb0 = old.nv, old.ne, old.nf, old.bodies.n
    nv1, ne1, nf1, nb1 = new.nv, new.ne, new.nf, new.bodies.n
    for name, q in new.quantities.items():
        oq = old.quantities.get(name)
        if oq is not None and [m[1] for m in oq.methods] != [m[1] for m in q.methods]:
            raise UnsupportedError(f"addload: quantity {name} has other methods in the new "
                                   "datafile")
    s = old
    s.X = np.vstack([old.X, new.X])
    s.E = np.vstack([old.E, new.E + nv0])
    s.FE = np.vstack([old.FE, np.where(new.FE >= 0, new.FE + ne0, new.FE - ne0)])
    counts = {"vertex": (nv0, nv1), "edge": (ne0, ne1), "facet": (nf0, nf1), "body": (nb0, nb1)}
    for kind, oa, na in (("vertex", old.vattr, new.vattr), ("edge", old.eattr, new.eattr),
                         ("facet", old.fattr, new.fattr)):
        n0, n1 = counts[kind]
        if "id" in oa or "id" in na:
            top = int(oa["id"].max()) if "id" in oa and n0 else n0
            ids0 = oa["id"] if "id" in oa else np.arange(1, n0 + 1)
            oa["id"] = np.concatenate([ids0, top + np.arange(1, n1 + 1)])
            na = {k: v for k, v in na.items() if k != "id"}
        for key in set(oa) | set(na):
            if key == "id":
                continue
            oa[key] = _cat(kind, key, oa.get(key), na.get(key), n0, n1)
    for kind, ot, nt in (("vertex", old.vcon, new.vcon), ("edge", old.econ, new.econ),
                         ("facet", old.fcon, new.fcon)):
        n0, n1 = counts[kind]
        for cid in set(ot) | set(nt):
            ot[cid] = _cat(kind, cid, ot.get(cid), nt.get(cid), n0, n1)
    for key in set(old.extra) | set(new.extra):
        n0, n1 = counts[key[0]]
        old.extra[key] = _cat(key[0], key, old.extra.get(key), new.extra.get(key), n0, n1)
    # declarations of the new file override
    s.constraints.update(new.constraints)
    s.boundaries.update(new.boundaries)
    for cid, c in s.constraints.items():
        if "global" in c.flags:
            s.vcon[cid] = np.ones(s.nv, bool)
            s.econ[cid] = np.ones(s.ne, np.int8)
    p = s.params
    p.update({k: v for k, v in new.params.items()})
    # bodies
    ob, nbod = old.bodies, new.bodies
    if nb1:
        if nb0:
            M = sp.bmat([[ob.facet_matrix, None], [None, nbod.facet_matrix]]).tocsr()
            for f in ("target", "volconst", "pressure", "density", "lagrange", "original"):
                setattr(ob, f, np.concatenate([getattr(ob, f), getattr(nbod, f)]))
            o0, o1 = ob.occurrences, nbod.occurrences
            ob.occurrences = (np.concatenate([o0[0], o1[0] + nb0]),
                              np.concatenate([o0[1], o1[1] + nf0]),
                              np.concatenate([o0[2], o1[2]]))
            ob.facet_matrix = M
            ob.n = nb0 + nb1
        else:
            nbod.facet_matrix = sp.hstack([sp.csr_matrix((nb1, nf0)),
                                           nbod.facet_matrix]).tocsr()
            r, c, v = nbod.occurrences
            nbod.occurrences = (r, c + nf0, v)
            s.bodies = nbod
        s.bodies.volume = None
    elif nb0:
        ob.facet_matrix = sp.hstack([ob.facet_matrix, sp.csr_matrix((nb0, nf1))]).tocsr()
    # quantities
    total = {"vertex": s.nv, "edge": s.ne, "facet": s.nf}
    for name, q in old.quantities.items():
        q.methods = [(m, et, np.arange(total[et]) if m.is_global else idx, sg)
                     for m, et, idx, sg in q.methods]
    for name, q in new.quantities.items():
        oq = old.quantities.get(name)
        meths = []
        for k, (m, et, idx, sg) in enumerate(q.methods):
            off = counts[et][0]
            if m.is_global:
                meths.append((m, et, np.arange(total[et]), None))
                continue
            idx, sg = idx + off, sg
            if oq is not None:
                om = oq.methods[k]
                if om[2] is not None and om[3] is not None:
                    idx = np.concatenate([om[2], idx])
                    sg = np.concatenate([om[3], sg])
            meths.append((m, et, idx, sg))
        q.methods = meths
        if oq is not None:
            q.value, q.pressure = oq.value, oq.pressure
        s.quantities[name] = q
    return s
