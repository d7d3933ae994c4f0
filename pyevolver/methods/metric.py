"""Edge lengths and facet areas in a Riemannian metric (``METRIC``,
``CONFORMAL_METRIC``; :class:`pyevolver.model.metric.Metric`), their
gradients and Hessians.

REF's rules, found by experiment against evolver-nox-d:

- an edge from ``x0`` to ``x1`` (``d = x1 − x0``) has length
  ``Σ_q w_q sqrt(dᵀ G(x_q) d)``, ``x_q = x0 + t_q d``, by Gauss-Legendre with
  ``integral_order_1d // 2 + 1`` points (order 3: two points; metric.fe's
  edges agree to 1e-15);
- a facet with sides ``s1 = x1 − x0``, ``s2 = x2 − x0`` has area
  ``½ Σ_q w_q sqrt(det(Sᵀ G(x_q) S))``, ``S = [s1 s2]``, by the triangle rule
  of ``integral_order_2d``: order 6 the 12-point degree-6 rule
  (Dunavant), order 7 the 16-point degree-8 rule (Dunavant; REF's value of
  every monomial up to degree 14 agrees to 1e-15);
- the motion is the plain coordinate gradient of these (REF's first step of
  metric.fe with fixed scale is ``x − scale ∇E``, not ``G⁻¹∇E``), volumes stay
  Euclidean (manual, "Riemannian metric").

The Hessians take central differences of the analytic per-element gradient
(each element's own coordinates moved, vectorized over the elements) and are
assembled sparse.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..errors import PyEvolverError, UnsupportedError
from ..expr.nodes import coord_names
from ..geometry.kernels import TRI6_B, TRI6_W, polished_rule
from ..model.metric import FACET_ORDERS
from ._common import assemble, scatter
from .registry import register_method


# ---------------------------------------------------------------------------
# quadrature rules


@lru_cache(maxsize=None)
def line_rule(order: int) -> tuple[np.ndarray, np.ndarray]:
    """``(t, w)`` on [0, 1] of REF's edge rule of ``integral_order_1d``:
    Gauss-Legendre with ``order // 2 + 1`` points."""
    x, w = np.polynomial.legendre.leggauss(max(int(order), 0) // 2 + 1)
    return (x + 1.0) / 2.0, w / 2.0


def _dunavant8():
    """16-point degree-8 rule on the triangle (Dunavant 1985), barycentric
    ``(B (16, 3), W (16,))``, the published constants polished
    (:func:`pyevolver.geometry.kernels.polished_rule`)."""
    return polished_rule([0.144315607677787, 0.459292588292723, 0.095091634267285,
                          0.170569307751760, 0.103217370534718, 0.050547228317031,
                          0.032458497623198, 0.008394777409958, 0.263112829634638,
                          0.027230314174435], centre=True, n3=3, n6=1, degree=8)


@lru_cache(maxsize=None)
def triangle_rule(order: int) -> tuple[np.ndarray, np.ndarray]:
    """``(B (q, 3), W (q,))`` barycentric points and weights (summing to 1)
    of REF's facet rule of ``integral_order_2d``."""
    if order == 6:
        return TRI6_B, TRI6_W
    if order == 7:
        return _dunavant8()
    raise UnsupportedError(f"INTEGRAL_ORDER_2D {order} with a metric",
                           f"pyevolver has REF's rules of orders "
                           f"{' and '.join(map(str, FACET_ORDERS))} only")


# ---------------------------------------------------------------------------
# the tensor


def tensor(s, P: np.ndarray, second: bool = False):
    """The metric at points ``P (m, n)``: ``G (m, n, n)``, ``dG (m, n, n, n)``
    (``[i, j, k] = ∂_k G_ij``), all symmetrized (only the symmetric part
    enters lengths and areas)."""
    m = s.metric
    n = m.dim
    npts = len(P)
    names = coord_names(n)
    coords = {nm: P[:, k] for k, nm in enumerate(names)}
    params = s.param_env()
    G = np.empty((npts, n, n))
    dG = np.empty((npts, n, n, n))
    if m.kind == "conformal":
        f = m.comps[0]
        lam = np.broadcast_to(np.asarray(f.values(params, coords, npts), float), (npts,))
        dl = f.gradient(params, coords, npts, names)
        eye = np.eye(n)
        G[:] = lam[:, None, None] * eye
        dG[:] = eye[None, :, :, None] * dl[:, None, None, :]
        return G, dG
    if m.kind != "matrix":
        raise UnsupportedError("KLEIN_METRIC lengths and areas",
                               "REF's exact hyperbolic formulas are not implemented")
    for i in range(n):
        for j in range(n):
            f = m.comps[i * n + j]
            G[:, i, j] = f.values(params, coords, npts)
            dG[:, i, j, :] = f.gradient(params, coords, npts, names)
    G = 0.5 * (G + G.transpose(0, 2, 1))
    dG = 0.5 * (dG + dG.transpose(0, 2, 1, 3))
    return G, dG


# ---------------------------------------------------------------------------
# per-element kernels: values and gradients of the elements' own corners


def _klein_check(*P):
    if any(np.any(np.einsum("mi,mi->m", X, X) >= 1.0) for X in P):
        raise PyEvolverError("Points outside unit disk in Klein model.")


def klein_edge_kernel(X0, X1, grad=True):
    """Hyperbolic lengths (Klein model: straight segments are geodesics)
    ``arccosh((1 − x·y) / √((1 − |x|²)(1 − |y|²)))`` and their gradients."""
    _klein_check(X0, X1)
    a = 1.0 - np.einsum("mi,mi->m", X0, X1)
    p = 1.0 - np.einsum("mi,mi->m", X0, X0)
    q = 1.0 - np.einsum("mi,mi->m", X1, X1)
    r = np.sqrt(p * q)
    c = np.maximum(a / r, 1.0)
    L = np.arccosh(c)
    if not grad:
        return L
    with np.errstate(all="ignore"):
        k = np.where(c > 1.0, 1.0 / (r * np.sqrt(c * c - 1.0)), 0.0)[:, None]
    g0 = k * (-X1 + (a / p)[:, None] * X0)
    g1 = k * (-X0 + (a / q)[:, None] * X1)
    return L, g0, g1


def klein_facet_kernel(X0, X1, X2, grad=True):
    """Hyperbolic triangle areas by L'Huilier's formula,
    ``tan(Δ/4) = √(Π tanh(·/2))`` over s, s − a, s − b, s − c (s the half
    perimeter of the side lengths), and their corner gradients."""
    la = klein_edge_kernel(X1, X2)         # side opposite corner 0
    lb = klein_edge_kernel(X0, X2)
    lc = klein_edge_kernel(X0, X1)
    a, b, c = la[0], lb[0], lc[0]
    s = 0.5 * (a + b + c)
    u = np.maximum(np.stack([s, s - a, s - b, s - c]), 0.0)
    P = np.prod(np.tanh(u / 2.0), axis=0)
    A = 4.0 * np.arctan(np.sqrt(P))
    if not grad:
        return A
    with np.errstate(all="ignore"):
        inv = np.where(u > 0, 1.0 / np.sinh(u), 0.0)    # d ln tanh(u/2) / du
        k = np.where(P > 0, 2.0 * np.sqrt(P) / (1.0 + P), 0.0)
    dA = [k * 0.5 * (inv[0] - inv[1] + inv[2] + inv[3]),
          k * 0.5 * (inv[0] + inv[1] - inv[2] + inv[3]),
          k * 0.5 * (inv[0] + inv[1] + inv[2] - inv[3])]
    dA = [np.nan_to_num(d)[:, None] for d in dA]
    g0 = dA[1] * lb[1] + dA[2] * lc[1]
    g1 = dA[0] * la[1] + dA[2] * lc[2]
    g2 = dA[0] * la[2] + dA[1] * lb[2]
    return A, g0, g1, g2


def edge_kernel(s, X0: np.ndarray, X1: np.ndarray, grad: bool = True):
    """Metric lengths ``(m,)`` of the edges ``X0 → X1 (m, n)`` and, with
    ``grad``, their gradients ``(g0, g1)`` (m, n) at both ends."""
    if s.metric.kind == "klein":
        return klein_edge_kernel(X0, X1, grad)
    t, w = line_rule(s.metric.order_1d)
    d = X1 - X0
    m, n = d.shape
    L = np.zeros(m)
    g0 = np.zeros((m, n))
    g1 = np.zeros((m, n))
    for tq, wq in zip(t, w):
        G, dG = tensor(s, X0 + tq * d)
        Gd = np.einsum("mij,mj->mi", G, d)
        Q = np.einsum("mi,mi->m", d, Gd)
        f = np.sqrt(np.maximum(Q, 0.0))
        L += wq * f
        if grad:
            p = np.einsum("mi,mj,mijk->mk", d, d, dG)
            with np.errstate(all="ignore"):
                c = np.where(f > 0, wq / (2.0 * f), 0.0)[:, None]
            g0 += c * (-2.0 * Gd + (1.0 - tq) * p)
            g1 += c * (2.0 * Gd + tq * p)
    return (L, g0, g1) if grad else L


def facet_kernel(s, X0, X1, X2, grad: bool = True):
    """Metric areas ``(m,)`` of the triangles ``X0 X1 X2 (m, n)`` and, with
    ``grad``, their corner gradients ``(g0, g1, g2)`` (m, n)."""
    if s.metric.kind == "klein":
        return klein_facet_kernel(X0, X1, X2, grad)
    B, W = triangle_rule(s.metric.order_2d)
    S = np.stack([X1 - X0, X2 - X0], axis=2)                  # (m, n, 2)
    m, n, _ = S.shape
    A = np.zeros(m)
    g = np.zeros((3, m, n))
    for b, wq in zip(B, W):
        G, dG = tensor(s, b[0] * X0 + b[1] * X1 + b[2] * X2)
        GS = np.einsum("mij,mjb->mib", G, S)
        M = np.einsum("mia,mib->mab", S, GS)
        D = M[:, 0, 0] * M[:, 1, 1] - M[:, 0, 1] * M[:, 1, 0]
        f = np.sqrt(np.maximum(D, 0.0))
        A += 0.5 * wq * f
        if grad:
            C = np.empty_like(M)                             # ∂D/∂M, the cofactors
            C[:, 0, 0] = M[:, 1, 1]
            C[:, 1, 1] = M[:, 0, 0]
            C[:, 0, 1] = -M[:, 1, 0]
            C[:, 1, 0] = -M[:, 0, 1]
            dS = 2.0 * np.einsum("mib,mab->mia", GS, C)      # ∂D/∂s_a (m, n, 2)
            dx = np.einsum("mab,mia,mijk,mjb->mk", C, S, dG, S)
            with np.errstate(all="ignore"):
                c = np.where(f > 0, 0.5 * wq / (2.0 * f), 0.0)[:, None]
            g[1] += c * (dS[:, :, 0] + b[1] * dx)
            g[2] += c * (dS[:, :, 1] + b[2] * dx)
            g[0] += c * (-dS[:, :, 0] - dS[:, :, 1] + b[0] * dx)
    return (A, g[0], g[1], g[2]) if grad else A


# ---------------------------------------------------------------------------
# on a surface


def _n(s):
    return s.metric.dim


def _edge_ends(s, idx):
    n = _n(s)
    return s.X[s.E[idx, 0], :n], s.X[s.E[idx, 1], :n]


def _facet_corners(s, idx=None):
    n = _n(s)
    F = s.F if idx is None else s.F[idx]
    return s.X[F[:, 0], :n], s.X[F[:, 1], :n], s.X[F[:, 2], :n]


def _pad(g, width=3):
    out = np.zeros(g.shape[:-1] + (width,))
    out[..., :g.shape[-1]] = g
    return out


def edge_lengths(t, idx=None) -> np.ndarray:
    """(ne,) metric lengths of the edges (``idx``: of those)."""
    s = t.surface
    idx = np.arange(s.ne) if idx is None else np.asarray(idx)
    return edge_kernel(s, *_edge_ends(s, idx), grad=False)


def facet_areas(t) -> np.ndarray:
    """(nf,) metric areas of the facets."""
    s = t.surface
    return facet_kernel(s, *_facet_corners(s), grad=False)


def edge_length_grad(t, idx: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Gradient (nv, 3) of ``Σ_e w_e L_e`` over the edges ``idx``."""
    s = t.surface
    idx = np.asarray(idx)
    _, g0, g1 = edge_kernel(s, *_edge_ends(s, idx))
    w = np.asarray(weights, float)[:, None]
    return scatter(s.nv, np.concatenate([s.E[idx, 0], s.E[idx, 1]]),
                   _pad(np.concatenate([w * g0, w * g1])))


def facet_area_grad(t) -> np.ndarray:
    """Per-corner gradients (nf, 3, 3) of the facet areas."""
    s = t.surface
    _, g0, g1, g2 = facet_kernel(s, *_facet_corners(s))
    return _pad(np.stack([g0, g1, g2], axis=1))


def _fd_blocks(kernel, s, corners):
    """Per-element Hessian blocks (m, k, k, 3, 3) of a kernel: central
    differences of its analytic corner gradients, each corner coordinate
    moved by h = 1e-5 × (the element's size)."""
    k = len(corners)
    m, n = corners[0].shape
    size = np.max([np.max(np.abs(c - corners[0]), axis=1) for c in corners[1:]], axis=0)
    h = 1e-5 * np.where(size > 0, size, 1.0)
    blocks = np.zeros((m, k, k, 3, 3))
    for a in range(k):
        for i in range(n):
            plus = [c.copy() for c in corners]
            minus = [c.copy() for c in corners]
            plus[a][:, i] += h
            minus[a][:, i] -= h
            gp = kernel(s, *plus)[1:]
            gm = kernel(s, *minus)[1:]
            for b in range(k):
                blocks[:, a, b, i, :n] = (gp[b] - gm[b]) / (2.0 * h[:, None])
    return 0.5 * (blocks + blocks.transpose(0, 2, 1, 4, 3))


def edge_length_hessian(t, idx, weights, basis=None):
    """Hessian of ``Σ_e w_e L_e`` (3nv, 3nv), or projected on ``basis``."""
    s = t.surface
    idx = np.asarray(idx)
    blocks = _fd_blocks(edge_kernel, s, list(_edge_ends(s, idx)))
    blocks *= np.asarray(weights, float)[:, None, None, None, None]
    return assemble(s.nv, s.E[idx], blocks, basis)


def facet_area_hessian(t, weights, basis=None):
    """Hessian of ``Σ_f w_f A_f`` (3nv, 3nv), or projected on ``basis``."""
    s = t.surface
    blocks = _fd_blocks(facet_kernel, s, list(_facet_corners(s)))
    blocks *= np.asarray(weights, float)[:, None, None, None, None]
    return assemble(s.nv, s.F, blocks, basis)


# ---------------------------------------------------------------------------
# where refining splits an edge


def split_fractions(s, idx: np.ndarray, max_steps: int = 60) -> np.ndarray:
    """(k,) where ``r`` / ``l`` put the new vertex on each edge ``idx``, as a
    fraction of the edge vector from its tail (REF's rule, measured with
    conformal metrics (1 + a x)², e^{±4x} on one edge, string and soapfilm):
    bisection from ½ toward the side with the larger metric length until
    the tail part's length over the head part's is strictly between 0.8 and
    1.2 (so REF stops at 3/8 on a mirror image where it goes on at 5/8)."""
    idx = np.asarray(idx, np.int64)
    X0, X1 = _edge_ends(s, idx)
    d = X1 - X0
    t = np.full(len(idx), 0.5)
    lo = np.zeros(len(idx))
    hi = np.ones(len(idx))
    act = np.ones(len(idx), bool)
    for _ in range(max_steps):
        if not act.any():
            break
        a = np.nonzero(act)[0]
        P = X0[a] + t[a, None] * d[a]
        l1 = edge_kernel(s, X0[a], P, grad=False)
        l2 = edge_kernel(s, P, X1[a], grad=False)
        with np.errstate(all="ignore"):
            r = l1 / l2
        ok = (r > 0.8) & (r < 1.2) | ~np.isfinite(r)
        act[a[ok]] = False
        up = a[~ok & (r >= 1.2)]
        dn = a[~ok & (r <= 0.8)]
        hi[up] = t[up]
        lo[dn] = t[dn]
        t[a[~ok]] = 0.5 * (lo[a[~ok]] + hi[a[~ok]])
    return t


def segment_lengths(s, P0: np.ndarray, P1: np.ndarray) -> np.ndarray:
    """(m,) metric lengths of the segments ``P0 → P1 (m, ≥ n)`` (remeshing
    measures edges and facets as ``length`` and ``area`` do: REF's ``t`` and
    ``w`` weed by the metric's)."""
    n = _n(s)
    return edge_kernel(s, np.atleast_2d(P0)[:, :n], np.atleast_2d(P1)[:, :n], grad=False)


def triangle_areas(s, P0: np.ndarray, P1: np.ndarray, P2: np.ndarray) -> np.ndarray:
    """(m,) metric areas of the triangles ``P0 P1 P2 (m, ≥ n)``."""
    n = _n(s)
    return facet_kernel(s, *(np.atleast_2d(P)[:, :n] for P in (P0, P1, P2)), grad=False)


# ---------------------------------------------------------------------------
# the named methods metric_facet_area and metric_edge_length


def _general(t, name):
    s = t.surface
    if s.metric is None or s.metric.kind != "matrix":
        # REF's ERROR 1583, also with CONFORMAL_METRIC and KLEIN_METRIC
        raise PyEvolverError("Cannot use metric_facet_area or metric_edge_length method "
                             "without a general metric.")
    if name == "metric_edge_length" and not s.string:
        raise UnsupportedError("method metric_edge_length in the soapfilm model",
                               "REF's value there is 0, not the metric length")


def _per(n, idx, w):
    full = np.zeros(n)
    np.add.at(full, np.asarray(idx, np.int64), w)
    return full


def _mfa_value(t, m, idx):
    _general(t, "metric_facet_area")
    return t.facet_area[idx]


def _mfa_gradient(t, m, idx, w):
    _general(t, "metric_facet_area")
    s = t.surface
    per = _per(s.nf, idx, w)
    return scatter(s.nv, s.F.ravel(), (facet_area_grad(t) * per[:, None, None]).reshape(-1, 3))


def _mfa_hessian(t, m, idx, w, basis=None):
    return facet_area_hessian(t, _per(t.surface.nf, idx, w), basis)


def _mel_value(t, m, idx):
    _general(t, "metric_edge_length")
    return t.edge_length[idx]


def _mel_gradient(t, m, idx, w):
    _general(t, "metric_edge_length")
    return edge_length_grad(t, idx, w)


def _mel_hessian(t, m, idx, w, basis=None):
    return edge_length_hessian(t, idx, w, basis)


register_method("metric_facet_area", "facet", _mfa_value, _mfa_gradient, _mfa_hessian)
register_method("metric_edge_length", "edge", _mel_value, _mel_gradient, _mel_hessian)
