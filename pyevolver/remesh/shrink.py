"""Drop vertices, edges and facets from a surface and renumber the rest.

The counterpart of :func:`~pyevolver.remesh.grow.grow` for operations that
delete elements (``t``, ``w``, ``o``): the caller has already rewritten the
connectivity ``E`` / ``FE`` of the surviving elements in terms of the old
indices; :func:`subset` keeps the marked elements in their order and maps
every index (edge endpoints, facet edges, body facets, quantity and
constraint memberships) to the new numbering.
"""
from __future__ import annotations

import copy

import numpy as np

from .grow import remap_quantities


def _renumber(keep):
    new = np.full(len(keep), -1, np.int64)
    new[keep] = np.arange(int(np.count_nonzero(keep)))
    return new


def subset(s, E, FE, vkeep, ekeep, fkeep):
    """A copy of ``s`` with only the kept elements.

    Parameters
    ----------
    s : Surface
    E : (ne, 2) int array
        Edge endpoints (old vertex indices) to use for the kept edges.
    FE : (nf, 3) int array
        Signed facet edges (old edge indices, ``~e`` for reversed) to use for
        the kept facets.
    vkeep, ekeep, fkeep : bool arrays (nv,), (ne,), (nf,)
    """
    nv_, ne_, nf_ = _renumber(vkeep), _renumber(ekeep), _renumber(fkeep)
    t = copy.copy(s)
    for name in ("_lift_cache", "_topo", "_corners"):
        t.__dict__.pop(name, None)
    t.X = s.X[vkeep].copy()
    t.E = nv_[E[ekeep]]
    fe = FE[fkeep]
    fwd = fe >= 0
    ei = ne_[np.where(fwd, fe, ~fe)]
    if (t.E < 0).any() or (ei < 0).any():
        raise ValueError("subset: a kept element refers to a dropped one")
    t.FE = np.where(fwd, ei, ~ei)
    t.vattr = {k: a[vkeep].copy() for k, a in s.vattr.items()}
    t.eattr = {k: a[ekeep].copy() for k, a in s.eattr.items()}
    t.fattr = {k: a[fkeep].copy() for k, a in s.fattr.items()}
    # survivors keep their ids (the Evolver's numbering has gaps after deletions)
    t.vattr["id"] = s.ids("vertex")[vkeep].copy()
    t.eattr["id"] = s.ids("edge")[ekeep].copy()
    t.fattr["id"] = s.ids("facet")[fkeep].copy()
    t.vcon = {c: a[vkeep].copy() for c, a in s.vcon.items()}
    t.econ = {c: a[ekeep].copy() for c, a in s.econ.items()}
    t.fcon = {c: a[fkeep].copy() for c, a in s.fcon.items()}
    keep = {"vertex": vkeep, "edge": ekeep, "facet": fkeep}
    t.extra = {(et, n): (a[keep[et]].copy() if et in keep else a.copy())
               for (et, n), a in s.extra.items()}
    b = copy.copy(s.bodies)
    if b.n:
        b.facet_matrix = s.bodies.facet_matrix.tocsc()[:, fkeep].tocsr()
        ob, of, osg = s.bodies.occurrences
        ok = fkeep[of]
        b.occurrences = (ob[ok], nf_[of[ok]], osg[ok])
        b.volume = None
    t.bodies = b
    newidx = {"vertex": nv_, "edge": ne_, "facet": nf_}

    def drop(etype, idx, sgn):
        ok = keep[etype][idx]
        return newidx[etype][idx[ok]], sgn[ok]
    t.quantities = remap_quantities(s, t, drop)
    t.topology_version = getattr(s, "topology_version", 0) + 1
    return t
