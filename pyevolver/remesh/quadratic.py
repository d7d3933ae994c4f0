"""Conversions between the linear and the quadratic model (``M 2`` /
``quadratic``, ``M 1`` / ``linear``) and ``r`` in the quadratic model.

In the quadratic model every edge carries a midpoint vertex; pyevolver keeps
them as the last ``ne`` vertices, in edge order (``Surface.midv``), as the
Evolver numbers them after ``M 2`` (its ``list vertices``: ids nv+1..nv+ne
in edge order).  A midpoint inherits its edge's FIXED, constraints and
boundary (as a vertex born on the edge, :func:`~pyevolver.remesh.grow.grow`)
and is projected onto its constraints.
"""
from __future__ import annotations

import numpy as np

from ..constraints import constrained_vertices, project_to_constraints
from ..errors import UnsupportedError
from ..geometry import quadratic as Q
from ..model.surface import Surface
from .grow import grow
from .refine import boundary_midpoints, split_edges
from .shrink import subset


def _check(s: Surface) -> None:
    if s.string:
        raise UnsupportedError("the quadratic model of the string model",
                               "pyevolver has it for soapfilm surfaces only")
    if s.periods is not None:
        raise UnsupportedError("the quadratic model in the torus model")


def _add_midpoints(s: Surface, P: np.ndarray | None = None) -> Surface:
    """``s`` (linear) with one midpoint vertex per edge appended, at ``P (ne, 3)``
    (default: the chord midpoints), projected onto the edges' constraints."""
    nv, ne = s.nv, s.ne
    t = grow(s, v_from_edge=np.arange(ne))
    new = np.arange(nv, nv + ne)
    t.X[new] = 0.5 * (s.X[s.E[:, 0]] + s.X[s.E[:, 1]]) if P is None else P
    if P is None:
        boundary_midpoints(t, s.E[:, 0], s.E[:, 1], new)
    sel = new[constrained_vertices(t)[new]]
    if len(sel):
        project_to_constraints(t, sel)
    t.order = 2
    return t


def to_quadratic(s: Surface) -> Surface:
    """The quadratic-model copy of linear surface ``s`` (``M 2``).

    Returns
    -------
    Surface
        ``nv + ne`` vertices: midpoint ``nv + e`` of edge ``e`` at the middle of
        the chord, projected onto the edge's constraints (boundary edges: the
        boundary point nearest the chord midpoint).
    """
    if s.order == 2:
        return s
    _check(s)
    return _add_midpoints(s)


def to_linear(s: Surface) -> Surface:
    """The linear-model copy of quadratic surface ``s`` (``M 1``): the midpoint
    vertices are dropped, the rest keep their ids and positions."""
    if s.order != 2:
        return s
    n0 = s.nv - s.ne
    vkeep = np.arange(s.nv) < n0
    t = subset(s, s.E, s.FE, vkeep, np.ones(s.ne, bool), np.ones(s.nf, bool))
    t.order = 1
    return t


# barycentric points, on the parent patch, of the midpoints of the three edges
# r draws inside a facet: b0 joins M0 and M2, b1 M1 and M0, b2 M2 and M1
# (Mj the midpoint of side j; see remesh.refine.split_edges)
_INNER = np.array([[0.5, 0.25, 0.25], [0.25, 0.5, 0.25], [0.25, 0.25, 0.5]])


def refine_quadratic(s: Surface) -> Surface:
    """``r`` in the quadratic model: every edge is split at its midpoint
    vertex, every facet into four; the new edges' midpoints are points of
    the old curves and patches (halves: parameters 1/4 and 3/4 of the old
    edge; edges inside a facet: the patch at the middle of the new edge in
    the parameter plane), then projected onto their constraints.

    Returns
    -------
    Surface
        ``V' = V + E + (2E + 3F)`` (corners, old midpoints, new midpoints),
        ``E' = 2E + 3F``, ``F' = 4F``.
    """
    if s.eattr["no_refine"].any():
        raise UnsupportedError("r with NO_REFINE edges in the quadratic model")
    if "boundary" in s.vattr:
        raise UnsupportedError("r on boundaries in the quadratic model")
    ne, nf = s.ne, s.nf
    midv = s.midv
    assert midv is not None
    E0 = s.E.copy()
    idx, _, F = s.topology()
    patches = s.X[np.concatenate([F, midv[idx]], axis=1)]          # (nf, 6, 3)
    curves = s.X[np.concatenate([E0, midv[:, None]], axis=1)]      # (ne, 3, 3)
    lin = to_linear(s)
    n0 = lin.nv
    t = split_edges(lin, np.ones(ne, bool))
    t.X[n0:n0 + ne] = s.X[midv]                # the old midpoints become corners
    Nq = Q.edge3_shape(np.array([0.25, 0.75]))[0]
    halves = np.einsum("qc,ncd->nqd", Nq, curves)                  # (ne, 2, 3)
    P = np.empty((t.ne, 3))
    P[:ne] = halves[:, 0]
    P[ne:2 * ne] = halves[:, 1]
    P[2 * ne:] = Q.patch_points(patches, _INNER).reshape(3 * nf, 3)
    return _add_midpoints(t, P)
