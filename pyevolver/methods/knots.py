"""Knot energies: all-pairs repulsions between vertices or edges.

Surface Evolver 2.70 manual, "Quantities and methods" (knot energies), with
the normalizations evolver-nox-d actually uses (found by experiment,
tests/methods/test_knots.py).  Sums run over ordered pairs (each unordered
pair counts twice); ``p`` is the variable ``knot_power`` (default 2), ``r``
the distance of two vertices, ``d`` the vector between the midpoints ``M``
of two edges, ``L`` and ``V`` edge lengths and vectors:

* ``knot_energy`` (vertex): ``Σ_{i≠j} q_i q_j / r^p``, ``q`` the vertex
  attribute ``node_charge`` when declared, else 1;
* ``uniform_knot_energy`` (vertex): the same with ``q_i`` the total length
  of the vertex's edges;
* ``edge_knot_energy`` = ``edge_edge_knot_energy`` (edge):
  ``Σ_{a≠b} L_a L_b / |d|²`` (always power 2);
* ``buck_knot_energy`` (edge): ``Σ 1/δ^p`` over ordered pairs of edges
  without a common vertex, ``δ`` the sum of the four distances between
  their endpoints minus ``2(L_a + L_b)``; a pair with ``δ ≤ 0`` is the
  Evolver's error 1543 "Buck denominator nonpositive";
* ``proj_knot_energy`` (edge): ``2 Σ_{a≠b} L_a L_b cos^p θ / |d|^p``,
  ``cos² θ = 1 − (d·V_a)²/(|d|² L_a²)`` (twice the manual's form);
* ``circle_knot_energy`` (edge): ``Σ_{a≠b} L_a L_b (1 − cos α)/|d|²``,
  ``cos α`` between edge a and the tangent at ``M_a`` of the circle through
  ``M_a`` tangent to edge b at ``M_b`` — polynomially
  ``(L_a L_b + V_a·V_b − 2 (V_a·d)(V_b·d)/|d|²)/|d|²`` (the manual's
  ``(1 − cos α)²`` is not what the program computes);
* ``edge_min_knot_energy`` (edge, value only): ``Σ L_a L_b / δ²`` over
  ordered pairs without a common vertex, ``δ`` the distance between the
  edges;
* ``writhe`` (edge): ``Σ_{a≠b} (V_a × V_b)·d/(4π |d|³)`` (the manual's sum
  over 4π, ordered pairs).

Each element's value is its row of the pair sum.  Gradients are analytic
(every ordered term differentiated in full, checked against differences);
``g`` moves by them, except: ``uniform_knot_energy`` moves by REF's force
(the charge part of the gradient halved, :func:`uniform_knot_force`) and
``g`` with ``proj_knot_energy`` is refused by name (REF's force differs
from :func:`proj_knot_gradient` in a way not reproduced).  ``knot_energy``
has an analytic (dense) Hessian; ``hessian`` with the others is refused by
name, where REF stops with its error 1571.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import PyEvolverError, UnsupportedError
from ..model.string import STRING_METHODS
from ._common import assemble
from .registry import register_method


class KnotError(PyEvolverError):
    """The Evolver's error 1543 (a Buck denominator ≤ 0)."""


def knot_power(s) -> float:
    """The variable ``knot_power`` (created with its default 2)."""
    if "knot_power" not in s.params:
        s.params["knot_power"] = 2.0
    return float(s.params["knot_power"])


def _vgrad(s, idx, vec):
    """(nv, D) from per-entry vectors ``vec`` at vertices ``idx``."""
    D = vec.shape[1]
    out = np.zeros((s.nv, s.X.shape[1]))
    for j in range(D):
        out[:, j] = np.bincount(idx, weights=vec[:, j], minlength=s.nv)
    return out


def _no_torus(s):
    if s.periods is not None:
        raise UnsupportedError("knot energies in the torus model",
                               "which images of the pairs REF takes was not measured")


def _edge_vectors(t, idx):
    s = t.surface
    _no_torus(s)
    idx = np.asarray(idx, np.int64)
    V = t.edge_vec[idx]
    L = t.edge_length[idx]
    M = s.X[s.E[idx, 0]] + 0.5 * V
    return V, L, M


def _edge_scatter(s, idx, gV, gL, gM, V, L):
    """Gradient (nv, D) from derivatives with respect to each edge's vector
    ``V``, length ``L`` and midpoint ``M`` (rows of idx)."""
    G = gV + (gL / L)[:, None] * V
    t_ = -G + 0.5 * gM
    h_ = G + 0.5 * gM
    E = s.E[np.asarray(idx, np.int64)]
    return _vgrad(s, np.concatenate([E[:, 0], E[:, 1]]), np.concatenate([t_, h_]))


# ---- vertex charges ----------------------------------------------------------------
def _pair_matrix(X):
    D = X[:, None, :] - X[None, :, :]
    r2 = np.einsum("ijk,ijk->ij", D, D)
    np.fill_diagonal(r2, np.inf)
    return D, r2


def _charges(s, idx):
    _no_torus(s)
    q = s.extra.get(("vertex", "node_charge"))
    return np.ones(len(idx)) if q is None else np.asarray(q, float)[idx]


def knot(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-vertex ``Σ_j q_i q_j / r_ij^p`` (over the vertices idx)."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    q = _charges(s, idx)
    _, r2 = _pair_matrix(s.X[idx])
    return q * ((r2 ** (-knot_power(s) / 2.0)) @ q)


def _vertex_pair_grad(s, idx, C, D):
    """Gradient of Σ_ij C_ij-weighted pair terms: C_ij = coefficient of
    (x_i − x_j) in the gradient of term (i, j) at x_i."""
    g = np.einsum("ij,ijk->ik", C, D) - np.einsum("ji,jik->ik", C, D)
    return _vgrad(s, idx, g)


def knot_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ_i w_i Σ_j q_i q_j r_ij^-p``."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    q = _charges(s, idx) * np.asarray(w, float)
    qq = _charges(s, idx)
    p = knot_power(s)
    D, r2 = _pair_matrix(s.X[idx])
    C = -p * np.outer(q, qq) * r2 ** (-p / 2.0 - 1.0)
    return _vertex_pair_grad(s, idx, C, D)


def knot_hessian(t: Any, m: Any, idx: np.ndarray, w: np.ndarray, basis: Any = None) -> Any:
    """Dense Hessian of ``Σ_i w_i Σ_j q_i q_j r_ij^-p`` as pair blocks
    ``[[H, −H], [−H, H]]``, ``H = c(−p r^-p-2 I + p(p+2) r^-p-4 d dᵀ)``."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    n = len(idx)
    p = knot_power(s)
    q = _charges(s, idx)
    D, r2 = _pair_matrix(s.X[idx])
    c = np.outer(q * np.asarray(w, float), q)
    i, j = np.nonzero(~np.eye(n, dtype=bool))
    d = D[i, j]
    rr = r2[i, j]
    dim = d.shape[1]
    H = (c[i, j] * -p * rr ** (-p / 2 - 1))[:, None, None] * np.eye(dim)[None] \
        + (c[i, j] * p * (p + 2) * rr ** (-p / 2 - 2))[:, None, None] \
        * np.einsum("ni,nj->nij", d, d)
    if dim < 3:
        H3 = np.zeros((len(i), 3, 3))
        H3[:, :dim, :dim] = H
        H = H3
    B = np.stack([np.stack([H, -H], 1), np.stack([-H, H], 1)], 1)
    return assemble(s.nv, np.stack([idx[i], idx[j]], 1), B, basis)


def _uniform_charges(t, idx):
    s = t.surface
    _no_torus(s)
    L = t.edge_length
    qa = np.bincount(s.E[:, 0], weights=L, minlength=s.nv) + \
        np.bincount(s.E[:, 1], weights=L, minlength=s.nv)
    return qa[np.asarray(idx, np.int64)]


def uniform_knot(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-vertex ``Σ_j q_i q_j / r_ij^p``, q the length of the vertex's edges."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    q = _uniform_charges(t, idx)
    _, r2 = _pair_matrix(s.X[idx])
    return q * ((r2 ** (-knot_power(s) / 2.0)) @ q)


def uniform_knot_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ_i w_i Σ_j q_i q_j r_ij^-p`` (through r and q)."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    w = np.asarray(w, float)
    q = _uniform_charges(t, idx)
    p = knot_power(s)
    D, r2 = _pair_matrix(s.X[idx])
    K = r2 ** (-p / 2.0)
    C = -p * np.outer(w * q, q) * r2 ** (-p / 2.0 - 1.0)
    g = _vertex_pair_grad(s, idx, C, D)
    dq = (w[:, None] + w[None, :]) * K @ q           # ∂F/∂q_k
    full = np.zeros(s.nv)
    full[idx] = dq
    dL = full[s.E[:, 0]] + full[s.E[:, 1]]
    G = (dL / t.edge_length)[:, None] * t.edge_vec
    return g + _vgrad(s, np.concatenate([s.E[:, 1], s.E[:, 0]]), np.concatenate([G, -G]))


# ---- edge pairs ----------------------------------------------------------------------
def _mid_pairs(M):
    d = M[:, None, :] - M[None, :, :]
    d2 = np.einsum("ijk,ijk->ij", d, d)
    np.fill_diagonal(d2, np.inf)
    return d, d2


def edge_knot(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``Σ_b L_a L_b / |M_a − M_b|²``."""
    _, L, M = _edge_vectors(t, idx)
    _, d2 = _mid_pairs(M)
    return L * ((1.0 / d2) @ L)


def edge_knot_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ_a w_a Σ_b L_a L_b / |d_ab|²``."""
    s = t.surface
    w = np.asarray(w, float)
    V, L, M = _edge_vectors(t, idx)
    d, d2 = _mid_pairs(M)
    W = w[:, None] + w[None, :]
    gL = (W / d2) @ L
    C = -2.0 * W * np.outer(L, L) / d2 ** 2
    gM = np.einsum("ab,abk->ak", C, d)
    return _edge_scatter(s, idx, np.zeros_like(V), gL, gM, V, L)


def _buck_parts(t, idx):
    s = t.surface
    idx = np.asarray(idx, np.int64)
    E = s.E[idx]
    V, L, _ = _edge_vectors(t, idx)
    A = [s.X[E[:, 0]], s.X[E[:, 0]] + V]
    den = -2.0 * (L[:, None] + L[None, :])
    diffs = {}
    for i in range(2):
        for j in range(2):
            dv = A[i][:, None, :] - A[j][None, :, :]
            rr = np.sqrt(np.einsum("ijk,ijk->ij", dv, dv))
            diffs[i, j] = (dv, rr)
            den = den + rr
    adj = np.zeros((len(idx), len(idx)), bool)
    for i in range(2):
        for j in range(2):
            adj |= E[:, i][:, None] == E[:, j][None, :]
    ok = ~adj
    if np.any(den[ok] <= 0):
        raise KnotError("Buck denominator nonpositive.")
    return idx, E, V, L, den, ok, diffs


def buck_knot(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``Σ_b 1/δ_ab^p`` over the edges b without a common vertex."""
    _, _, _, _, den, ok, _ = _buck_parts(t, idx)
    p = knot_power(t.surface)
    return np.where(ok, np.where(ok, den, 1.0) ** (-p), 0.0).sum(axis=1)


def buck_knot_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ_a w_a Σ_b 1/δ_ab^p``."""
    s = t.surface
    idx, E, V, L, den, ok, diffs = _buck_parts(t, idx)
    p = knot_power(s)
    w = np.asarray(w, float)
    C = np.where(ok, -p * w[:, None] * np.where(ok, den, 1.0) ** (-p - 1.0), 0.0)
    g = np.zeros((s.nv, s.X.shape[1]))
    for (i, j), (dv, rr) in diffs.items():
        with np.errstate(divide="ignore", invalid="ignore"):
            u = np.nan_to_num(dv / rr[:, :, None])
        ga = np.einsum("ab,abk->ak", C, u)
        gb = -np.einsum("ab,abk->bk", C, u)
        g += _vgrad(s, E[:, i], ga) + _vgrad(s, E[:, j], gb)
    gL = -2.0 * (C.sum(axis=1) + C.sum(axis=0))
    return g + _edge_scatter(s, idx, np.zeros_like(V), gL, np.zeros_like(V), V, L)


def _proj_parts(t, idx):
    s = t.surface
    V, L, M = _edge_vectors(t, idx)
    d, d2 = _mid_pairs(M)
    p = knot_power(s)
    g = np.einsum("abk,ak->ab", d, V)
    A = np.maximum((L * L)[:, None] * d2 - g * g, 0.0)
    np.fill_diagonal(A, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        term = 2.0 * (L ** (1.0 - p))[:, None] * L[None, :] * A ** (p / 2.0) * d2 ** (-p)
    np.fill_diagonal(term, 0.0)
    np.fill_diagonal(d2, 1.0)       # (finite where the terms vanish)
    return V, L, d, d2, p, g, A, term


def proj_knot(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``2 Σ_b L_a L_b cos^p θ_ab / |d_ab|^p``."""
    return _proj_parts(t, idx)[-1].sum(axis=1)


def proj_knot_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ_a w_a Σ_b term_ab``, term = 2 L_b L_a^(1−p)
    A^(p/2) |d|^(−2p), A = L_a²|d|² − (d·V_a)²."""
    s = t.surface
    V, L, d, d2, p, g, A, term = _proj_parts(t, idx)
    T = np.asarray(w, float)[:, None] * term
    with np.errstate(divide="ignore", invalid="ignore"):
        TA = np.nan_to_num(np.where(A > 0, (p / 2.0) * T / A, 0.0))
        Td = np.nan_to_num(T / d2)
    # through L_a (the factor L_a^(1−p)) and L_b
    gL = (1.0 - p) * T.sum(axis=1) / L + T.sum(axis=0) / L
    # through A: ∂A/∂V_a = 2|d|² V_a − 2 g d, ∂A/∂d = 2 L_a² d − 2 g V_a
    gV = 2.0 * (TA * d2).sum(axis=1)[:, None] * V - 2.0 * np.einsum("ab,abk->ak", TA * g, d)
    Cd = 2.0 * TA * (L * L)[:, None] - 2.0 * p * Td
    Gd = Cd[:, :, None] * d - 2.0 * (TA * g)[:, :, None] * V[:, None, :]
    gM = Gd.sum(axis=1) - Gd.sum(axis=0)
    return _edge_scatter(s, idx, gV, gL, gM, V, L)


def _circle_parts(t, idx):
    V, L, M = _edge_vectors(t, idx)
    d, d2 = _mid_pairs(M)
    ga = np.einsum("abk,ak->ab", d, V)
    gb = np.einsum("abk,bk->ab", d, V)
    N = np.outer(L, L) + V @ V.T - 2.0 * ga * gb / d2
    return V, L, d, d2, ga, gb, N


def circle_knot(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``Σ_b L_a L_b (1 − cos α_ab)/|d_ab|²``."""
    *_, d2, _, _, N = _circle_parts(t, idx)
    return (N / d2).sum(axis=1)


def circle_knot_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ_a w_a Σ_b N_ab/|d_ab|²``,
    N = L_a L_b + V_a·V_b − 2 (V_a·d)(V_b·d)/|d|²."""
    s = t.surface
    V, L, d, d2, ga, gb, N = _circle_parts(t, idx)
    W = np.asarray(w, float)[:, None] / d2 * np.ones_like(d2)
    np.fill_diagonal(W, 0.0)
    # through L_a L_b
    LL = W * np.outer(L, L)
    gL = LL.sum(axis=1) / L + LL.sum(axis=0) / L
    # through V_a·V_b and the g terms
    B = W * gb / d2
    Aa = W * ga / d2
    gV = W @ V + W.T @ V - 2.0 * np.einsum("ab,abk->ak", B, d) \
        - 2.0 * np.einsum("ab,abk->bk", Aa, d)
    # through d (in N and in 1/|d|²)
    c1 = 4.0 * W * ga * gb / d2 ** 2 - 2.0 * W * N / d2
    Gd = c1[:, :, None] * d - 2.0 * B[:, :, None] * V[:, None, :] \
        - 2.0 * Aa[:, :, None] * V[None, :, :]
    gM = Gd.sum(axis=1) - Gd.sum(axis=0)
    return _edge_scatter(s, idx, gV, gL, gM, V, L)


def _writhe_parts(t, idx):
    V, L, M = _edge_vectors(t, idx)
    d, d2 = _mid_pairs(M)
    np.fill_diagonal(d2, 1.0)
    C = np.cross(V[:, None, :], V[None, :, :])              # V_a × V_b
    det = np.einsum("abk,abk->ab", C, d)
    r3 = d2 ** 1.5
    return V, L, d, d2, C, det, r3


def writhe(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``Σ_b (V_a × V_b)·d_ab / (4π |d_ab|³)`` (the Gauss integral)."""
    _, _, _, _, _, det, r3 = _writhe_parts(t, idx)
    return (det / r3).sum(axis=1) / (4.0 * np.pi)


def writhe_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ_a w_a Σ_b det(V_a, V_b, d)/(4π|d|³)``."""
    s = t.surface
    V, L, d, d2, C, det, r3 = _writhe_parts(t, idx)
    W = np.asarray(w, float)[:, None] / (4.0 * np.pi) / r3
    np.fill_diagonal(W, 0.0)
    # ∂/∂V_a = V_b × d, ∂/∂V_b = d × V_a
    gV = np.einsum("ab,abk->ak", W, np.cross(V[None, :, :], d)) \
        + np.einsum("ab,abk->bk", W, np.cross(d, V[:, None, :]))
    Gd = W[:, :, None] * C - (3.0 * W * det / d2)[:, :, None] * d
    gM = Gd.sum(axis=1) - Gd.sum(axis=0)
    return _edge_scatter(s, idx, gV, np.zeros(len(L)), gM, V, L)


def segment_distances(P0, P1, Q0, Q1) -> np.ndarray:
    """Distances between the segments P0P1 and Q0Q1 (broadcast arrays of
    points): the closest points' parameters clamped to [0, 1], the second
    one first when the first is clamped (as in Ericson's algorithm)."""
    u, v, w = P1 - P0, Q1 - Q0, P0 - Q0
    a = (u * u).sum(-1)
    b = (u * v).sum(-1)
    c = (v * v).sum(-1)
    d = (u * w).sum(-1)
    e = (v * w).sum(-1)
    den = a * c - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        sc = np.clip(np.where(den > 1e-14 * a * c, (b * e - c * d) / den, 0.0), 0.0, 1.0)
        tc = np.where(c > 0, (b * sc + e) / c, 0.0)
        tk = np.clip(tc, 0.0, 1.0)
        sc = np.where(tc != tk, np.clip(np.where(a > 0, (tk * b - d) / a, 0.0), 0.0, 1.0), sc)
    dP = w + sc[..., None] * u - tk[..., None] * v
    return np.sqrt((dP * dP).sum(-1))


def edge_min_knot(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``Σ_b L_a L_b / δ_ab²``, δ the distance between the edges
    (closest points), over the edges b without a common vertex."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    E = s.E[idx]
    V, L, _ = _edge_vectors(t, idx)
    P0 = s.X[E[:, 0]]
    P1 = P0 + V
    dist = segment_distances(P0[:, None], P1[:, None], P0[None], P1[None])
    adj = np.zeros((len(idx), len(idx)), bool)
    for i in range(2):
        for j in range(2):
            adj |= E[:, i][:, None] == E[:, j][None, :]
    with np.errstate(divide="ignore"):
        val = np.where(adj, 0.0, np.outer(L, L) / np.where(adj, 1.0, dist) ** 2)
    return val.sum(axis=1)


def uniform_knot_force(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """REF's "gradient" of ``uniform_knot_energy`` (what ``g`` moves by): the
    part through the distances in full, the part through the charges
    (:func:`uniform_knot_gradient`) halved — measured with ``v_force``
    (tests/methods/test_knots.py); not the gradient of its value."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    full = uniform_knot_gradient(t, m, idx, w)
    q = _uniform_charges(t, idx)
    D, r2 = _pair_matrix(s.X[idx])
    C = -knot_power(s) * np.outer(np.asarray(w, float) * q, q) * \
        r2 ** (-knot_power(s) / 2.0 - 1.0)
    g_r = _vertex_pair_grad(s, idx, C, D)
    return g_r + 0.5 * (full - g_r)


def proj_knot_refused(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``g`` with ``proj_knot_energy``: refused by name (see the module)."""
    raise UnsupportedError("the gradient of method proj_knot_energy",
                           "REF's force is not the gradient of its energy "
                           "(proj_knot_gradient) and was not reproduced")


_NO_H = "REF: ERROR 1571 (the method has no Hessian available)"
register_method("knot_energy", "vertex", knot, knot_gradient, knot_hessian)
register_method("uniform_knot_energy", "vertex", uniform_knot, uniform_knot_force,
                no_hessian=_NO_H)
register_method("edge_knot_energy", "edge", edge_knot, edge_knot_gradient, no_hessian=_NO_H)
register_method("edge_edge_knot_energy", "edge", edge_knot, edge_knot_gradient,
                no_hessian=_NO_H)
register_method("buck_knot_energy", "edge", buck_knot, buck_knot_gradient, no_hessian=_NO_H)
register_method("proj_knot_energy", "edge", proj_knot, proj_knot_refused, no_hessian=_NO_H)
register_method("circle_knot_energy", "edge", circle_knot, circle_knot_gradient,
                no_hessian=_NO_H)
register_method("writhe", "edge", writhe, writhe_gradient, no_hessian=_NO_H)
# (no gradient: the manual's "DO NOT use as an energy"; g with it is refused by name)
register_method("edge_min_knot_energy", "edge", edge_min_knot)
STRING_METHODS.update({"knot_energy", "uniform_knot_energy", "edge_knot_energy",
                       "edge_edge_knot_energy", "buck_knot_energy", "proj_knot_energy",
                       "circle_knot_energy", "writhe", "edge_min_knot_energy"})
