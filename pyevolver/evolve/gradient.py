"""Analytic gradients of the total energy and of constrained values
w.r.t. the vertices.

Every term of :class:`pyevolver.methods.totals.Totals` has its gradient here
or, for the named quantities, in the method's registry entry
(:mod:`pyevolver.methods.registry`); all are checked against central finite
differences in ``tests/evolve/test_gradient.py``.  Shapes: gradients are
``(nv, 3)`` arrays.  The discretisations of the built-in methods are stated
in :mod:`pyevolver.methods.basic`.
"""
from __future__ import annotations

import numpy as np

from ..constraints import integral_edges
from ..errors import UnsupportedError
from ..methods import axis_major as AM, string as SM
from ..methods._common import corner_scatter, scatter  # noqa: F401  (re-exported)
from ..methods._common import facet_points as _facet_points
from ..methods._common import n2_grad_dot as _n2_grad_dot
from ..methods.basic import (_cz_grad, edge_length_grad, edge_vector_integral_grad,  # noqa: F401
                             facet_area_grad, facet_gravity_grad, facet_volume_grad)
from ..methods.curvature import legacy_gradient
from ..methods.registry import lookup
from ..model.records import convex_edges, torus_lift_shifts

# ---------------------------------------------------------------------------
# totals


def content_edge_terms(t):
    """Per-edge content integrals: ``[(components, edge indices, signs)]``."""
    return integral_edges(t.surface, "content")


def energy_gradient(t):
    """Gradient (nv, 3) of the total energy of :class:`Totals` ``t``."""
    s = t.surface
    if s.string:
        return _string_energy_gradient(t)
    if hasattr(t, "energy_gradient"):       # a model's own (the quadratic model's)
        return t.energy_gradient()
    if AM.available(t):                 # (corner_scatter's numbers, fewer numpy calls)
        g = AM.scatter(s, AM.area_grad(t) * s.facet_tension)
    else:
        g = corner_scatter(t, facet_area_grad(t), s.facet_tension)
    et = s.eattr.get("tension")
    if et is not None and np.any(et):
        nz = np.nonzero(et)[0]
        g += edge_length_grad(t, nz, et[nz])
    for comps, idx, sign in integral_edges(s, "energy"):
        g += edge_vector_integral_grad(t, comps, idx, sign)
    if "gap" in t.terms:
        g += gap_energy_grad(t)
    if "sq_curvature" in t.terms:
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


def _string_energy_gradient(t):
    """Gradient (nv, 3) of the total energy of a string surface."""
    s = t.surface
    et = s.edge_tension
    nz = np.nonzero(et)[0]
    g = edge_length_grad(t, nz, et[nz])
    for formula, on in SM.vertex_integrand(s, "energy"):
        idx = np.nonzero(on)[0]
        d = SM.point_gradients(s, formula, idx)
        g[idx] += d
    b = s.bodies
    if b.n:
        if s.gravity_constant != 0 and s.gravity_on and np.any(b.density):
            w = s.gravity_constant * (b.facet_matrix.T @ b.density)
            g += SM.chain_grad(s, np.asarray(w, float), SM.gravity_derivs)
        pmask = ~np.isnan(b.pressure)
        for i in np.nonzero(pmask)[0]:
            g -= b.pressure[i] * SM.body_gradient(s, i)
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
    s = t.surface
    out = np.zeros((s.nv, 3))
    for c, idx in convex_edges(s):
        d = t.edge_vec[idx]
        L = np.sqrt(np.einsum("ij,ij->i", d, d))        # Euclidean under a metric too
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
        return SM.volume_gradients(t)
    if hasattr(t, "body_volume_gradients"):  # a model's own (the quadratic model's)
        return t.body_volume_gradients()
    b = s.bodies
    vg = facet_volume_grad(t, s.symmetric_content)
    out = np.zeros((b.n, s.nv, 3))
    Bm = b.facet_matrix.tocsr()
    lift = s.periods is not None and s.symmetry_group is None   # (a group: no lift)
    if lift:
        D = torus_lift_shifts(s)
        P = _facet_points(t)
    content = content_edge_terms(t)
    for i in range(b.n):
        w = np.zeros(Bm.shape[1])    # row i dense (as todense() sums: in stored order)
        lo, hi = Bm.indptr[i], Bm.indptr[i + 1]
        np.add.at(w, Bm.indices[lo:hi], Bm.data[lo:hi])
        out[i] = corner_scatter(t, vg, w)
        if lift:
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
    g = np.zeros((s.nv, s.X.shape[1]))
    if q.kind == "energy" and q.modulus == 0:
        return g                    # (not evaluated, as in REF)
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
        fn = lookup(m.method, getattr(t, "model", "linear")).gradient
        if fn is None:
            raise UnsupportedError(f"the gradient of method {m.method}")
        g += fn(t, m, np.asarray(idx, np.int64), w)
    return g
