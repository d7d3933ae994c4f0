"""``hessian`` in SPACE_DIMENSION 4 to 9 (the linear soapfilm model).

The surface's vertices have ``d > 3`` coordinates; the energies there
(facet and edge tension through Gram determinants, ``linear_elastic_B``,
``relaxed_elastic*``) have analytic gradients in all ``d`` of them, and the
Hessian of the Lagrangian is their central differences over a distance-2
vertex colouring (:func:`fd_hessian_nd`, as :func:`.hessian.fd_hessian` in
3 dimensions).  Each mobile vertex moves in the tangent space of its
level-set constraints (``d − k`` coordinates, the constraint curvature
``Σ μ ∇²φ`` taken out as in 3 dimensions); a FIXED vertex does not move.

``hessian_normal`` (on by default): REF's vertex normals in ``d > 3`` are
those of x1..x3 (measured for ``V``); a vertex then moves along that normal
in x1..x3 only, x4..xd staying (measured on a 5-D square with a free
centre: tests/evolve/test_hessian_nd.py).
Fixed quantities are refused (bodies are refused at load in ``d > 3``).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..constraints import vertex_coords
from ..constraints.levelset import tangent_projectors, _names
from ..errors import UnsupportedError
from ..geometry import kernels as G
from . import gradient as GR
from .hessian import Basis, HessianSystem, distance2_coloring, hessian_system
from .iterate import _Constraints


def fd_hessian_nd(fun, s, h=None):
    """Sparse (d nv, d nv) Hessian of a gradient function ``fun() -> (nv, d)``
    of the surface's coordinates, by central differences over a distance-2
    colouring (one gradient pair per colour and coordinate)."""
    nv, d = s.X.shape
    if nv == 0:
        return sp.csr_matrix((0, 0))
    X0 = s.X.copy()
    scale = float(np.max(np.ptp(X0, axis=0)))
    h = h if h is not None else 1e-5 * max(scale, 1e-12)
    color = distance2_coloring(s)
    F = s.F
    r = np.concatenate([s.E[:, 0], s.E[:, 1]] + [F[:, i] for i in range(3)] + [np.arange(nv)])
    c = np.concatenate([s.E[:, 1], s.E[:, 0]] + [F[:, (i + 1) % 3] for i in range(3)] +
                       [np.arange(nv)])
    A = sp.csr_matrix((np.ones(len(r)), (r, c)), shape=(nv, nv))
    A = (A + A.T).tocoo()
    rows, cols, vals = [], [], []
    try:
        for col in range(color.max() + 1):
            members = color == col
            sel = members[A.col]
            zr, uc = A.row[sel], A.col[sel]
            for k in range(d):
                s.X = X0.copy()
                s.X[members, k] += h
                gp = fun()
                s.X = X0.copy()
                s.X[members, k] -= h
                gm = fun()
                D = (gp - gm) / (2 * h)
                for i in range(d):
                    rows.append(d * zr + i)
                    cols.append(d * uc + k)
                    vals.append(D[zr, i])
    finally:
        s.X = X0
    H = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(d * nv, d * nv))
    return 0.5 * (H + H.T)


def _bases(s, mobile, normal):
    """(nv, d, d) per-vertex bases of the free motions and their sizes."""
    nv, d = s.X.shape
    P = tangent_projectors(s, np.arange(nv))                    # (nv, d, d)
    w, V = np.linalg.eigh(P)
    keep = w > 0.5                                              # eigenvalues 0 or 1
    order = np.argsort(~keep, axis=1, kind="stable")
    V = np.take_along_axis(V, order[:, None, :], axis=2)
    ndof = np.where(mobile, keep.sum(axis=1), 0)
    if normal:
        t = s.evaluate()
        N2 = G.facet_normals(t.facet_S[:, :, :3])
        nrm = G.vertex_normals(s.F, N2, nv)                     # x1..x3 normals
        free = mobile & (ndof == d) & (np.linalg.norm(nrm, axis=1) > 0)
        B = V.copy()
        B[free] = 0.0
        B[free, :3, 0] = nrm[free]
        ndof = np.where(free, 1, ndof)
        # on level-set constraints: the normal projected on the tangent
        # space (when it has a part there), as in 3 dimensions
        con = np.nonzero(mobile & (ndof > 1) & (ndof < d))[0]
        if len(con):
            npad = np.zeros((len(con), d))
            npad[:, :3] = nrm[con]
            nt = np.einsum("nij,ni->nj", V[con], npad)
            nt[np.arange(d)[None, :] >= ndof[con, None]] = 0.0
            nn = np.linalg.norm(nt, axis=1)
            first = np.eye(d)[0][None, :]
            u = np.where(nn[:, None] > 1e-12, nt / np.maximum(nn, 1e-300)[:, None], first)
            B[con] = 0.0
            B[con, :, 0] = np.einsum("nij,nj->ni", V[con], u)
            ndof[con] = 1
        return B, ndof
    return V, ndof


def _constraint_curvature(s, mobile, gL):
    """Σ_v μ_v ∇²φ(x_v) (sparse (d nv, d nv)), μ the multipliers that take the
    normal part of the Lagrangian gradient ``gL`` (nv, d)."""
    nv, d = s.X.shape
    if not s.vcon:
        return None
    env = s.param_env()
    names = _names(s)
    cids = sorted(s.vcon)
    on = np.stack([np.asarray(s.vcon[c], bool) for c in cids], axis=1) & mobile[:, None]
    rows, cols, vals = [], [], []
    keys, inv = np.unique(on, axis=0, return_inverse=True)
    for gi, key in enumerate(keys):
        if not key.any():
            continue
        sel = np.nonzero(inv.ravel() == gi)[0]
        coords = vertex_coords(s, sel)
        active = [c for c, k in zip(cids, key) if k]
        Gm = np.stack([np.broadcast_to(s.constraints[c].formula.gradient(env, coords, len(sel),
                                                                         names), (len(sel), d))
                       for c in active], axis=2)                 # (n, d, k)
        GtG = np.einsum("nik,nil->nkl", Gm, Gm)
        rhs = np.einsum("nik,ni->nk", Gm, gL[sel])
        mu = np.linalg.solve(GtG, rhs[..., None])[..., 0]
        Hs = np.zeros((len(sel), d, d))
        for j, c in enumerate(active):
            Hs += mu[:, j, None, None] * s.constraints[c].formula.hessian(env, coords, len(sel),
                                                                          names)
        for i in range(d):
            for k in range(d):
                rows.append(d * sel + i)
                cols.append(d * sel + k)
                vals.append(Hs[:, i, k])
    if not rows:
        return None
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(d * nv, d * nv))


class _NdBasis(Basis):
    """A :class:`~.hessian.Basis` with ``d`` coordinates per vertex."""

    def matrix(self):
        nv, d, m = self.B.shape
        j = np.arange(m)
        use = j[None, :] < self.ndof[:, None]
        v, jj = np.nonzero(use)
        rows = (d * v[:, None] + np.arange(d)[None, :]).ravel()
        cols = np.repeat(self.start[v] + jj, d)
        vals = self.B[v, :, jj].ravel()
        return sp.csr_matrix((vals, (rows, cols)), shape=(d * nv, self.n))


def hessian_system_nd(it, normal: bool = True) -> HessianSystem:
    """:func:`.hessian.hessian_system` for ``d > 3`` coordinates."""
    s = it.surface
    mobile = it._mobile()
    cons = _Constraints(s)
    if len(cons):
        raise UnsupportedError(f"hessian with fixed quantities in SPACE_DIMENSION {s.sdim}",
                               "only energies and level-set constraints")
    t = s.evaluate()
    gE = GR.energy_gradient(t)
    H = fd_hessian_nd(lambda: GR.energy_gradient(s.evaluate()), s)
    B, ndof = _bases(s, mobile, normal)
    basis = _NdBasis(B, ndof)
    T = basis.matrix()
    K = T.T @ H @ T
    Hc = _constraint_curvature(s, mobile, gE)
    if Hc is not None:
        K = K - T.T @ Hc @ T
    K = sp.csc_matrix(K)
    rhs = -(T.T @ gE.ravel())
    return HessianSystem(K, None, rhs, None, T, basis, np.zeros(0), cons, mobile, s.X[:, :3])


def system(it, normal: bool = True, lowrank: bool = False) -> HessianSystem:
    """The Hessian system of ``hessian`` in any dimension: this module's in
    ``d > 3`` (which refuses FUNCTION quantities), :func:`.hessian.hessian_system`
    (with ``lowrank``) in 3."""
    if it.surface.X.shape[1] > 3:
        return hessian_system_nd(it, normal)
    return hessian_system(it, normal, lowrank=lowrank)
