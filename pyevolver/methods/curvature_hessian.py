"""Hessians of the curvature energies, for ``hessian`` and Hessian-vector products.

Every vertex energy is ``Σ_v w_v φ(y_v)`` where ``y_v`` is a short vector of
star sums over the facets around v (``(A, F, N)`` for the squared mean
curvature methods of :mod:`.curvature`, ``(K, A)`` for ``sq_gauss_curvature``,
``(S, A)`` for ``cotan_sq_mean_curvature``).  With ``J`` the Jacobian of all
the ``y_v`` (a sparse (r·nv, 3nv) matrix assembled from per-facet blocks) the
Hessian is the Gauss–Newton part plus the curvature of the star sums::

    H = Jᵀ diag(∇²φ_v) J + Σ_f ∇²( Σ_{v ∈ f} ∇φ_v · y_{v,f} )

The first term couples vertices two edges apart (a common star), the second
is a 9×9 block per facet.  The per-facet pieces and their exact second
derivatives come from :mod:`.jets`; the area-gradient term ``λ · ∇_c A``
is written as ``N · w / (4A)`` with ``w = Σ_c e_c × λ_c`` (``∇_c A = N × e_c
/ (4A)``, ``e_c`` the side opposite corner c).  ``mean_curvature_integral`` is
a 12×12 block per edge (its two facets), the angle sums of the Gaussian
curvatures 9×9 blocks per facet.

All functions take ``(t, method, idx, w, basis=None)`` as the gradients do
and return a sparse matrix: (3nv, 3nv), or ``Tᵀ H T`` on a
:class:`pyevolver.evolve.hessian.Basis`.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..constraints.levelset import constrained_vertices, curved_constraints
from . import curvature as C
from ._common import assemble, facet_points
from .registry import register_method
from . import jets as J
from . import star_rows as SR

# -- assembly ---------------------------------------------------------------------------------

def _elements(nv, verts, H, basis):
    """Sparse matrix from per-element Hessians H (m, 3k, 3k) on ``verts`` (m, k)."""
    m, k = verts.shape
    H = _finite(H)
    return assemble(nv, verts, H.reshape(m, k, 3, k, 3).transpose(0, 1, 3, 2, 4), basis)


def _rows(nrows, ridx, verts, blocks, nv, basis):
    """Sparse (nrows, 3nv or basis.n) matrix from per-element row blocks:
    ``ridx`` (m, r) row numbers, ``verts`` (m, k), ``blocks`` (m, r, k, 3);
    in COO form, its entries not summed (:func:`_add` converts once)."""
    m, r = ridx.shape
    k = verts.shape[1]
    blocks = _finite(blocks)
    if basis is None:
        cols = 3 * verts[:, :, None] + np.arange(3)
        rows = np.broadcast_to(ridx[:, :, None, None], (m, r, k, 3))
        cols = np.broadcast_to(cols[:, None], (m, r, k, 3))
        return sp.coo_matrix((blocks.ravel(), (rows.ravel(), cols.ravel())),
                             shape=(nrows, 3 * nv))
    Bv = basis.B[verts]                                         # (m, k, 3, d)
    d = Bv.shape[3]
    # contract each vertex's 3 columns with its basis: (m, r, k, 3) @ (m, 1, k, 3, d)
    vals = np.matmul(blocks[:, :, :, None, :], Bv[:, None])[:, :, :, 0, :]
    idx = basis.start[verts][:, :, None] + np.arange(d)
    rows = np.broadcast_to(ridx[:, :, None, None], (m, r, k, d))
    cols = np.broadcast_to(idx[:, None], (m, r, k, d))
    if (basis.ndof >= d).all():
        return sp.coo_matrix((vals.ravel(), (rows.ravel(), cols.ravel())),
                             shape=(nrows, basis.n))
    ok = np.arange(d)[None, None, :] < basis.ndof[verts][:, :, None]
    keep = np.broadcast_to(ok[:, None], (m, r, k, d))
    return sp.coo_matrix((vals[keep], (rows[keep], cols[keep])), shape=(nrows, basis.n))


def _finite(a):
    """``a`` with non-finite entries (degenerate elements) set to 0."""
    bad = ~np.isfinite(a)
    if bad.any():
        a = np.where(bad, 0.0, a)
    return a


def _gauss_newton(Jm, M):
    """``Jmᵀ diag(M) Jm`` for per-vertex blocks M (nv, r, r)."""
    nv, r, _ = M.shape
    Jm = Jm.tocsr()
    Md = sp.bsr_matrix((_finite(M), np.arange(nv), np.arange(nv + 1)),
                       shape=(nv * r, nv * r)).tocsr()
    return (Jm.T @ (Md @ Jm)).tocsr()


def _facet_jets(P):
    """Corner jets, ``N = (x1−x0)×(x2−x0)``, ``|N|`` and the area of facets P (nf, 3, 3)."""
    x = J.points(P)
    N2 = J.cross(x[1] - x[0], x[2] - x[0])
    L = J.norm(N2)
    return x, N2, L, L * 0.5


def _inverse(s):
    with np.errstate(all="ignore"):
        return s.apply(1.0 / s.v, -1.0 / s.v ** 2, 2.0 / s.v ** 3)


# -- squared mean curvature (the star sums A, F, N) ---------------------------------------------

def _ratio(P, gP, HP, Q, gQ, HQ):
    """Gradient and Hessian of P/Q over z (6,) from those of P and Q."""
    with np.errstate(all="ignore"):
        g = gP / Q[:, None] - (P / Q ** 2)[:, None] * gQ
        o = gP[:, :, None] * gQ[:, None, :]
        H = (HP / Q[:, None, None] - (o + np.swapaxes(o, 1, 2)) / (Q ** 2)[:, None, None]
             - (P / Q ** 2)[:, None, None] * HQ
             + (2 * P / Q ** 3)[:, None, None] * gQ[:, :, None] * gQ[:, None, :])
    return g, H


#: vertices per chunk of :func:`vertex_energy_hessian` (its (n, 6, 6)
#: temporaries: 110 MB for the whole 81,920-facet sphere at once)
VERTEX_CHUNK = 8192


def vertex_energy_hessian(s, A, F, N, name, m=None):
    """Hessian (nv, 7, 7) of the vertex energies ``E_v`` of method ``name`` in
    the variables ``(A, F, N)`` (see :func:`curvature._vertex_energy`),
    over chunks of :data:`VERTEX_CHUNK` vertices."""
    kind, h0, old = C._kind(s, name)
    nv = s.nv
    M = np.zeros((nv, 7, 7))
    for lo in range(0, nv, VERTEX_CHUNK):
        sl = slice(lo, lo + VERTEX_CHUNK)
        _energy_hessian_rows(M[sl], kind, None if h0 is None else h0[sl],
                             A[sl], F[sl], N[sl])
    np.nan_to_num(M, copy=False)
    if old:
        M[C._skipped(s, m)] = 0.0
    return M


def _energy_hessian_rows(M, kind, h0, A, F, N):
    """:func:`vertex_energy_hessian` of some vertices, into their rows M (n, 7, 7)."""
    nv = len(A)
    I3 = np.eye(3)
    FF = np.einsum("ij,ij->i", F, F)
    FN = np.einsum("ij,ij->i", F, N)
    NN = np.einsum("ij,ij->i", N, N)
    with np.errstate(all="ignore"):
        if kind == "plain":                        # 0.75 F·F / A
            M[:, 1:4, 1:4] = (1.5 / A)[:, None, None] * I3
            M[:, 0, 1:4] = M[:, 1:4, 0] = -1.5 * F / (A ** 2)[:, None]
            M[:, 0, 0] = 1.5 * FF / A ** 3
        elif kind == "eff":                        # 0.75 A q, q = F·F / N·N
            qF = 2 * F / NN[:, None]
            qN = -2 * (FF / NN ** 2)[:, None] * N
            qFF = (2 / NN)[:, None, None] * I3
            qFN = -4 * F[:, :, None] * N[:, None, :] / (NN ** 2)[:, None, None]
            qNN = (-2 * FF / NN ** 2)[:, None, None] * I3 \
                + (8 * FF / NN ** 3)[:, None, None] * N[:, :, None] * N[:, None, :]
            a = (0.75 * A)[:, None, None]
            M[:, 1:4, 1:4] = a * qFF
            M[:, 1:4, 4:7] = a * qFN
            M[:, 4:7, 1:4] = a * np.swapaxes(qFN, 1, 2)
            M[:, 4:7, 4:7] = a * qNN
            M[:, 0, 1:4] = M[:, 1:4, 0] = 0.75 * qF
            M[:, 0, 4:7] = M[:, 4:7, 0] = 0.75 * qN
        else:                                      # (h − h0)² A / 3, h = 1.5 P/Q
            Z = np.zeros((nv, 3))
            Zm = np.zeros((nv, 6, 6))
            swap = Zm.copy()
            swap[:, :3, 3:] = swap[:, 3:, :3] = I3
            if kind == "norm":                     # P = F·F, Q = F·N
                ok = FN != 0
                P, gP = FF, np.hstack([2 * F, Z])
                HP = Zm.copy()
                HP[:, :3, :3] = 2 * I3
                Q, gQ, HQ = FN, np.hstack([N, F]), swap
            else:                                  # P = F·N, Q = N·N
                ok = NN > 0
                P, gP, HP = FN, np.hstack([N, F]), swap
                Q, gQ = NN, np.hstack([Z, 2 * N])
                HQ = Zm.copy()
                HQ[:, 3:, 3:] = 2 * I3
            gr, Hr = _ratio(P, gP, HP, Q, gQ, HQ)
            h = 1.5 * P / Q
            gh, Hh = 1.5 * gr, 1.5 * Hr
            d = h - (h0 if h0 is not None else 0.0)
            M[:, 1:, 1:] = (2 * A / 3)[:, None, None] * (gh[:, :, None] * gh[:, None, :]
                                                         + d[:, None, None] * Hh)
            M[:, 0, 1:] = M[:, 1:, 0] = (2 * d / 3)[:, None] * gh
            M[~ok] = 0.0


#: facets per chunk of :func:`star_hessian`: the jets' (m, 9, 9) temporaries of a
#: chunk stay a few MB (the whole surface at once: about 0.8 GB at 81,920 facets;
#: 2,048 rather than 4,096: 20 MB less at the peak of the bending Hessian there,
#: no slower)
CHUNK = 2048


def star_hessian(t, M, dA, dF, dN, basis=None):
    """Hessian of ``Σ_v φ_v(A_v, F_v, N_v)`` given the per-vertex Hessians
    M (nv, 7, 7) and first derivatives ``dA`` (nv,), ``dF``, ``dN`` (nv, 3).

    The facet terms and the Jacobian rows are computed over chunks of
    :data:`CHUNK` facets (both are sums over facets) and assembled once."""
    s = t.surface
    nv, Fall = s.nv, s.F
    Pall = facet_points(t)
    nf = len(Pall)
    H2parts, Jparts = [], []
    rows = SR.StarRows(Fall, basis, 7) if SR.applies(basis) else None
    for lo in range(0, max(nf, 1), CHUNK):
        Fc, P = Fall[lo:lo + CHUNK], Pall[lo:lo + CHUNK]
        m = len(Fc)
        x, N2, L, Aj = _facet_jets(P)
        # curvature of the star sums: α A_f + Σ_c λ_c · ∇_c A_f + ½ Λ · N_f
        lam = dF[Fc]                                                  # (m, 3, 3)
        e = [x[2] - x[1], x[0] - x[2], x[1] - x[0]]
        w = J.cross_const(e[0], lam[:, 0]) + J.cross_const(e[1], lam[:, 1]) \
            + J.cross_const(e[2], lam[:, 2])
        psi = J.dot(N2, w) * _inverse(L * 2.0)
        H = (Aj.H * dA[Fc].sum(axis=1)[:, None, None] + psi.H
             + 0.5 * N2.hc(dN[Fc].sum(axis=1)))
        H2parts.append(_elements(nv, Fc, H, basis))
        # Gauss–Newton part through the Jacobian of (A_v, F_v, N_v)
        blocks = np.empty((m, 3, 7, 9))
        blocks[:, :, 0, :] = Aj.g[:, None, :]
        for c in range(3):
            blocks[:, c, 1:4, :] = Aj.H[:, 3 * c:3 * c + 3, :]      # ∂F_c/∂x = ∂²A/∂x_c∂x
        blocks[:, :, 4:7, :] = 0.5 * N2.J[:, None]
        if rows is not None:          # straight into the CSR pattern (star_rows)
            U = basis.B[Fc][:, :, :, 0]                                   # (m, 3, 3)
            vals = np.einsum("mcibk,mbk->mcib", _finite(blocks).reshape(m, 3, 7, 3, 3), U)
            rows.add_chunk(lo, Fc, vals)
            continue
        ridx = (7 * Fc[:, :, None] + np.arange(7)).reshape(m, 21)
        Jparts.append(_rows(7 * nv, ridx, Fc, blocks.reshape(m, 21, 3, 3), nv, basis))
    # (the last chunk's jets and blocks, 20 MB at 4,096 facets, go before the products)
    x = N2 = L = Aj = lam = e = w = psi = H = blocks = None
    if rows is not None:        # (Jᵀ (diag(M) J) with diag(M) J in J's pattern)
        GN = (rows.matrix().T @ rows.block_product(_finite(M))).tocsr()
    else:
        GN = _gauss_newton(_add(Jparts), M)
    return GN + _add(H2parts)


def _add(parts):
    """Sum of sparse matrices of one shape (COO entries concatenated, one conversion)."""
    if len(parts) == 1:
        return parts[0].tocsr()
    coo = [p.tocoo() for p in parts]
    return sp.csr_matrix((np.concatenate([c.data for c in coo]),
                          (np.concatenate([c.row for c in coo]),
                           np.concatenate([c.col for c in coo]))), shape=coo[0].shape)


def vertex_hessian(t, m, idx, w, basis=None):
    """Hessian of ``Σ_v w_v E_v`` for the squared mean curvature methods."""
    s = t.surface
    C._check_supported(s)
    A, F, N = C.star_sums(t)
    rows, Pm = C.mirror_projector(s, m)
    C.check_old_gradient(s, m, rows)
    F, N = C._project(rows, Pm, F), C._project(rows, Pm, N)
    _, dF, dN, dA = C._vertex_energy(s, A, F, N, m.method, m)
    dF, dN = C._project(rows, Pm, dF), C._project(rows, Pm, dN)
    wv = C.vertex_weights(s.nv, idx, w)
    M = vertex_energy_hessian(s, A, F, N, m.method, m)
    M *= wv[:, None, None]
    if len(rows):                      # E(A, P F, P N): M -> Tᵀ M T, T = diag(1, P, P)
        T = np.zeros((len(rows), 7, 7))
        T[:, 0, 0] = 1.0
        T[:, 1:4, 1:4] = T[:, 4:7, 4:7] = Pm
        M[rows] = np.einsum("nji,njk,nkl->nil", T, M[rows], T)
    return star_hessian(t, M, dA * wv, dF * wv[:, None], dN * wv[:, None], basis)


def legacy_hessian(t, basis=None):
    """Hessian of the legacy SQUARED_CURVATURE vertex method (unit weights)."""
    s = t.surface
    m = C._Legacy(C._LEGACY[s.curvature_mode])
    return vertex_hessian(t, m, np.arange(s.nv), np.ones(s.nv), basis)


# -- mean_curvature_integral ----------------------------------------------------------------------

def mci_hessian(t, m, idx, w, basis=None):
    """Hessian of ``Σ_e w_e ½ L_e θ_e``: a 12×12 block per edge over its
    ends and the third vertices of its two facets."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    ok, e, f1, f2 = C._dihedral(t, idx)
    w = np.asarray(w, float)[ok]
    tail, head = s.E[e, 0], s.E[e, 1]
    k = s.F[f1].sum(axis=1) - tail - head
    l_ = s.F[f2].sum(axis=1) - tail - head
    verts = np.stack([tail, head, k, l_], axis=1)
    x = J.points(s.X[verts])
    d = x[1] - x[0]
    N1 = J.cross(d, x[2] - x[0])                 # f1 runs tail → head → k
    N2 = J.cross(x[0] - x[1], x[3] - x[1])       # f2 runs head → tail → l
    L = J.norm(d)
    u = d * _inverse(L)
    if m.method == "mean_curvature_integral_a":           # ½ L tan θ (REF's "_a")
        theta = J.dot(u, J.cross(N1, N2)) * _inverse(J.dot(N1, N2))
    else:
        theta = J.atan2(J.dot(u, J.cross(N1, N2)), J.dot(N1, N2))
    E = (L * theta) * (0.5 * w)
    return _elements(s.nv, verts, E.H, basis)


# -- Gaussian curvature -------------------------------------------------------------------------

def _angle_jets(x):
    out = []
    for a in range(3):
        u = x[(a + 1) % 3] - x[a]
        v = x[(a + 2) % 3] - x[a]
        out.append(J.atan2(J.norm(J.cross(u, v)), J.dot(u, v)))
    return out


def _gauss_hessian(t, idx, w, square, basis):
    s = t.surface
    if square:
        C._check_closed(s, "sq_gauss_curvature", True)
    else:
        C._check_supported(s)
    K, A, P, _ = C._gauss(t)
    nv, Fc = s.nv, s.F
    nf = len(P)
    wv = C.vertex_weights(nv, idx, w)
    x, _, _, Aj = _facet_jets(P)
    ang = _angle_jets(x)
    with np.errstate(all="ignore"):
        if square:
            dK = 6 * K / A * wv
            dA = -3 * K * K / (A * A) * wv
        else:
            dK, dA = wv, np.zeros(nv)
    H = Aj.H * dA[Fc].sum(axis=1)[:, None, None]
    for c in range(3):
        H = H - dK[Fc[:, c]][:, None, None] * ang[c].H          # K_v = 2π − Σ angles
    H2 = _elements(nv, Fc, H, basis)
    if not square:
        return H2
    blocks = np.empty((nf, 3, 2, 9))
    for c in range(3):
        blocks[:, c, 0, :] = -ang[c].g
    blocks[:, :, 1, :] = Aj.g[:, None, :]
    ridx = (2 * Fc[:, :, None] + np.arange(2)).reshape(nf, 6)
    Jm = _rows(2 * nv, ridx, Fc, blocks.reshape(nf, 6, 3, 3), nv, basis)
    M = np.empty((nv, 2, 2))
    with np.errstate(all="ignore"):
        M[:, 0, 0] = 6 / A
        M[:, 0, 1] = M[:, 1, 0] = -6 * K / A ** 2
        M[:, 1, 1] = 6 * K * K / A ** 3
    return _gauss_newton(Jm, M * wv[:, None, None]) + H2


def star_gauss_hessian(t, m, idx, w, basis=None):
    return _gauss_hessian(t, idx, w, False, basis)


def sq_gauss_hessian(t, m, idx, w, basis=None):
    return _gauss_hessian(t, idx, w, True, basis)


# -- cotan_sq_mean_curvature ---------------------------------------------------------------------

def cotan_hessian(t, m, idx, w, basis=None):
    """Hessian of ``Σ_v w_v φ_v`` with ``φ = |S|²/(16 A)`` (MDSB; see
    :func:`curvature.cotan_values`) and, with ``h_zero``, ``− (h0/2) S·N/|N|
    + h0² A`` (N the star's area vector ``Σ_f ½ N2_f``): star sums
    ``y = (S, A)`` or ``(S, A, N)``."""
    s = t.surface
    C._check_closed(s, "cotan_sq_mean_curvature")
    P, cot, _, _, _, Sv, Av = C._cotan_parts(t)
    nv, Fc = s.nv, s.F
    nf = len(P)
    wv = C.vertex_weights(nv, idx, w)
    x, N2, _, Aj = _facet_jets(P)
    cj = []
    for a in range(3):
        u = x[(a + 1) % 3] - x[a]
        v = x[(a + 2) % 3] - x[a]
        cj.append(J.dot(u, v) * _inverse(J.norm(J.cross(u, v))))
    Sc, Am = [], []
    obtuse = cot < 0
    any_obt = obtuse.any(axis=1)
    for c in range(3):
        c1, c2 = (c + 1) % 3, (c + 2) % 3
        Sc.append((x[c] - x[c1]) * cj[c2] + (x[c] - x[c2]) * cj[c1])
        eij, eik = x[c1] - x[c], x[c2] - x[c]
        vor = (J.dot(eij, eij) * cj[c2] + J.dot(eik, eik) * cj[c1]) * 0.125
        frac = np.where(obtuse[:, c], 0.5, 0.25)
        Am.append(J.S(np.where(any_obt, frac * Aj.v, vor.v),
                      np.where(any_obt[:, None], frac[:, None] * Aj.g, vor.g),
                      np.where(any_obt[:, None, None], frac[:, None, None] * Aj.H, vor.H)))
    h0 = C._h_zero(s, "cotan_sq_mean_curvature")
    r = 4 if h0 is None else 7
    with np.errstate(all="ignore"):
        SS = np.einsum("ij,ij->i", Sv, Sv)
        dS = Sv / (8 * Av)[:, None] * wv[:, None]
        dA = -SS / (16 * Av * Av) * wv
    dS, dA = np.nan_to_num(dS), np.nan_to_num(dA)
    if h0 is not None:
        nh, nN = C._cotan_normals(t, Fc)
        Sn = np.einsum("ij,ij->i", Sv, nh)
        dS = dS - (0.5 * h0 * wv)[:, None] * nh
        dA = dA + h0 * h0 * wv
        with np.errstate(all="ignore"):
            dN = np.nan_to_num((Sv - nh * Sn[:, None]) / nN[:, None]) * (-0.5 * h0 * wv)[:, None]
    H = np.zeros((nf, 9, 9))
    for c in range(3):
        H += Sc[c].hc(dS[Fc[:, c]]) + dA[Fc[:, c]][:, None, None] * Am[c].H
    if h0 is not None:                                  # N_v = Σ_f ½ N2_f at every corner
        H += N2.hc(0.5 * dN[Fc].sum(axis=1))
    H2 = _elements(nv, Fc, H, basis)
    blocks = np.zeros((nf, 3, r, 9))
    for c in range(3):
        blocks[:, c, :3, :] = Sc[c].J
        blocks[:, c, 3, :] = Am[c].g
        if h0 is not None:
            blocks[:, c, 4:, :] = 0.5 * N2.J
    ridx = (r * Fc[:, :, None] + np.arange(r)).reshape(nf, 3 * r)
    Jm = _rows(r * nv, ridx, Fc, blocks.reshape(nf, 3 * r, 3, 3), nv, basis)
    M = np.zeros((nv, r, r))
    with np.errstate(all="ignore"):
        M[:, :3, :3] = (1 / (8 * Av))[:, None, None] * np.eye(3)
        M[:, :3, 3] = M[:, 3, :3] = -Sv / (8 * Av ** 2)[:, None]
        M[:, 3, 3] = SS / (8 * Av ** 3)
        if h0 is not None:
            # −(h0/2) S·n̂: ∂²/∂S∂N = −(h0/2)(I − n̂n̂ᵀ)/|N|, and ∂²/∂N² = −(h0/2) ∇²(S·N/|N|)
            # with ∇²(S·N/|N|) = [3(S·n̂) n̂n̂ᵀ − (S·n̂) I − S n̂ᵀ − n̂ Sᵀ] / |N|²
            eye = np.eye(3)
            Pn = eye - nh[:, :, None] * nh[:, None, :]
            M[:, :3, 4:] = (-0.5 * h0 / nN)[:, None, None] * Pn
            M[:, 4:, :3] = M[:, :3, 4:]
            SnT = Sv[:, :, None] * nh[:, None, :]
            M[:, 4:, 4:] = (-0.5 * h0 / nN ** 2)[:, None, None] * (
                3 * Sn[:, None, None] * nh[:, :, None] * nh[:, None, :]
                - Sn[:, None, None] * eye - SnT - SnT.transpose(0, 2, 1))
    return _gauss_newton(Jm, M * wv[:, None, None]) + H2


# ---------------------------------------------------------------------------
# the registry entries of the curvature family (values and gradients in
# :mod:`pyevolver.methods.curvature`, Hessians here)

def plane_constraints_only(s) -> bool:
    """False where a constrained vertex is on a curved constraint: the
    gradient holds the mirror projectors constant there (as REF), so its
    derivative has terms in the projectors' derivatives that
    :func:`vertex_hessian` leaves out; ``hessian`` then takes differences of
    the gradient."""
    if not s.vcon:
        return True
    rows = np.nonzero(constrained_vertices(s))[0]
    return not (len(rows) and curved_constraints(s, rows))


for _name in C.VERTEX_METHODS:
    register_method(_name, "vertex", C.vertex_values, C.vertex_gradient, vertex_hessian,
                    hessian_applies=plane_constraints_only)
for _name in ("mean_curvature_integral", "mean_curvature_integral_a"):
    register_method(_name, "edge", C.mci_values, C.mci_gradient, mci_hessian)
register_method("star_gauss_curvature", "vertex", C.star_gauss_values, C.star_gauss_gradient,
                star_gauss_hessian)
register_method("sq_gauss_curvature", "vertex", C.sq_gauss_values, C.sq_gauss_gradient,
                sq_gauss_hessian)
register_method("cotan_sq_mean_curvature", "vertex", C.cotan_values, C.cotan_gradient,
                cotan_hessian)
register_method("circle_willmore", "vertex", C.circle_willmore_values, C.circle_willmore_gradient,
                no_hessian="Bobenko's energy is not smooth (REF has no Hessian for it); "
                           "use bfgs (or g)")
