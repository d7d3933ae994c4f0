"""Analytic gradients of energies and constrained values w.r.t. vertices.

Every term of :class:`pyevolver.model.surface.Totals` has its gradient here; all
are checked against central finite differences in ``tests/test_gradient.py``.
Shapes: gradients are ``(nv, 3)`` arrays.

Discretisations (Surface Evolver manual, "Energies" chapter):

* area of triangle ``(x0, x1, x2)`` with unit normal ``n``:
  ``dA/dx0 = 1/2 n x (x2 - x1)`` (cyclic);
* z-flux volume ``v = (z0+z1+z2)/6 * cz`` with
  ``cz = (x1-x0)(y2-y0) - (y1-y0)(x2-x0)``; symmetric content
  ``v = x0 . (x1 x x2) / 6``;
* gravity ``g = (z0^2+z1^2+z2^2+z0z1+z1z2+z0z2)/24 * cz``;
* edge integrals by 2-point Gauss-Legendre, differentiated through the
  symbolic Jacobian of the integrand.
"""
from __future__ import annotations

import numpy as np

from ..geometry import kernels as G


def scatter(nv, idx, vecs):
    """Sum per-corner vectors ``vecs (m, 3)`` into vertices ``idx (m,)``."""
    out = np.empty((nv, 3))
    for k in range(3):
        out[:, k] = np.bincount(idx, weights=vecs[:, k], minlength=nv)
    return out


def _facet_points(t):
    """Unwrapped facet corners (nf, 3, 3)."""
    x0 = t.facet_x0
    S = t.facet_S
    return np.stack([x0, x0 + S[:, 0], x0 + S[:, 1]], axis=1)


def facet_area_grad(t):
    """Per-corner gradients (nf, 3, 3) of facet areas."""
    P = _facet_points(t)
    N2 = t.facet_N2
    with np.errstate(all="ignore"):
        n = N2 / np.linalg.norm(N2, axis=1)[:, None]
    n = np.nan_to_num(n)
    g = np.empty_like(P)
    g[:, 0] = 0.5 * np.cross(n, P[:, 2] - P[:, 1])
    g[:, 1] = 0.5 * np.cross(n, P[:, 0] - P[:, 2])
    g[:, 2] = 0.5 * np.cross(n, P[:, 1] - P[:, 0])
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
    P = _facet_points(t)
    if symmetric:
        g = np.empty_like(P)
        g[:, 0] = np.cross(P[:, 1], P[:, 2]) / 6.0
        g[:, 1] = np.cross(P[:, 2], P[:, 0]) / 6.0
        g[:, 2] = np.cross(P[:, 0], P[:, 1]) / 6.0
        return g
    cz = t.facet_N2[:, 2]
    Z = P[:, :, 2].sum(axis=1)
    g = _cz_grad(P) * (Z / 6.0)[:, None, None]
    g[:, :, 2] += (cz / 6.0)[:, None]
    return g


def facet_gravity_grad(t):
    P = _facet_points(t)
    z = P[..., 2]
    S = (z * z).sum(axis=1) + z[:, 0] * z[:, 1] + z[:, 1] * z[:, 2] + z[:, 0] * z[:, 2]
    cz = t.facet_N2[:, 2]
    g = _cz_grad(P) * (S / 24.0)[:, None, None]
    dS = np.stack([2 * z[:, 0] + z[:, 1] + z[:, 2], 2 * z[:, 1] + z[:, 0] + z[:, 2],
                   2 * z[:, 2] + z[:, 0] + z[:, 1]], axis=1)
    g[:, :, 2] += dS * (cz / 24.0)[:, None]
    return g


def _n2_grad_dot(P, D):
    """Per-corner gradients of D . N2, N2 = (x1-x0) x (x2-x0), D per facet."""
    g = np.empty_like(P)
    g[:, 1] = np.cross(P[:, 2] - P[:, 0], D)
    g[:, 2] = np.cross(D, P[:, 1] - P[:, 0])
    g[:, 0] = -g[:, 1] - g[:, 2]
    return g


def corner_scatter(t, per_corner, weights=None):
    """Scatter per-corner facet gradients (nf, 3, 3) to vertices."""
    s = t.surface
    if weights is not None:
        per_corner = per_corner * weights[:, None, None]
    return scatter(s.nv, s.F.ravel(), per_corner.reshape(-1, 3))


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
    from ..model.surface import located
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


def edge_length_grad(t, idx, weights):
    s = t.surface
    d = t.edge_vec[idx]
    L = t.edge_length[idx]
    with np.errstate(all="ignore"):
        u = np.nan_to_num(d / L[:, None]) * weights[:, None]
    return scatter(s.nv, np.concatenate([s.E[idx, 0], s.E[idx, 1]]), np.concatenate([-u, u]))


# ---------------------------------------------------------------------------
# totals


def content_edge_terms(t):
    """Per-edge content integrals: ``[(components, edge indices, signs)]``."""
    from ..model.surface import integral_edges
    return integral_edges(t.surface, "content")


def energy_gradient(t):
    """Gradient (nv, 3) of the total energy of :class:`Totals` ``t``."""
    s = t.surface
    if s.string:
        from ..model.string import energy_gradient as string_gradient
        return string_gradient(t)
    g = corner_scatter(t, facet_area_grad(t), s.facet_tension)
    et = s.eattr.get("tension")
    if et is not None and np.any(et):
        nz = np.nonzero(et)[0]
        g += edge_length_grad(t, nz, et[nz])
    from ..model.surface import integral_edges
    for comps, idx, sign in integral_edges(s, "energy"):
        g += edge_vector_integral_grad(t, comps, idx, sign)
    if "gap" in t.terms:
        g += gap_energy_grad(t)
    if "sq_curvature" in t.terms:
        from ..methods.curvature import legacy_gradient
        g += s.sq_curvature_modulus * legacy_gradient(t)
    b = s.bodies
    if b.n:
        if s.gravity_constant != 0 and s.gravity_on and np.any(b.density):
            w = s.gravity_constant * (b.facet_matrix.T @ b.density)
            g += corner_scatter(t, facet_gravity_grad(t), w)
        pmask = ~np.isnan(b.pressure)
        if pmask.any():
            vg = body_volume_gradients(t)
            g -= np.einsum("b,bvk->vk", b.pressure[pmask], vg[pmask])
    for q in s.quantities.values():
        if q.kind == "energy":
            g += quantity_gradient(t, q)
    return g


def gap_energy_grad(t):
    """Gradient of the gap energy of edges on CONVEX constraints.

    Per edge end e with constraint gradient g_e and edge vector s:
    ``T_e = k |s.g_e| |s| / (12 |g_e|)``; differentiated through s and
    through g_e (the symbolic Hessian of the constraint function).
    """
    from ..model.surface import convex_edges
    s = t.surface
    out = np.zeros((s.nv, 3))
    for c, idx in convex_edges(s):
        d = t.edge_vec[idx]
        L = t.edge_length[idx]
        params = s.param_env()
        for end in (0, 1):
            vi = s.E[idx, end]
            P = s.X[vi]
            coords = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
            gg = c.formula.gradient(params, coords, len(idx))
            H = c.formula.hessian(params, coords, len(idx))
            n = np.linalg.norm(gg, axis=1)
            h = np.einsum("ij,ij->i", d, gg)
            ok = n > 0
            with np.errstate(all="ignore"):
                dT_ds = (np.sign(h)[:, None] * gg * L[:, None]
                         + np.abs(h)[:, None] * d / L[:, None]) / (12 * n[:, None])
                dT_dg = L[:, None] / 12 * (np.sign(h)[:, None] * d / n[:, None]
                                           - np.abs(h)[:, None] * gg / n[:, None] ** 3)
            dT_ds = np.where(ok[:, None], np.nan_to_num(dT_ds), 0.0)
            dT_dg = np.where(ok[:, None], np.nan_to_num(dT_dg), 0.0)
            out += scatter(s.nv, np.concatenate([s.E[idx, 1], s.E[idx, 0], vi]),
                           np.concatenate([dT_ds, -dT_ds, np.einsum("nij,nj->ni", H, dT_dg)]))
    return s.gap_constant * out


def body_volume_gradients(t):
    """(nb, nv, 3) gradients of body volumes (content integrals included)."""
    s = t.surface
    if s.string:
        from ..model.string import volume_gradients
        return volume_gradients(t)
    b = s.bodies
    vg = facet_volume_grad(t, s.symmetric_content)
    out = np.zeros((b.n, s.nv, 3))
    Bm = b.facet_matrix.tocsr()
    if s.periods is not None:
        from ..model.surface import torus_lift_shifts
        D = torus_lift_shifts(s)
        P = _facet_points(t)
    content = content_edge_terms(t)
    for i in range(b.n):
        w = np.asarray(Bm.getrow(i).todense()).ravel()
        out[i] = corner_scatter(t, vg, w)
        if s.periods is not None:
            if s.symmetric_content:
                out[i] += corner_scatter(t, _n2_grad_dot(P, D[i]) / 6.0)
            else:
                Dz = np.zeros_like(D[i])
                Dz[:, 2] = D[i][:, 2]
                out[i] += corner_scatter(t, _n2_grad_dot(P, Dz) / 2.0)
        if content:
            # an edge's content counts for the body through each facet it is on
            idx, sgn, _ = s.topology()
            per_edge = np.zeros(s.ne)
            np.add.at(per_edge, idx.ravel(), (sgn * w[:, None]).ravel())
            for comps, eidx, sign in content:
                coef = sign * per_edge[eidx]
                nz = coef != 0
                if nz.any():
                    out[i] += edge_vector_integral_grad(t, comps, eidx[nz], coef[nz])
    return out


def quantity_gradient(t, q):
    """Gradient (nv, 3) of a named quantity's value (a FUNCTION quantity's:
    Σ_i ∂f/∂v_i ∇v_i over the method instances it reads)."""
    s = t.surface
    g = np.zeros((s.nv, 3))
    if q.function is not None:
        env = t.instance_values(q)
        names = list(env)
        d = q.function.gradient(s.param_env(), env, 1, names)[0]
        for di, n in zip(d, names):
            if di:
                g += (q.modulus * di) * quantity_gradient(t, s.quantities[n[:-6]])
        return g
    for m, etype, idx, sign in q.methods:
        w = np.ones(len(idx)) if sign is None else np.asarray(sign, float)
        w = w * m.modulus * q.modulus
        name = m.method
        if name == "facet_area":
            full = np.zeros(s.nf)
            np.add.at(full, idx, w)
            g += corner_scatter(t, facet_area_grad(t), full)
        elif name == "facet_volume":
            full = np.zeros(s.nf)
            np.add.at(full, idx, w)
            g += corner_scatter(t, facet_volume_grad(t, s.symmetric_content), full)
        elif name in ("edge_length", "edge_area"):
            g += edge_length_grad(t, idx, w)
        elif name == "facet_tension":
            full = np.zeros(s.nf)
            np.add.at(full, idx, w * s.facet_tension[idx])
            g += corner_scatter(t, facet_area_grad(t), full)
        elif name == "edge_tension":
            g += edge_length_grad(t, idx, w * s.edge_tension[idx])
        elif name == "edge_vector_integral":
            g += edge_vector_integral_grad(t, m.vector or [], idx, w)
        elif name == "facet_vector_integral":
            g += _facet_vector_integral_grad(t, m.vector or [], idx, w)
        else:
            from ..methods import GRADIENTS
            fn = GRADIENTS.get(name)
            if fn is None:
                from ..errors import UnsupportedError
                raise UnsupportedError(f"the gradient of method {name}")
            g += fn(t, m, np.asarray(idx, np.int64), w)
    return g


def _facet_vector_integral_grad(t, comps, idx, w):
    """Gradient of sum_f w_f * 1/2 sum_q W_q Q(x_q) . N2_f."""
    s = t.surface
    n = len(idx)
    if n == 0:
        return np.zeros((s.nv, 3))
    P = _facet_points(t)[idx]
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
    g2 = _n2_grad_dot(P, Qbar)
    per = (g1 + g2) * w[:, None, None]
    return scatter(s.nv, s.F[idx].ravel(), per.reshape(-1, 3))
