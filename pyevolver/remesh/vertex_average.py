"""Vertex averaging: ``V``, ``rawv`` and ``rawestv`` (spec §8.3).

Evolver 2.70 does not do what its manual describes (an area-weighted
average of facet centroids); the spec records what it does, checked
numerically against ``evolver-nox-d``:

* every new position is computed from the old positions, then all are applied;
* a vertex that is FIXED or on a parametric boundary does not move;
* edge weights: ``w_e`` = the summed area of the facets on edge ``e``
  (weight 1 instead for edges with other than two facets);
* ``V``/``rawv`` (``mode`` "V"/"raw"): a vertex on level-set constraints uses
  only the edges that carry all of its constraints; a vertex on triple
  (valence >= 3) edges uses only those, with weight 1, and does not move if
  it has three or more of them; a vertex on free-edge (valence-1) edges uses
  only those, with weight 1.  ``rawestv`` ("rawest") uses every edge with
  area weights;
* fewer than two usable edges: no move;
* ``D = Σ w_e² (x_e - x_v) / Σ w_e²``;
* ``V`` only: ``D`` loses its component along the unit vertex normal
  (REF's ``vertex_normal``: :func:`geometry.vertex_normals` with the
  facets in REF's order, the sum of the adjacent facets' area vectors on a
  smooth star), and on constrained vertices is
  projected onto the constraint tangent space before and after;
* ``x_v += D / 4``; constrained vertices are projected back.

In a symmetry group (pyevolver.model.groups) the head of an edge sees its
tail at ``-Aᵀ d`` (``d = g(x_head) - x_tail``); the normals of ``V`` are
the facets' area vectors as they are, in each facet's frame (measured:
turning them into the vertex's frame does not give REF's moves).
"""
from __future__ import annotations

import copy

import numpy as np

from ..geometry import kernels as G
from ..constraints import project_tangent, project_to_constraints
from ..model.records import vertex_facet_rank


def vertex_average(s, mode="V", totals=None):
    """Return a copy of surface ``s`` with vertices averaged.

    Parameters
    ----------
    s : Surface
    mode : {"V", "raw", "rawest"}
        ``V`` (volume-preserving: normal component removed), ``rawv`` or
        ``rawestv``.
    totals : Totals, optional
        An evaluation of ``s`` as it is (the session's, when nothing
        changed since it was made); evaluated here otherwise.

    Returns
    -------
    Surface
        A new surface sharing the topology of ``s``, new coordinates.
    """
    t = totals if totals is not None and totals.surface is s else s.evaluate()
    nv, ne = s.nv, s.ne
    idx = s.topology()[0]                                        # (nf, 3) edge ids
    valence = np.bincount(idx.ravel(), minlength=ne)
    area_w = np.bincount(idx.ravel(), weights=np.repeat(t.facet_area, 3), minlength=ne)
    ends = s.E
    d = t.edge_vec                                               # head - tail (wrapped)
    # each edge seen from both ends: vertex v, edge e, vector x_e - x_v
    v = np.concatenate([ends[:, 0], ends[:, 1]])
    e = np.concatenate([np.arange(ne), np.arange(ne)])
    maps = getattr(t, "edge_maps", None)        # a symmetry group: the tail seen from the head
    vec = np.concatenate([d, -d if maps is None else -np.einsum("eji,ej->ei", maps, d)])
    if mode == "rawest":
        use = np.ones(len(v), bool)
        w = area_w[e]
    else:
        w = np.where(valence[e] == 2, area_w[e], 1.0)
        use = np.ones(len(v), bool)
        if s.vcon:
            # only edges carrying every constraint of the vertex
            for c, on_v in s.vcon.items():
                on_e = s.econ.get(c)
                on_e = np.zeros(ne, bool) if on_e is None else (on_e != 0)
                use &= ~on_v[v] | on_e[e]
        if len(valence) and valence.min() == 2 and valence.max() == 2:
            frozen = np.zeros(nv, bool)         # (no triple or free edges: the rules below are void)
        else:
            trip = valence[e] >= 3
            ntrip = np.bincount(v, weights=trip.astype(float), minlength=nv)
            use &= (ntrip[v] == 0) | trip
            free = valence[e] == 1
            nfree = np.bincount(v, weights=free.astype(float), minlength=nv)
            use &= (nfree[v] == 0) | free
            frozen = ntrip >= 3
    w2 = np.where(use, w * w, 0.0)
    cnt = np.bincount(v, weights=use.astype(float), minlength=nv)
    W = np.bincount(v, weights=w2, minlength=nv)
    D = np.zeros((nv, s.X.shape[1]))
    for k in range(D.shape[1]):
        D[:, k] = np.bincount(v, weights=w2 * vec[:, k], minlength=nv)
    movable = ~s.vattr["fixed"] & (cnt >= 2) & (W > 0)
    bnd = s.vattr.get("boundary")
    if bnd is not None:
        movable &= bnd == 0
    if mode != "rawest":
        movable &= ~frozen
    D[~movable] = 0.0
    mv = np.nonzero(movable)[0]
    D[mv] /= W[mv, None]
    if mode == "V":
        # in SPACE_DIMENSION > 3 REF's normals are those of x1..x3 and only
        # those coordinates lose their normal component (measured)
        N2 = t.facet_N2 if D.shape[1] == 3 else G.facet_normals(t.facet_S[:, :, :3])
        n = G.vertex_normals(s.F, N2, nv, vertex_facet_rank(s))
        (D,) = project_tangent(s, [D])
        D[:, :3] -= np.einsum("ij,ij->i", D[:, :3], n)[:, None] * n
        (D,) = project_tangent(s, [D])
    new = copy.copy(s)
    new.__dict__.pop("_lift_cache", None)
    X = s.X + D / 4.0
    new.X = X
    if new.vcon:
        project_to_constraints(new, mv)
    return new
