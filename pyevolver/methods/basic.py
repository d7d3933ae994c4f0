"""The built-in area, volume, length and integral methods (the Evolver's
``facet_area``, ``facet_volume``, ``edge_length``, ``edge_area``,
``edge_tension``, ``facet_tension`` and the scalar / vector integrals): values,
analytic gradients and Hessians.

Discretisations (Surface Evolver manual, "Energies" chapter):

* area of triangle ``(x0, x1, x2)`` with unit normal ``n``:
  ``dA/dx0 = 1/2 n x (x2 - x1)`` (cyclic);
* z-flux volume ``v = (z0+z1+z2)/6 * cz`` with
  ``cz = (x1-x0)(y2-y0) - (y1-y0)(x2-x0)``; symmetric content
  ``v = x0 . (x1 x x2) / 6``;
* gravity ``g = (z0^2+z1^2+z2^2+z0z1+z1z2+z0z2)/24 * cz``;
* edge and facet integrals by Gauss quadrature, differentiated through the
  symbolic Jacobian of the integrand.
"""
from __future__ import annotations

import numpy as np

from ..errors import UnsupportedError
from ..geometry import kernels as G
from . import axis_major as AM, metric as MT
from .jets import skew
from ..model.formulas import located
from ._common import (assemble, assemble_projected, corner_scatter, edge_pullback, facet_points,
                      finite, group_blocks, has_group_maps, n2_grad_dot, scatter)
from .registry import register_method

# ---------------------------------------------------------------------------
# values


def _eu_area(ctx):
    """(nf,) Euclidean facet areas: REF's named methods (``facet_area``,
    ``edge_length``, the tensions) measure Euclidean under a METRIC, only the
    default energy and ``metric_facet_area`` / ``metric_edge_length`` use it."""
    return getattr(ctx, "euclidean_facet_area", ctx.facet_area)


def _eu_length(ctx):
    if ctx.surface.metric is None:
        return ctx.edge_length
    return np.sqrt(np.einsum("ij,ij->i", ctx.edge_vec, ctx.edge_vec))


def _facet_area(ctx, m, idx):
    return _eu_area(ctx)[idx]


def _facet_volume(ctx, m, idx):
    return ctx.facet_volume[idx]


def _edge_length(ctx, m, idx):
    return _eu_length(ctx)[idx]


def _facet_tension(ctx, m, idx):
    return _eu_area(ctx)[idx] * ctx.surface.facet_tension[idx]


def _vertex_scalar_integral(ctx, m, idx):
    X = ctx.surface.X[idx]
    return ctx.eval_points(m.scalar, X, "vertex", idx)


def _facet_scalar_integral(ctx, m, idx):
    pts = G.facet_quadrature_points(ctx.facet_x0[idx], ctx.facet_S[idx])
    n = len(idx)
    vals = ctx.eval_points(m.scalar, pts.reshape(-1, pts.shape[-1]), "facet",
                           np.repeat(idx, 12)).reshape(n, 12)
    return vals @ G.TRI6_W * ctx.facet_area[idx]


def _facet_vector_integral(ctx, m, idx):
    pts = G.facet_quadrature_points(ctx.facet_x0[idx], ctx.facet_S[idx])
    n = len(idx)
    flat = pts.reshape(-1, pts.shape[-1])
    rep = np.repeat(idx, 12)
    N2 = ctx.facet_N2[idx]
    total = np.zeros(n)
    for k, comp in enumerate(m.vector or []):
        q = ctx.eval_points(comp, flat, "facet", rep).reshape(n, 12) @ G.TRI6_W
        total += 0.5 * q * N2[:, k]
    return total


def _edge_scalar_integral(ctx, m, idx):
    x0 = ctx.surface.X[ctx.surface.E[idx, 0]]
    d = ctx.edge_vec[idx]
    pts = G.edge_quadrature_points(x0, d)
    n = len(idx)
    vals = ctx.eval_points(m.scalar, pts.reshape(-1, pts.shape[-1]), "edge",
                           np.repeat(idx, 2)).reshape(n, 2)
    return vals @ G.GL2_W * ctx.edge_length[idx]


def _edge_vector_integral(ctx, m, idx):
    return ctx.edge_vector_integral(m.vector or [], idx)



# ---------------------------------------------------------------------------
# gradients


def facet_area_grad(t, euclidean=False):
    """Per-corner gradients (nf, 3, 3) of facet areas (in the surface's
    metric unless ``euclidean``)."""
    if t.surface.metric is not None and not euclidean:
        return MT.facet_area_grad(t)
    if AM.available(t):                 # (the same numbers, fewer numpy calls)
        return AM.facet_major(AM.area_grad(t))
    P = facet_points(t)
    N2 = t.facet_N2
    with np.errstate(all="ignore"):
        n = N2 / np.linalg.norm(N2, axis=1)[:, None]
    n = finite(n)
    g = np.empty_like(P)
    g[:, 0] = 0.5 * G.cross(n, P[:, 2] - P[:, 1])      # (np.cross's products, less overhead)
    g[:, 1] = 0.5 * G.cross(n, P[:, 0] - P[:, 2])
    g[:, 2] = 0.5 * G.cross(n, P[:, 1] - P[:, 0])
    return g


def _cz_grad(P):
    """d cz / d corner (nf, 3, 3) for cz = (x1-x0)(y2-y0) - (y1-y0)(x2-x0)."""
    x, y = P[..., 0], P[..., 1]
    g = np.zeros_like(P)
    g[:, 0, 0] = y[:, 1] - y[:, 2]
    g[:, 1, 0] = y[:, 2] - y[:, 0]
    g[:, 2, 0] = y[:, 0] - y[:, 1]
    g[:, 0, 1] = x[:, 2] - x[:, 1]
    g[:, 1, 1] = x[:, 0] - x[:, 2]
    g[:, 2, 1] = x[:, 1] - x[:, 0]
    return g


def facet_volume_grad(t, symmetric):
    """Per-corner gradients (nf, 3, 3) of facet volume contributions."""
    P = facet_points(t)
    if symmetric:
        g = np.empty_like(P)
        g[:, 0] = G.cross(P[:, 1], P[:, 2]) / 6.0
        g[:, 1] = G.cross(P[:, 2], P[:, 0]) / 6.0
        g[:, 2] = G.cross(P[:, 0], P[:, 1]) / 6.0
        return g
    cz = t.facet_N2[:, 2]
    Z = P[:, :, 2].sum(axis=1)
    g = _cz_grad(P) * (Z / 6.0)[:, None, None]
    g[:, :, 2] += (cz / 6.0)[:, None]
    return g


def facet_gravity_grad(t) -> np.ndarray:
    """Per-corner gradients (nf, 3, 3) of the facets' gravity integrals."""
    P = facet_points(t)
    z = P[..., 2]
    S = (z * z).sum(axis=1) + z[:, 0] * z[:, 1] + z[:, 1] * z[:, 2] + z[:, 0] * z[:, 2]
    cz = t.facet_N2[:, 2]
    g = _cz_grad(P) * (S / 24.0)[:, None, None]
    dS = np.stack([2 * z[:, 0] + z[:, 1] + z[:, 2], 2 * z[:, 1] + z[:, 0] + z[:, 2],
                   2 * z[:, 2] + z[:, 0] + z[:, 1]], axis=1)
    g[:, :, 2] += dS * (cz / 24.0)[:, None]
    return g


def edge_vector_integral_grad(t, comps, idx, sign=None):
    """Gradient of sum_e sign_e * int_e Q . dl (2-point Gauss-Legendre)."""
    s = t.surface
    n = len(idx)
    if n == 0:
        return np.zeros((s.nv, 3))
    x0 = s.X[s.E[idx, 0]]
    d = t.edge_vec[idx]
    pts = G.edge_quadrature_points(x0, d)            # (n, 2, 3)
    flat = pts.reshape(-1, 3)
    rep = np.repeat(idx, 2)
    env_coords = {"x": flat[:, 0], "y": flat[:, 1], "z": flat[:, 2]}
    Q = np.zeros((n, 2, 3))
    J = np.zeros((n, 2, 3, 3))                        # J[..., k, j] = dQ_k/dx_j
    env = _Env(t, env_coords, rep)
    with located(getattr(comps, "what", ""), getattr(comps, "line", None)):
        for k, comp in enumerate(comps[:3]):
            Q[:, :, k] = comp.values(env.params, env.coords, len(flat)).reshape(n, 2)
            Jk = comp.gradient(env.params, env.coords, len(flat))
            J[:, :, k, :] = Jk.reshape(n, 2, 3)
    w = G.GL2_W
    tq = G.GL2_T
    # dI/dx_j at quadrature point q: sum_k J[k, j] d_k
    Jd = np.einsum("nqkj,nk->nqj", J, d)
    g_tail = np.einsum("q,nqj->nj", w * (1 - tq), Jd) - np.einsum("q,nqj->nj", w, Q)
    g_head = np.einsum("q,nqj->nj", w * tq, Jd) + np.einsum("q,nqj->nj", w, Q)
    if sign is not None:
        g_tail = g_tail * sign[:, None]
        g_head = g_head * sign[:, None]
    return scatter(s.nv, np.concatenate([s.E[idx, 0], s.E[idx, 1]]),
                   np.concatenate([g_tail, g_head]))


class _Env:
    def __init__(self, t, coords, rep):
        s = t.surface
        self.params = s.param_env()
        self.coords = dict(coords)
        for (et, name), arr in s.extra.items():
            if et == "edge" and arr.ndim == 1:
                self.coords[name] = arr[rep]


def edge_length_grad(t, idx: np.ndarray, weights: np.ndarray, euclidean=False) -> np.ndarray:
    """Gradient (nv, 3) of ``Σ_e w_e |e|`` over the edges ``idx`` (in the
    surface's metric unless ``euclidean``)."""
    if t.surface.metric is not None and not euclidean:
        return MT.edge_length_grad(t, idx, weights)
    s = t.surface
    d = t.edge_vec[idx]
    L = _eu_length(t)[idx]
    with np.errstate(all="ignore"):
        u = np.nan_to_num(d / L[:, None]) * weights[:, None]
    return scatter(s.nv, np.concatenate([s.E[idx, 0], s.E[idx, 1]]),
                   np.concatenate([-u, edge_pullback(t, idx, u)]))


def _facet_vector_integral_grad(t, comps, idx, w):
    """Gradient of sum_f w_f * 1/2 sum_q W_q Q(x_q) . N2_f."""
    s = t.surface
    n = len(idx)
    if n == 0:
        return np.zeros((s.nv, 3))
    P = facet_points(t)[idx]
    B = G.TRI6_B
    pts = np.einsum("qc,ncj->nqj", B, P)             # (n, 12, 3)
    flat = pts.reshape(-1, 3)
    coords = {"x": flat[:, 0], "y": flat[:, 1], "z": flat[:, 2]}
    params = s.param_env()
    Q = np.zeros((n, 12, 3))
    J = np.zeros((n, 12, 3, 3))
    for k, comp in enumerate(comps[:3]):
        Q[:, :, k] = comp.values(params, coords, len(flat)).reshape(n, 12)
        J[:, :, k, :] = comp.gradient(params, coords, len(flat)).reshape(n, 12, 3)
    N2 = t.facet_N2[idx]
    W = G.TRI6_W
    # term 1: dQ/dx_q . N2 distributed to corners by barycentric weight B[q, c]
    JN = np.einsum("nqkj,nk->nqj", J, N2)             # (n, 12, 3)
    g1 = 0.5 * np.einsum("q,qc,nqj->ncj", W, B, JN)
    # term 2: Qbar . dN2/dx_c
    Qbar = 0.5 * np.einsum("q,nqk->nk", W, Q)
    g2 = n2_grad_dot(P, Qbar)
    per = (g1 + g2) * w[:, None, None]
    return scatter(s.nv, s.F[idx].ravel(), per.reshape(-1, 3))


def _point_coords(t, P, etype, idx):
    """Coordinates and the elements' scalar extra attributes at points P (n, 3)."""
    s = t.surface
    coords = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
    for (et, name), arr in s.extra.items():
        if et == etype and arr.ndim == 1:
            coords[name] = arr[idx]
    return coords


def _vertex_scalar_gradient(t, m, idx, w):
    """Gradient (nv, 3) of ``Σ_v w_v f(x_v)``: ``w_v ∇f(x_v)`` (manual:
    vertex_scalar_integral, the integrand evaluated at the vertex)."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    X = s.X[idx]
    if s.sdim != 3:
        raise UnsupportedError("the gradient of vertex_scalar_integral outside 3 dimensions")
    grad = m.scalar.gradient(s.param_env(), _point_coords(t, X, "vertex", idx), len(idx))
    return scatter(s.nv, idx, grad * np.asarray(w, float)[:, None])


def _facet_scalar_gradient(t, m, idx, w):
    """Gradient (nv, 3) of ``Σ_f w_f A_f Σ_q W_q f(x_q)`` (the degree-6 rule
    of :func:`_facet_scalar_integral`, x_q = Σ_c B_qc x_c): the quadrature
    mean times ∇A_f plus ``A_f Σ_q W_q B_qc ∇f(x_q)`` at corner c."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    n = len(idx)
    if n == 0:
        return np.zeros((s.nv, 3))
    if s.sdim != 3:
        raise UnsupportedError("the gradient of facet_scalar_integral outside 3 dimensions")
    P = facet_points(t)[idx]
    B, W = G.TRI6_B, G.TRI6_W
    flat = np.einsum("qc,ncj->nqj", B, P).reshape(-1, 3)
    coords = _point_coords(t, flat, "facet", np.repeat(idx, len(W)))
    params = s.param_env()
    f = m.scalar.values(params, coords, len(flat)).reshape(n, len(W))
    df = m.scalar.gradient(params, coords, len(flat)).reshape(n, len(W), 3)
    A = t.facet_area[idx]
    per = (f @ W)[:, None, None] * facet_area_grad(t)[idx]
    per += A[:, None, None] * np.einsum("q,qc,nqj->ncj", W, B, df)
    per *= np.asarray(w, float)[:, None, None]
    return scatter(s.nv, s.F[idx].ravel(), per.reshape(-1, 3))



# ---------------------------------------------------------------------------
# Hessians


def facet_area_hessian(t, weights, basis=None, euclidean=False):
    """Hessian of ``Σ_f w_f A_f`` (3nv, 3nv).

    With ``N = (x1−x0)×(x2−x0)``, ``n = N/|N|`` and ``e_a`` the side opposite
    corner a (``e_0 = x2−x1`` cyclic), ``∂A/∂x_a = ½ n × e_a`` and

        ∂²A/∂x_a∂x_b = ½ ε_ab [n]x + [e_a]xᵀ (I − n nᵀ) [e_b]x / (2|N|)

    with ε_ab = +1 if b = a+2, −1 if b = a+1 (mod 3), 0 if a = b.
    """
    if t.surface.metric is not None and not euclidean:
        return MT.facet_area_hessian(t, weights, basis)
    s = t.surface
    P = facet_points(t)
    N2 = t.facet_N2
    L = np.linalg.norm(N2, axis=1)
    ok = (L > 0) & (weights != 0)
    P, N2, L, w = P[ok], N2[ok], L[ok], weights[ok]
    n = N2 / L[:, None]
    e = np.stack([P[:, 2] - P[:, 1], P[:, 0] - P[:, 2], P[:, 1] - P[:, 0]], 1)
    if basis is not None and basis.B.shape[2] == 1 and not has_group_maps(t):
        # one free direction u_v per vertex: contract in closed form,
        # u_aᵀ H_ab u_b = ½ ε_ab u_a·(n × u_b) + (w_a·w_b − (n·w_a)(n·w_b)) / (2|N|)
        # with w_a = e_a × u_a
        F = s.F[ok]
        U = basis.B[F][:, :, :, 0]                                   # (m, 3, 3)
        W = np.cross(e, U)
        nw = np.einsum("mi,mai->ma", n, W)
        K = np.einsum("mai,mbi->mab", W, W) - nw[:, :, None] * nw[:, None, :]
        K /= (2 * L)[:, None, None]
        nxU = np.cross(n[:, None, :], U)
        T3 = np.einsum("mai,mbi->mab", U, nxU)                     # u_a·(n × u_b)
        K[:, 0, 2] += 0.5 * T3[:, 0, 2]
        K[:, 1, 0] += 0.5 * T3[:, 1, 0]
        K[:, 2, 1] += 0.5 * T3[:, 2, 1]
        K[:, 0, 1] -= 0.5 * T3[:, 0, 1]
        K[:, 1, 2] -= 0.5 * T3[:, 1, 2]
        K[:, 2, 0] -= 0.5 * T3[:, 2, 0]
        K *= w[:, None, None]
        return assemble_projected(F, K[:, :, :, None, None], basis)
    # [e_a]x^T (I - n n^T) [e_b]x = (e_a.e_b) I - e_b e_a^T - c_a c_b^T, c_a = n x e_a
    c = np.cross(n[:, None, :], e)                                   # (m, 3, 3)
    dots = np.einsum("mai,mbi->mab", e, e)
    B = -(e[:, None, :, :, None] * e[:, :, None, None, :])           # (m, a, b, i, l)
    B -= c[:, :, None, :, None] * c[:, None, :, None, :]
    B[:, :, :, [0, 1, 2], [0, 1, 2]] += dots[:, :, :, None]
    B /= (2 * L)[:, None, None, None, None]
    nx = skew(n)
    eps = np.zeros((3, 3))
    for a in range(3):
        eps[a, (a + 2) % 3] = 1.0
        eps[a, (a + 1) % 3] = -1.0
    B += 0.5 * eps[None, :, :, None, None] * nx[:, None, None]
    B *= w[:, None, None, None, None]
    return assemble(s.nv, s.F[ok], group_blocks(t, B, ok), basis)


def edge_length_hessian(t, idx, weights, basis=None, euclidean=False):
    """Hessian of ``Σ_e w_e L_e``: blocks ``±(I − t tᵀ)/L``."""
    if t.surface.metric is not None and not euclidean:
        return MT.edge_length_hessian(t, idx, weights, basis)
    s = t.surface
    d = t.edge_vec[idx]
    L = _eu_length(t)[idx]
    ok = L > 0
    d, L, w, idx = d[ok], L[ok], np.asarray(weights)[ok], idx[ok]
    u = d / L[:, None]
    K = (np.eye(3)[None] - u[:, :, None] * u[:, None, :]) * (w / L)[:, None, None]
    B = np.stack([np.stack([K, -K], 1), np.stack([-K, K], 1)], 1)
    return assemble(s.nv, s.E[idx], group_blocks(t, B, edges=idx), basis)


def facet_volume_hessian(t, weights, symmetric, basis=None):
    """Hessian of ``Σ_f w_f v_f`` for the z-flux or symmetric facet volume."""
    s = t.surface
    P = facet_points(t)
    m = len(P)
    if basis is not None and basis.B.shape[2] == 1 and not has_group_maps(t):
        # one free direction u_v per vertex: second directional derivatives
        U = basis.B[s.F][:, :, :, 0]                                 # (m, 3, 3)
        K = np.zeros((m, 3, 3))
        if symmetric:
            # v = det[x0, x1, x2]/6: u_a in slot a, u_b in slot b, x_c in slot c
            for a in range(3):
                for b in range(3):
                    if a != b:
                        c = 3 - a - b
                        slots = [None, None, None]
                        slots[a], slots[b], slots[c] = U[:, a], U[:, b], P[:, c]
                        K[:, a, b] = np.einsum("mi,mi->m", slots[0],
                                               np.cross(slots[1], slots[2])) / 6.0
        else:
            # v = Z cz / 6: Z = Σ z, cz bilinear in (x, y)
            C = np.array([[0, 1, -1], [-1, 0, 1], [1, -1, 0]], float)
            Z = P[:, :, 2].sum(axis=1)
            dcz = _cz_grad(P)                                     # (m, 3, 3)
            du = dcz[:, :, 0] * U[:, :, 0] + dcz[:, :, 1] * U[:, :, 1]   # dcz_a · u_a
            uz = U[:, :, 2]
            xy = U[:, :, 0][:, :, None] * U[:, :, 1][:, None, :]     # u_ax u_by
            K = (Z[:, None, None] * (C[None] * xy + C.T[None] * xy.transpose(0, 2, 1))
                 + uz[:, :, None] * du[:, None, :] + du[:, :, None] * uz[:, None, :]) / 6.0
        K *= np.asarray(weights)[:, None, None]
        return assemble_projected(s.F, K[:, :, :, None, None], basis)
    B = np.zeros((m, 3, 3, 3, 3))
    if symmetric:
        # v = det[x0, x1, x2]/6: d²v/dx_a^i dx_b^j = ±ε_ijk x_c^k / 6
        for a in range(3):
            for b in range(3):
                if a == b:
                    continue
                c = 3 - a - b
                sign = 1.0 if (a, b, c) in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) else -1.0
                B[:, a, b] = sign * skew(P[:, c]).transpose(0, 2, 1) / 6.0
                # eps_ijk x^k = -[x]x_ij
    else:
        # v = (z0+z1+z2) cz / 6, cz bilinear in x and y
        C = np.array([[0, 1, -1], [-1, 0, 1], [1, -1, 0]], float)
        Z = P[:, :, 2].sum(axis=1)
        dcz = _cz_grad(P)                      # (m, 3, 3): d cz / d corner
        for a in range(3):
            for b in range(3):
                B[:, a, b, 0, 1] = Z * C[a, b] / 6.0
                B[:, a, b, 1, 0] = Z * C[b, a] / 6.0
                B[:, a, b, 2, 0] = dcz[:, b, 0] / 6.0
                B[:, a, b, 2, 1] = dcz[:, b, 1] / 6.0
                B[:, a, b, 0, 2] = dcz[:, a, 0] / 6.0
                B[:, a, b, 1, 2] = dcz[:, a, 1] / 6.0
    B *= np.asarray(weights)[:, None, None, None, None]
    return assemble(s.nv, s.F, group_blocks(t, B), basis)


def facet_gravity_hessian(t, weights, basis=None):
    """Hessian of ``Σ_f w_f g_f`` with ``g = S(z) cz / 24`` (see :mod:`.gradient`).

    ``S = Σ z_a² + Σ_{a<b} z_a z_b`` is quadratic in the heights and ``cz``
    bilinear in x and y, so the blocks are ``S/24 ∂²cz`` (xy-xy),
    ``∂S/∂z_a ∂cz/∂(x,y)_b / 24`` (z-xy) and ``(1 + δ_ab) cz / 24`` (z-z).
    """
    s = t.surface
    P = facet_points(t)
    m = len(P)
    z = P[:, :, 2]
    S = (z * z).sum(axis=1) + z[:, 0] * z[:, 1] + z[:, 1] * z[:, 2] + z[:, 0] * z[:, 2]
    dS = z + z.sum(axis=1)[:, None]               # ∂S/∂z_a = 2 z_a + Σ_{b≠a} z_b
    cz = t.facet_N2[:, 2]
    dcz = _cz_grad(P)
    C = np.array([[0, 1, -1], [-1, 0, 1], [1, -1, 0]], float)
    B = np.zeros((m, 3, 3, 3, 3))
    for a in range(3):
        for b in range(3):
            B[:, a, b, 0, 1] = S * C[a, b]
            B[:, a, b, 1, 0] = S * C[b, a]
            B[:, a, b, 2, 0] = dS[:, a] * dcz[:, b, 0]
            B[:, a, b, 2, 1] = dS[:, a] * dcz[:, b, 1]
            B[:, a, b, 0, 2] = dS[:, b] * dcz[:, a, 0]
            B[:, a, b, 1, 2] = dS[:, b] * dcz[:, a, 1]
            B[:, a, b, 2, 2] = (2.0 if a == b else 1.0) * cz
    B *= (np.asarray(weights) / 24.0)[:, None, None, None, None]
    return assemble(s.nv, s.F, group_blocks(t, B), basis)



# ---------------------------------------------------------------------------
# the registry entries


def _per_facet(t, idx, w):
    """(nf,) the weights ``w`` of facets ``idx`` summed per facet."""
    full = np.zeros(t.surface.nf)
    np.add.at(full, idx, w)
    return full


def _area_gradient(t, m, idx, w):
    return corner_scatter(t, facet_area_grad(t, True), _per_facet(t, idx, w))


def _area_hessian(t, m, idx, w, basis=None):
    return facet_area_hessian(t, _per_facet(t, idx, w), basis, euclidean=True)


def _volume_gradient(t, m, idx, w):
    s = t.surface
    return corner_scatter(t, facet_volume_grad(t, s.symmetric_content), _per_facet(t, idx, w))


def _volume_hessian(t, m, idx, w, basis=None):
    return facet_volume_hessian(t, _per_facet(t, idx, w), t.surface.symmetric_content, basis)


def _length_gradient(t, m, idx, w):
    return edge_length_grad(t, idx, w, True)


def _length_hessian(t, m, idx, w, basis=None):
    return edge_length_hessian(t, np.asarray(idx, np.int64), w, basis, euclidean=True)


def _facet_tension_gradient(t, m, idx, w):
    s = t.surface
    return corner_scatter(t, facet_area_grad(t, True),
                          _per_facet(t, idx, w * s.facet_tension[idx]))


def _edge_vector_gradient(t, m, idx, w):
    return edge_vector_integral_grad(t, m.vector or [], idx, w)


def _facet_vector_gradient(t, m, idx, w):
    return _facet_vector_integral_grad(t, m.vector or [], idx, w)


register_method("facet_area", "facet", _facet_area, _area_gradient, _area_hessian)
register_method("facet_volume", "facet", _facet_volume, _volume_gradient, _volume_hessian,
                hessian_applies=lambda s: s.periods is None)
register_method("edge_length", "edge", _edge_length, _length_gradient, _length_hessian)
register_method("edge_area", "edge", _edge_length, _length_gradient)
# the method edge_tension is the edge length, whatever the edges' tension (REF; the
# manual: "edge_tension or edge_length ... Length of edge")
register_method("edge_tension", "edge", _edge_length, _length_gradient, _length_hessian)
register_method("facet_tension", "facet", _facet_tension, _facet_tension_gradient)
register_method("vertex_scalar_integral", "vertex", _vertex_scalar_integral,
                _vertex_scalar_gradient)
register_method("facet_scalar_integral", "facet", _facet_scalar_integral, _facet_scalar_gradient)
register_method("facet_vector_integral", "facet", _facet_vector_integral, _facet_vector_gradient)
register_method("edge_scalar_integral", "edge", _edge_scalar_integral)
register_method("edge_vector_integral", "edge", _edge_vector_integral, _edge_vector_gradient)
