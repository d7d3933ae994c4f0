"""Shared kernels of the method derivatives (used by the methods and by
:mod:`pyevolver.evolve`): scattering per-corner vectors to vertices, the
unwrapped facet corners, and sparse assembly of per-element Hessian blocks.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..geometry.kernels import cross


def finite(x: np.ndarray) -> np.ndarray:
    """``np.nan_to_num(x)`` for an array ``x`` the caller has just made (it is
    changed in place, and returned as it is when all finite, the usual
    case: a tenth of nan_to_num's time, which counts on small surfaces)."""
    if np.isfinite(x).all():
        return x
    return np.nan_to_num(x, copy=False)


def csr_matvec(M, x: np.ndarray) -> np.ndarray:
    """``M @ x`` for a sparse matrix ``M`` and a vector ``x``: for CSR the
    same products summed in the same order as scipy's (each row from 0, in
    stored order), so the same numbers, without scipy's call overhead (a
    fifth of a small surface's evaluation: the bodies' volumes)."""
    if getattr(M, "format", None) != "csr" or x.ndim != 1 or x.dtype != np.float64 \
            or M.dtype != np.float64:
        return M @ x
    cached = M.__dict__.get("_rows_of_entries")
    if cached is not None and cached[0] is M.indptr and len(cached[1]) == len(M.data):
        rows = cached[1]
    else:                       # (kept on the matrix while its structure is the same)
        rows = np.repeat(np.arange(M.shape[0]), np.diff(M.indptr))
        M.__dict__["_rows_of_entries"] = (M.indptr, rows)
    return np.bincount(rows, weights=M.data * x[M.indices], minlength=M.shape[0])


def scatter(nv: int, idx: np.ndarray, vecs: np.ndarray) -> np.ndarray:
    """Sum per-corner vectors ``vecs (m, 3)`` into vertices ``idx (m,)``."""
    out = np.empty((nv, 3))
    for k in range(3):
        out[:, k] = np.bincount(idx, weights=vecs[:, k], minlength=nv)
    return out


def facet_points(t) -> np.ndarray:
    """Unwrapped facet corners (nf, 3, 3)."""
    x0 = t.facet_x0
    S = t.facet_S
    return np.stack([x0, x0 + S[:, 0], x0 + S[:, 1]], axis=1)


def n2_grad_dot(P: np.ndarray, D: np.ndarray) -> np.ndarray:
    """Per-corner gradients of D . N2, N2 = (x1-x0) x (x2-x0), D per facet."""
    g = np.empty_like(P)
    g[:, 1] = cross(P[:, 2] - P[:, 0], D)
    g[:, 2] = cross(D, P[:, 1] - P[:, 0])
    g[:, 0] = -g[:, 1] - g[:, 2]
    return g


def corner_scatter(t, per_corner: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """Scatter per-corner facet gradients (nf, 3, 3) to vertices."""
    s = t.surface
    if weights is not None:
        per_corner = per_corner * weights[:, None, None]
    maps = getattr(t, "corner_maps", None)
    if maps is not None:            # a symmetry group: back through Aᵀ (methods.group_geometry)
        per_corner = np.einsum("fkji,fkj->fki", maps, per_corner)
    return scatter(s.nv, s.F.ravel(), per_corner.reshape(-1, 3))


def edge_pullback(t, idx: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Gradients ``u (n, 3)`` with respect to the heads' images ``g(x_head)``
    of the edges ``idx``, as gradients with respect to the heads (``Aᵀ u`` in
    a symmetry group, methods.group_geometry; ``u`` otherwise)."""
    maps = getattr(t, "edge_maps", None)
    if maps is None:
        return u
    return np.einsum("nji,nj->ni", maps[idx], u)


def group_blocks(t, blocks: np.ndarray, sel=None, edges=None) -> np.ndarray:
    """Hessian blocks (m, k, k, 3, 3) with respect to the unwrapped corners
    as blocks with respect to the vertices: ``A_aᵀ H_ab A_b`` with the
    corners' linear parts ``A`` in a symmetry group (methods.group_geometry;
    the translations drop out of second derivatives), unchanged otherwise.
    ``sel`` picks the facets (or ``edges`` the edges: tail I, head A) the
    blocks belong to."""
    if edges is not None:
        emaps = getattr(t, "edge_maps", None)
        if emaps is None:
            return blocks
        maps = np.zeros((len(edges), 2, 3, 3))
        maps[:, 0] = np.eye(3)
        maps[:, 1] = emaps[edges]
    else:
        maps = getattr(t, "corner_maps", None)
        if maps is None:
            return blocks
        if sel is not None:
            maps = maps[sel]
    return np.einsum("maip,mabij,mbjq->mabpq", maps, blocks, maps, optimize=True)


def has_group_maps(t) -> bool:
    """Whether the evaluation carries a symmetry group's maps (the
    hessian_normal shortcuts then take the general path)."""
    return getattr(t, "corner_maps", None) is not None


def assemble(nv: int, verts: np.ndarray, blocks: np.ndarray, basis=None) -> sp.coo_matrix:
    """Sparse matrix from per-element blocks, in COO form with the elements'
    entries not yet summed (``evolve.hessian._sum`` adds all parts in one conversion).

    verts : (m, k) vertex indices of each element; blocks : (m, k, k, 3, 3).
    Without ``basis`` the (3nv, 3nv) matrix; with a :class:`Basis` the
    projected ``Tᵀ H T`` (ndof, ndof), contracted per element before the
    assembly (nine times fewer entries in the hessian_normal case).
    """
    m, k = verts.shape
    if basis is not None:
        Bv = basis.B[verts]                                        # (m, k, 3, d)
        blocks = np.einsum("maip,mabij,mbjq->mabpq", Bv, blocks, Bv, optimize=True)
        return assemble_projected(verts, blocks, basis)
    rows = (3 * verts[:, :, None, None, None] + np.arange(3)[None, None, None, :, None])
    cols = (3 * verts[:, None, :, None, None] + np.arange(3)[None, None, None, None, :])
    rows = np.broadcast_to(rows, (m, k, k, 3, 3)).ravel()
    cols = np.broadcast_to(cols, (m, k, k, 3, 3)).ravel()
    return sp.coo_matrix((blocks.ravel(), (rows, cols)), shape=(3 * nv, 3 * nv))


def assemble_projected(verts: np.ndarray, blocks: np.ndarray, basis) -> sp.coo_matrix:
    """Sparse (ndof, ndof) matrix from projected element blocks (m, k, k, d, d)."""
    m, k = verts.shape
    d = blocks.shape[3]
    idx = basis.start[verts][:, :, None] + np.arange(d)        # (m, k, d)
    ok = np.arange(d)[None, None, :] < basis.ndof[verts][:, :, None]
    idx = np.where(ok, idx, -1)
    rows = np.broadcast_to(idx[:, :, None, :, None], (m, k, k, d, d)).ravel()
    cols = np.broadcast_to(idx[:, None, :, None, :], (m, k, k, d, d)).ravel()
    vals = blocks.ravel()
    if (basis.ndof[verts] < d).any():
        keep = (rows >= 0) & (cols >= 0)
        rows, cols, vals = rows[keep], cols[keep], vals[keep]
    return sp.coo_matrix((vals, (rows, cols)), shape=(basis.n, basis.n))
