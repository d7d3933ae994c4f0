"""Facet-area derivatives on corners gathered axis-major (issue 24).

:class:`~pyevolver.methods.totals.Totals` gathers the facet corners one
axis at a time, ``P[axis][corner]`` (3, 3, nf).  The kernels here work in
that layout, all three corners of every facet in each numpy call (the
facet-major versions in :mod:`pyevolver.methods.basic` and
:mod:`pyevolver.methods.curvature` make a call per corner and per
component, which is most of a small surface's time), and give the same
numbers: every element is the same sum of the same products, and the
scatter to the vertices sums in :func:`~pyevolver.methods._common.corner_scatter`'s
order (tests/methods/test_axis_major.py compares them bit for bit).

They apply to a :class:`Totals` with ``_corner_xyz`` and ``_corner_sides``
(no torus, no symmetry group: :func:`available`).
"""
from __future__ import annotations

import numpy as np

from ._common import finite

NEXT = np.array([1, 2, 0])       # (c + 1) % 3
NEXT2 = np.array([2, 0, 1])      # (c + 2) % 3
#: above this many facets :func:`scatter` sums axis by axis (no index array of
#: 9 entries per facet kept, 6 MB at 81,920 facets; below, one bincount wins)
LOW_MEMORY_FACETS = 20_000


def available(t) -> bool:
    """Whether ``t`` has its corners gathered axis-major (and no maps of a
    symmetry group)."""
    d = t.__dict__
    return ("_corner_xyz" in d and "_corner_sides" in d and getattr(t, "corner_maps", None) is None
            and t.surface.metric is None)


def cross(u, v):
    """Cross products along the first axis (3, ...): component i is
    ``u[i+1] v[i+2] - u[i+2] v[i+1]`` (the products of geometry.kernels.cross);
    on large surfaces component by component (the same products, without
    four copies of the operands at once)."""
    if u.shape[-1] > LOW_MEMORY_FACETS:
        out = np.empty(np.broadcast_shapes(u.shape, v.shape))
        for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
            np.multiply(u[j], v[k], out=out[i])
            out[i] -= u[k] * v[j]
        return out
    out = u.take(NEXT, axis=0) * v.take(NEXT2, axis=0)
    out -= u.take(NEXT2, axis=0) * v.take(NEXT, axis=0)
    return out


def sides(P, a, b):
    """``facet_points``' corners Q (3 axes, 3 corners, nf) — x0, x0 + a,
    x0 + b — and the side opposite each corner, ``E[:, c] = Q[:, c+2] - Q[:, c+1]``."""
    Q = np.empty_like(P)
    Q[:, 0] = P[:, 0]
    np.add(P[:, 0], a, out=Q[:, 1])
    np.add(P[:, 0], b, out=Q[:, 2])
    if P.shape[-1] > LOW_MEMORY_FACETS:      # (corner by corner: no copies of Q)
        E = np.empty_like(Q)
        for c in range(3):
            np.subtract(Q[:, NEXT2[c]], Q[:, NEXT[c]], out=E[:, c])
        return Q, E
    E = Q.take(NEXT2, axis=1)
    E -= Q.take(NEXT, axis=1)
    return Q, E


def corner_sides(t):
    """:func:`sides` of the Totals ``t`` (kept on it)."""
    c = t.__dict__.get("_axis_sides")
    if c is None:
        a, b = t._corner_sides
        c = t._axis_sides = sides(t._corner_xyz, a, b)
    return c


def unit_normals(t):
    """(3, nf) unit facet normals ``N2 / (2 area)`` (0 where degenerate)."""
    c = t.__dict__.get("_axis_normals")
    if c is None:
        with np.errstate(all="ignore"):
            c = t._axis_normals = finite(t.facet_N2.T / (2.0 * t.facet_area))
    return c


def area_grad(t):
    """Per-corner gradients of the facet areas, (3 axes, 3 corners, nf):
    ``½ n × E[c]`` (``facet_area_grad``'s numbers; kept on ``t``)."""
    c = t.__dict__.get("_axis_area_grad")
    if c is None:
        n = unit_normals(t)
        c = cross(n[:, None, :], corner_sides(t)[1])
        c *= 0.5
        t._axis_area_grad = c
    return c


def facet_major(G):
    """(nf, 3 corners, 3 axes) C-ordered copy of an axis-major ``G``."""
    return np.ascontiguousarray(G.transpose(2, 1, 0))


def gather(s, V):
    """(3 axes, 3 corners, nf) values of the (nv, 3) array ``V`` at the facet corners."""
    return np.ascontiguousarray(V.T).take(s.facet_corners(), axis=1)


def gather1(s, v):
    """(3 corners, nf) values of the (nv,) array ``v`` at the facet corners."""
    return v.take(s.facet_corners())


def scatter(s, G):
    """Per-corner vectors ``G`` (3 axes, 3 corners, nf) summed into the
    vertices, (nv, 3) C-ordered, in corner_scatter's order (facet by facet,
    corner by corner: one bincount for the three axes, or one per axis on
    large surfaces, :func:`scatter_by_axis`)."""
    nv = s.nv
    topo = s.topology()
    if s.nf > LOW_MEMORY_FACETS:
        return scatter_by_axis(topo[2].ravel(), G, nv)
    c = s.__dict__.get("_axis_scatter")
    if c is None or c[0] is not topo:
        flat = topo[2].ravel()
        c = s._axis_scatter = (topo, np.concatenate((flat, flat + nv, flat + 2 * nv)))
    out = np.bincount(c[1], weights=G.transpose(0, 2, 1).ravel(), minlength=3 * nv)
    return np.ascontiguousarray(out.reshape(3, nv).T)


def scatter_by_axis(flat, G, nv):
    """:func:`scatter` with one bincount per axis over ``flat``, the facets'
    vertices facet by facet (``F.ravel()``): the same sums in the same order,
    without an index array of 9 entries per facet."""
    out = np.empty((nv, 3))
    for ax in range(3):
        out[:, ax] = np.bincount(flat, weights=G[ax].T.ravel(), minlength=nv)
    return out


def star_perp_chain(t, dF, dN, dA):
    """The chain rule of the star curvature energies (curvature.vertex_gradient)
    axis-major: the per-corner gradient (3, 3, nf) of Σ_v over the area
    gradient F_v (through the facet-area Hessian), the area vectors N_v and
    the star areas A_v, given ∂E/∂F, ∂E/∂N (nv, 3) and ∂E/∂A (nv,)."""
    s = t.surface
    Q, E = corner_sides(t)
    n = unit_normals(t)
    L = 2.0 * t.facet_area
    U = gather(s, dF)
    # _area_hvp: the directional derivative of ½ n × e_c along U
    de = U.take(NEXT2, axis=1)
    de -= U.take(NEXT, axis=1)
    dN2 = cross(U[:, 1] - U[:, 0], Q[:, 2] - Q[:, 0])
    dN2 += cross(Q[:, 1] - Q[:, 0], U[:, 2] - U[:, 0])
    nd = _dot_rows(n, dN2)
    with np.errstate(all="ignore"):
        dn = finite((dN2 - n * nd) / L)
    g = cross(dn[:, None, :], E)
    g += cross(n[:, None, :], de)
    g *= 0.5
    # n2_grad_dot with D = the corners' ∂E/∂N summed over the facet
    D = np.add.reduce(gather(s, dN), axis=1)
    h = np.empty_like(g)
    h[:, 1] = cross(Q[:, 2] - Q[:, 0], D)
    h[:, 2] = cross(D, Q[:, 1] - Q[:, 0])
    np.subtract(-h[:, 1], h[:, 2], out=h[:, 0])
    h *= 0.5
    g += h
    g += area_grad(t) * np.add.reduce(gather1(s, dA), axis=0)
    return g


def _dot_rows(u, v):
    """Σ_i u[i] v[i] over the first axis of (3, nf) arrays, as the
    ``einsum("ij,ij->i")`` of the facet-major rows."""
    return np.einsum("ji,ji->i", u, v)
