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
from ..errors import UnsupportedError, dimension_error
from ..geometry import quadratic as Q
from ..model.surface import Surface
from .grow import grow, remap_quantities
from .refine import boundary_midpoints, split_edges
from .shrink import subset


def _check(s: Surface) -> None:
    if s.X.shape[1] > 3:
        raise dimension_error(s.sdim, "the quadratic model")
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
    # on a boundary: the curve point nearest the chord's midpoint (after r:
    # nearest the point of the old curve), by the Gauss-Newton of
    # remesh.refine started from the tail's parameters (REF's p1 after M 2
    # on catbody.fe: 0.5235693, below pi/6 as from the tail)
    boundary_midpoints(t, s.E[:, 1], s.E[:, 0], new, target=P)
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
# r draws inside a facet split on all sides (remesh.refine.split_edges's order):
# b0 joins M0 and M2, b1 M1 and M0, b2 M2 and M1 (Mj the midpoint of side j)
_INNER = np.array([[0.5, 0.25, 0.25], [0.25, 0.5, 0.25], [0.25, 0.25, 0.5]])


def refine_quadratic(s: Surface) -> Surface:
    """``r`` in the quadratic model: every edge without NO_REFINE is split
    at its midpoint vertex and the facets across their split sides (as
    :func:`~pyevolver.remesh.refine.split_edges`); the new edges' midpoints
    are points of the old curves and patches (halves: parameters 1/4 and 3/4
    of the old edge; edges inside a facet: the patch at the middle of the
    new edge in the parameter plane), projected onto their constraints;
    unsplit edges keep their midpoints.  Facets split on one or two sides
    (NO_REFINE edges beside refined ones) are refused by name.

    Returns
    -------
    Surface
        Corners, then the old midpoints of the split edges, then one
        midpoint per edge: ``V' = V + E + (2E + 3F)``, ``E' = 2E + 3F``,
        ``F' = 4F`` without NO_REFINE.
    """
    ne = s.ne
    midv = s.midv
    assert midv is not None
    ref = ~s.eattr["no_refine"]
    R = np.nonzero(ref)[0]
    idx, _, F = s.topology()
    nref = ref[idx].sum(axis=1)
    if np.any((nref == 1) | (nref == 2)):
        raise UnsupportedError(
            "r in the quadratic model with NO_REFINE edges on facets that are split",
            "REF's midpoints of the edges cutting such facets are not matched yet (cube.fe "
            "with two NO_REFINE edges, M 2; g 2; r: REF's energy 4.996029, the patch "
            "points give 4.974721)")
    patches = s.X[np.concatenate([F, midv[idx]], axis=1)]          # (nf, 6, 3)
    curves = s.X[np.concatenate([s.E, midv[:, None]], axis=1)]     # (ne, 3, 3)
    lin = to_linear(s)
    n0 = lin.nv
    t = split_edges(lin, ref)
    t.X[n0:n0 + len(R)] = s.X[midv[R]]          # the old midpoints become corners
    if "params" in s.vattr:
        t.vattr["params"][n0:n0 + len(R)] = s.vattr["params"][midv[R]]
    Nq = Q.edge3_shape(np.array([0.25, 0.75]))[0]
    halves = np.einsum("qc,ncd->nqd", Nq, curves[R])               # (k, 2, 3)
    P = np.empty((t.ne, 3))
    P[:ne] = s.X[midv]
    P[R] = halves[:, 0]
    P[ne:ne + len(R)] = halves[:, 1]
    f3 = np.nonzero(nref == 3)[0]
    P[ne + len(R):] = Q.patch_points(patches[f3], _INNER).reshape(-1, 3)
    return _add_midpoints(t, P)


def _permute_vertices(s: Surface, perm: np.ndarray) -> Surface:
    """A copy of ``s`` whose vertex ``i`` is ``s``'s vertex ``perm[i]`` (ids kept)."""
    perm = np.asarray(perm, np.int64)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(len(perm))
    keep = np.ones(s.nv, bool)
    t = subset(s, s.E, s.FE, keep, np.ones(s.ne, bool), np.ones(s.nf, bool))
    t.X = s.X[perm].copy()
    t.E = inv[s.E]
    t.vattr = {k: a[perm].copy() for k, a in t.vattr.items()}
    t.vcon = {c: a[perm].copy() for c, a in t.vcon.items()}
    t.extra = {(et, n): (a[perm].copy() if et == "vertex" else a) for (et, n), a in t.extra.items()}

    def move(etype, idx, sgn):
        return (inv[idx], sgn) if etype == "vertex" else (idx, sgn)
    t.quantities = remap_quantities(t, t, move)
    t.__dict__.pop("_topo", None)
    return t


def from_listed(s: Surface) -> Surface:
    """The quadratic surface of a datafile with ``QUADRATIC`` in its top
    section: the edges' listed midpoints (``s.listed_midpoints``, -1 where an
    edge lists none) move to the end in edge order; an edge without one
    gets a new midpoint as with ``M 2``.

    Raises
    ------
    UnsupportedError
        When a listed midpoint is also an edge's end or two edges share one.
    """
    mids = np.asarray(s.__dict__.pop("listed_midpoints"), np.int64)
    # the edges of triangulated faces (spokes) come after the listed ones
    mids = np.concatenate([mids, np.full(s.ne - len(mids), -1, np.int64)])
    _check(s)
    listed = mids[mids >= 0]
    if len(np.unique(listed)) != len(listed) or np.isin(listed, s.E).any():
        raise UnsupportedError("a midpoint vertex shared by two edges or also an edge's end")
    missing = np.nonzero(mids < 0)[0]
    if len(missing):
        nv = s.nv
        s = grow(s, v_from_edge=missing)
        new = np.arange(nv, nv + len(missing))
        s.X[new] = 0.5 * (s.X[s.E[missing, 0]] + s.X[s.E[missing, 1]])
        boundary_midpoints(s, s.E[missing, 0], s.E[missing, 1], new)
        sel = new[constrained_vertices(s)[new]]
        if len(sel):
            project_to_constraints(s, sel)
        mids = mids.copy()
        mids[missing] = new
    corners = np.setdiff1d(np.arange(s.nv), mids)
    t = _permute_vertices(s, np.concatenate([corners, mids]))
    t.order = 2
    return t
