"""Elastic stretching energies of facets: ``linear_elastic``, the
``relaxed_elastic_A`` family (``relaxed_elastic1_A``, ``relaxed_elastic2_A``)
and ``dirichlet_elastic`` (``A0 Tr(FQ)`` per facet, as evolver-nox-d computes
it; it needs only ``form_factors``).

Surface Evolver 2.70 manual, "Quantities and methods", linear_elastic and
relaxed_elastic_A.  The unstrained shape of a facet is its Gram matrix
``S = [[s11, s12], [s12, s22]]``, kept in the facet attribute
``form_factors = {s11, s12, s22}`` (``s11 = |v2-v1|²``, ``s12 = (v2-v1)·(v3-v1)``,
``s22 = |v3-v1|²``); ``F`` is the Gram matrix of the strained facet, ``Q = S⁻¹``
and ``C = (FQ − I)/2`` the Cauchy-Green strain.  With ``ν`` the facet's
``poisson_ratio`` the energy density is

    w = (Tr C² + ν (Tr C)² / (1 − ν)) / (2 (1 + ν))

and the facet's energy is ``w`` times its unstrained area ``√det S / 2``
(measured against evolver-nox-d: tests/methods/test_elastic.py).

``relaxed_elastic_A`` lets compression cost nothing: with ``λ₁ ≥ λ₂`` the
eigenvalues of ``C`` and ``σᵢ = (λᵢ + ν/(1−ν) (λ₁+λ₂)) / (1+ν)`` those of the
stress, a facet with two positive stresses has the linear energy; otherwise
one with ``λ₁ > 0`` (stretched in one direction, wrinkled in the other) has
the uniaxial ``λ₁²/2`` times its area, and one with ``λ₁ ≤ 0`` none (the
rule evolver-nox-d follows: a facet with ``λ₁ > 0 ≥ σ₁`` still has ``λ₁²/2``).
``relaxed_elastic1_A`` / ``relaxed_elastic2_A`` are the energies of the facets
stressed in one / two directions.  These three are multiplied by the facet
attribute ``LEBweight`` when it is declared (as the Evolver does;
``linear_elastic`` ignores it).

As in the Evolver, the attributes ``poisson_ratio`` and ``form_factors`` must be
declared (the Evolver stops the load with "Facet extra attribute ... missing";
the manual's promise to create ``form_factors`` is not what 2.70 does), and a
facet whose form factors are degenerate (``det S ≤ 0``, e.g. never set) has
zero energy.

Gradients are analytic: ``dw = tr(M dF)`` with ``M = (QC + k Tr C Q) / (2(1+ν))``,
``k = ν/(1−ν)``, and for the uniaxial branch ``d(λ₁²/2) = (λ₁/2) yᵀ dF y`` with
``y = L r``, ``Q = L Lᵀ`` and ``r`` the unit eigenvector of ``Lᵀ F L``.
``linear_elastic``, ``dirichlet_elastic`` and the three-dimensional relaxed
methods have analytic Hessians (the relaxed ones branch by branch); the
five-dimensional ones are taken by finite differences of the gradient (the
registry's fallback).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import PyEvolverError, UnsupportedError
from ..geometry.kernels import scatter_nd
from ._common import assemble, corner_scatter
from .registry import register_method


def _attrs(t, name: str):
    """The facet attributes ``poisson_ratio`` (nf,) and ``form_factors`` (nf, 3)."""
    s = t.surface
    nu = s.extra.get(("facet", "poisson_ratio"))
    ff = s.extra.get(("facet", "form_factors"))
    if nu is None:
        raise PyEvolverError(f"Facet extra attribute poisson_ratio missing. Needed by {name}.")
    if ff is None or ff.ndim != 2 or ff.shape[1] < 3:
        raise PyEvolverError(f"Facet extra attribute form_factors real[3] missing. "
                             f"Needed by {name}.")
    return np.asarray(nu, float), np.asarray(ff, float)


def _strain(t, idx, name):
    """Per-facet pieces for the facets ``idx``.

    Returns
    -------
    dict
        ``a, b`` (n, 3) sides; ``F, Q, C`` (n, 2, 2); ``A0`` (n,) unstrained
        areas (0 for degenerate form factors); ``nu`` (n,).  For the
        five-dimensional methods (:func:`_is_b`) the sides are those of
        x1..x3 and the form factors the Gram matrix of the sides in x4, x5
        (with ``ra, rb`` (n, 2) those reference sides).
    """
    idx = np.asarray(idx, np.int64)
    S = t.facet_S[idx]
    if _is_b(name):
        nu_all = _b_attrs(t, name)
        a, b = S[:, 0, :3], S[:, 1, :3]
        ra, rb = S[:, 0, 3:5], S[:, 1, 3:5]
        ff = np.stack([np.einsum("ij,ij->i", ra, ra), np.einsum("ij,ij->i", ra, rb),
                       np.einsum("ij,ij->i", rb, rb)], axis=1)
    else:
        nu_all, ff_all = _attrs(t, name)
        a, b = S[:, 0], S[:, 1]
        ff = ff_all[idx, :3]
    det = ff[:, 0] * ff[:, 2] - ff[:, 1] ** 2
    ok = det > 0
    safe = np.where(ok, det, 1.0)
    Q = np.empty((len(idx), 2, 2))
    Q[:, 0, 0] = ff[:, 2] / safe
    Q[:, 0, 1] = Q[:, 1, 0] = -ff[:, 1] / safe
    Q[:, 1, 1] = ff[:, 0] / safe
    F = np.empty((len(idx), 2, 2))
    F[:, 0, 0] = np.einsum("ij,ij->i", a, a)
    F[:, 0, 1] = F[:, 1, 0] = np.einsum("ij,ij->i", a, b)
    F[:, 1, 1] = np.einsum("ij,ij->i", b, b)
    C = 0.5 * (F @ Q - np.eye(2))
    A0 = np.where(ok, 0.5 * np.sqrt(safe), 0.0)
    P = {"a": a, "b": b, "F": F, "Q": Q, "C": C, "A0": A0, "nu": nu_all[idx]}
    if _is_b(name):
        P["ra"], P["rb"] = ra, rb
    return P


def _linear_density(C, nu):
    """Energy density (n,) and its derivative ``M`` (n, 2, 2) w.r.t. ``F`` (given Q)."""
    tr = C[:, 0, 0] + C[:, 1, 1]
    trcc = np.einsum("nij,nji->n", C, C)
    k = nu / (1.0 - nu)
    w = (trcc + k * tr ** 2) / (2.0 * (1.0 + nu))
    return w, tr, k


def _is_b(name: str) -> bool:
    """Whether ``name`` is a five-dimensional method (``linear_elastic_B``,
    ``relaxed_elastic``, ``relaxed_elastic1``, ``relaxed_elastic2``: the
    reference shape in the coordinates x4, x5)."""
    return name in ("linear_elastic_b", "relaxed_elastic", "relaxed_elastic1",
                    "relaxed_elastic2")


def _b_attrs(t, name: str) -> np.ndarray:
    """``poisson_ratio`` (nf,) of a five-dimensional method, which needs
    ``SPACE_DIMENSION 5``."""
    s = t.surface
    if s.X.shape[1] != 5:
        raise UnsupportedError(f"{name} in SPACE_DIMENSION {s.sdim}",
                               "the method needs SPACE_DIMENSION 5: x1..x3 strained, "
                               "x4, x5 the unstrained plane")
    nu = s.extra.get(("facet", "poisson_ratio"))
    if nu is None:
        raise PyEvolverError(f"Facet extra attribute poisson_ratio missing. Needed by {name}.")
    return np.asarray(nu, float)


def _b_gradient(t, idx, P, M, e):
    """Gradient (nv, 5) of ``Σ_f E_f`` for a five-dimensional method, with
    ``M`` (n, 2, 2) = ``∂E/∂F`` (weights and unstrained areas included) and
    ``e`` (n,) the facet energies (weighted): through the strained sides
    (x1..x3) as :func:`_gradient_from_M`, and through the reference sides
    (x4, x5) with ``∂E/∂S = e Q / 2 − M F Q`` (``dA0 = A0 tr(Q dS)/2``, and
    the density depends on F and S only through ``F Q``, ``dQ = −Q dS Q``)."""
    s = t.surface
    MS = 0.5 * e[:, None, None] * P["Q"] - M @ P["F"] @ P["Q"]
    per = np.zeros((len(idx), 3, 5))
    for cols, (a, b), Mx in (((0, 3), (P["a"], P["b"]), M), ((3, 5), (P["ra"], P["rb"]), MS)):
        Ms = 0.5 * (Mx + np.swapaxes(Mx, 1, 2))
        ga = 2.0 * (Ms[:, 0, 0, None] * a + Ms[:, 0, 1, None] * b)
        gb = 2.0 * (Ms[:, 0, 1, None] * a + Ms[:, 1, 1, None] * b)
        per[:, 0, cols[0]:cols[1]] = -(ga + gb)
        per[:, 1, cols[0]:cols[1]] = ga
        per[:, 2, cols[0]:cols[1]] = gb
    return scatter_nd(s.nv, s.F[idx].ravel(), per.reshape(-1, 5))


def linear_elastic_b(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-facet ``linear_elastic_B`` energy, shape (len(idx),): the
    ``linear_elastic`` density of the strain of x1..x3 against the reference
    shape in x4, x5, times ``LEBweight`` when declared (manual, quants.htm)."""
    P = _strain(t, idx, "linear_elastic_b")
    w, _, _ = _linear_density(P["C"], P["nu"])
    return P["A0"] * w * _lebweight(t, idx)


def linear_elastic_b_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, 5) of ``Σ w_f E_f`` for ``linear_elastic_B``."""
    idx = np.asarray(idx, np.int64)
    P = _strain(t, idx, "linear_elastic_b")
    c = np.asarray(w, float) * P["A0"] * _lebweight(t, idx)
    dens, _, _ = _linear_density(P["C"], P["nu"])
    M = _linear_M(P) * c[:, None, None]
    return _b_gradient(t, idx, P, M, c * dens)


def _lebweight(t, idx):
    """The facet attribute ``LEBweight`` at ``idx`` (ones when not declared)."""
    weight = t.surface.extra.get(("facet", "lebweight"))
    if weight is None:
        weight = t.surface.extra.get(("facet", "LEBweight"))
    idx = np.asarray(idx, np.int64)
    return np.ones(len(idx)) if weight is None else np.asarray(weight, float)[idx]


def _gradient_from_M(t, idx, P, M):
    """Scatter ``dE = tr(M dF)`` (M (n, 2, 2), already times the weights) to
    the vertices: ``∂/∂a = 2(Ms11 a + Ms12 b)``, ``∂/∂b = 2(Ms12 a + Ms22 b)``."""
    Ms = 0.5 * (M + np.swapaxes(M, 1, 2))
    a, b = P["a"], P["b"]
    ga = 2.0 * (Ms[:, 0, 0, None] * a + Ms[:, 0, 1, None] * b)
    gb = 2.0 * (Ms[:, 0, 1, None] * a + Ms[:, 1, 1, None] * b)
    s = t.surface
    per = np.zeros((s.nf, 3, 3))
    per[idx, 0] = -(ga + gb)
    per[idx, 1] = ga
    per[idx, 2] = gb
    return corner_scatter(t, per)


def linear_elastic(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-facet ``linear_elastic`` energy, shape (len(idx),)."""
    P = _strain(t, idx, "linear_elastic")
    w, _, _ = _linear_density(P["C"], P["nu"])
    return P["A0"] * w


def linear_elastic_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, 3) of ``Σ w_f E_f`` for ``linear_elastic``."""
    idx = np.asarray(idx, np.int64)
    P = _strain(t, idx, "linear_elastic")
    M = _linear_M(P)
    M *= (np.asarray(w, float) * P["A0"])[:, None, None]
    return _gradient_from_M(t, idx, P, M)


def _linear_M(P):
    """``∂w/∂F`` (n, 2, 2) of the linear density."""
    C, Q, nu = P["C"], P["Q"], P["nu"]
    _, tr, k = _linear_density(C, nu)
    return (Q @ C + (k * tr)[:, None, None] * Q) / (2.0 * (1.0 + nu))[:, None, None]


def _relaxed(t, idx, name):
    """Pieces of the relaxed energies: the strain data ``P``, the branch of
    each facet (0 none, 1 one direction, 2 two), ``λ₁`` and ``y`` (n, 2)."""
    P = _strain(t, idx, name)
    n = len(P["A0"])
    ok = P["A0"] > 0
    # a reference metric that overflowed (huge reference coordinates): NaN values
    bad = ~np.all(np.isfinite(P["Q"]) & np.isfinite(P["F"]), axis=(1, 2))
    Q = np.where((ok & ~bad)[:, None, None], P["Q"], np.eye(2))
    L = np.linalg.cholesky(Q)                                  # Q = L Lᵀ
    R = np.swapaxes(L, 1, 2) @ np.where(bad[:, None, None], 0.0, P["F"]) @ L
    mu, r = np.linalg.eigh(R)                                  # ascending, of FQ
    mu[bad] = np.nan
    lam = 0.5 * (mu - 1.0)                                     # eigenvalues of C
    l1, l2 = lam[:, 1], lam[:, 0]
    nu = P["nu"]
    k = nu / (1.0 - nu)
    s1 = l1 + k * (l1 + l2)
    s2 = l2 + k * (l1 + l2)
    branch = np.zeros(n, np.int64)
    branch[l1 > 0] = 1
    branch[(s1 > 0) & (s2 > 0)] = 2
    branch[~ok] = 0
    y = np.einsum("nij,nj->ni", L, r[:, :, 1])
    return P, branch, l1, y, _lebweight(t, idx)


def _relaxed_values(t, idx, name, which):
    P, branch, l1, _, lw = _relaxed(t, idx, name)
    w_lin, _, _ = _linear_density(P["C"], P["nu"])
    e = np.where(branch == 2, w_lin, np.where(branch == 1, 0.5 * l1 ** 2, 0.0))
    if which:
        e = np.where(branch == which, e, 0.0)
    return P["A0"] * lw * e


def _relaxed_gradient(t, idx, w, name, which):
    idx = np.asarray(idx, np.int64)
    P, branch, l1, y, lw = _relaxed(t, idx, name)
    M2 = _linear_M(P)
    M1 = (0.5 * l1)[:, None, None] * np.einsum("ni,nj->nij", y, y)
    M = np.where((branch == 2)[:, None, None], M2,
                 np.where((branch == 1)[:, None, None], M1, 0.0))
    if which:
        M = np.where((branch == which)[:, None, None], M, 0.0)
    c = np.asarray(w, float) * P["A0"] * lw
    M = M * c[:, None, None]
    if _is_b(name):
        w_lin, _, _ = _linear_density(P["C"], P["nu"])
        e = np.where(branch == 2, w_lin, np.where(branch == 1, 0.5 * l1 ** 2, 0.0))
        if which:
            e = np.where(branch == which, e, 0.0)
        return _b_gradient(t, idx, P, M, c * e)
    return _gradient_from_M(t, idx, P, M)


def _relaxed_hessian(t, idx, w, name, which, basis=None):
    """Analytic Hessian of ``Σ w_f E_f`` for the three-dimensional relaxed
    methods, branch by branch (the branch held fixed): the linear density's
    (:func:`linear_elastic_hessian`) where both stresses are positive; for
    ``λ₁²/2`` with ``λ₁ = (μ₁ − 1)/2``, ``μ₁ ≥ μ₂`` the eigenvalues of
    ``Lᵀ F L`` (unit eigenvectors ``r₁, r₂``, ``y = L r₁``, ``z = L r₂``):
    ``d²(λ₁²/2) = (yᵀdF y)²/4 + λ₁ (yᵀdF z)²/(μ₁ − μ₂)``; zero elsewhere."""
    idx = np.asarray(idx, np.int64)
    P = _strain(t, idx, name)
    n = len(idx)
    ok = P["A0"] > 0
    Q = np.where(ok[:, None, None], P["Q"], np.eye(2))
    L = np.linalg.cholesky(Q)
    mu, r = np.linalg.eigh(np.swapaxes(L, 1, 2) @ P["F"] @ L)
    lam = 0.5 * (mu - 1.0)
    l1, l2 = lam[:, 1], lam[:, 0]
    nu = P["nu"]
    k = nu / (1.0 - nu)
    branch = np.zeros(n, np.int64)
    branch[l1 > 0] = 1
    branch[(l1 + k * (l1 + l2) > 0) & (l2 + k * (l1 + l2) > 0)] = 2
    branch[~ok] = 0
    if which:
        branch = np.where(branch == which, branch, 0)
    c = np.asarray(w, float) * P["A0"] * _lebweight(t, idx)
    # the linear branch
    M2 = _linear_M(P)
    EQ = np.einsum("jab,nbc->njac", _E, P["Q"])
    tr2 = np.einsum("niab,njba->nij", EQ, EQ)
    tr1 = np.einsum("niaa->ni", EQ)
    H2 = (tr2 + k[:, None, None] * tr1[:, :, None] * tr1[:, None, :]) \
        / (4.0 * (1.0 + nu))[:, None, None]
    # the uniaxial branch
    y = np.einsum("nij,nj->ni", L, r[:, :, 1])
    z = np.einsum("nij,nj->ni", L, r[:, :, 0])
    M1 = (0.5 * l1)[:, None, None] * np.einsum("ni,nj->nij", y, y)
    u = np.einsum("na,jab,nb->nj", y, _E, y)
    v = np.einsum("na,jab,nb->nj", y, _E, z)
    gap = mu[:, 1] - mu[:, 0]
    one = branch == 1
    g1 = np.where(one, l1 / np.where(gap > 0, gap, 1.0), 0.0)
    H1 = 0.25 * np.einsum("ni,nj->nij", u, u) + g1[:, None, None] * np.einsum("ni,nj->nij", v, v)
    sel2, sel1 = (branch == 2)[:, None, None], one[:, None, None]
    M = np.where(sel2, M2, np.where(sel1, M1, 0.0)) * c[:, None, None]
    Hf = np.where(sel2, H2, np.where(sel1, H1, 0.0)) * c[:, None, None]
    gf = np.stack([M[:, 0, 0], M[:, 0, 1] + M[:, 1, 0], M[:, 1, 1]], 1)
    return _hessian_from_f(t, idx, P, gf, Hf, basis)


def _register_relaxed(name: str, which: int) -> None:
    def values(t, m, idx):
        return _relaxed_values(t, idx, name, which)

    def gradient(t, m, idx, w):
        return _relaxed_gradient(t, idx, w, name, which)

    def hessian(t, m, idx, w, basis=None):
        return _relaxed_hessian(t, idx, w, name, which, basis)

    values.__doc__ = f"Per-facet ``{name}`` energy, shape (len(idx),)."
    gradient.__doc__ = f"Gradient (nv, 3) of ``Σ w_f E_f`` for ``{name}``."
    hessian.__doc__ = f"Analytic Hessian of ``Σ w_f E_f`` for ``{name}`` (:func:`_relaxed_hessian`)."
    register_method(name, "facet", values, gradient, None if _is_b(name) else hessian)


def _ff_strain(t, idx, name):
    """:func:`_strain` for methods that need only ``form_factors``."""
    s = t.surface
    if ("facet", "poisson_ratio") in s.extra:
        return _strain(t, idx, name)
    s.extra[("facet", "poisson_ratio")] = np.zeros(s.nf)
    try:
        return _strain(t, idx, name)
    finally:
        del s.extra[("facet", "poisson_ratio")]


def dirichlet_elastic(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-facet ``dirichlet_elastic`` energy ``A0 Tr(FQ)`` (evolver-nox-d's
    value; the manual's ``Tr(CCᵀ)`` of the deformation C), shape (len(idx),)."""
    P = _ff_strain(t, idx, "dirichlet_elastic")
    return P["A0"] * np.einsum("nij,nji->n", P["F"], P["Q"])


def dirichlet_elastic_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, 3) of ``Σ w_f A0 Tr(F Q)``: ``M = w A0 Q``."""
    idx = np.asarray(idx, np.int64)
    P = _ff_strain(t, idx, "dirichlet_elastic")
    M = P["Q"] * (np.asarray(w, float) * P["A0"])[:, None, None]
    return _gradient_from_M(t, idx, P, M)


_E = np.array([[[1.0, 0.0], [0.0, 0.0]], [[0.0, 1.0], [1.0, 0.0]], [[0.0, 0.0], [0.0, 1.0]]])


def _hessian_from_f(t, idx, P, gf, Hf, basis):
    """Assemble ``Σ_f [Jᵀ Hf J + Σ_j gf_j ∂²f_j]`` over the facets, with
    ``f = (F11, F12, F22)`` the Gram entries, ``gf`` (n, 3) and ``Hf``
    (n, 3, 3) the derivatives of the facet energy w.r.t. them."""
    a, b = P["a"], P["b"]
    n = len(a)
    # J: (n, 3 entries, 2 sides, 3 coords); dF11 = 2a·da, dF12 = a·db + b·da, dF22 = 2b·db
    J = np.zeros((n, 3, 2, 3))
    J[:, 0, 0] = 2 * a
    J[:, 1, 0] = b
    J[:, 1, 1] = a
    J[:, 2, 1] = 2 * b
    Hs = np.einsum("njsc,njk,nktd->nsctd", J, Hf, J)           # (n, 2, 3, 2, 3)
    eye = np.eye(3)
    Hs[:, 0, :, 0, :] += 2 * gf[:, 0, None, None] * eye
    Hs[:, 0, :, 1, :] += gf[:, 1, None, None] * eye
    Hs[:, 1, :, 0, :] += gf[:, 1, None, None] * eye
    Hs[:, 1, :, 1, :] += 2 * gf[:, 2, None, None] * eye
    T = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])        # vertex <- sides
    blocks = np.einsum("is,nsctd,jt->nijcd", T, Hs, T)            # (n, 3, 3, 3, 3)
    s = t.surface
    return assemble(s.nv, s.F[idx], blocks, basis)


def linear_elastic_hessian(t: Any, m: Any, idx: np.ndarray, w: np.ndarray,
                           basis: Any = None) -> Any:
    """Analytic Hessian of ``Σ w_f E_f`` for ``linear_elastic``: the density's
    second derivative ``(tr(dF₁Q dF₂Q) + k tr(dF₁Q) tr(dF₂Q)) / (4(1+ν))`` and
    its first derivative times the Gram entries' second derivatives."""
    idx = np.asarray(idx, np.int64)
    P = _strain(t, idx, "linear_elastic")
    c = np.asarray(w, float) * P["A0"]
    M = _linear_M(P) * c[:, None, None]
    gf = np.stack([M[:, 0, 0], M[:, 0, 1] + M[:, 1, 0], M[:, 1, 1]], 1)
    EQ = np.einsum("jab,nbc->njac", _E, P["Q"])                  # (n, 3, 2, 2)
    tr2 = np.einsum("niab,njba->nij", EQ, EQ)
    tr1 = np.einsum("niaa->ni", EQ)
    nu = P["nu"]
    k = nu / (1.0 - nu)
    Hf = (tr2 + k[:, None, None] * tr1[:, :, None] * tr1[:, None, :]) \
        * (c / (4.0 * (1.0 + nu)))[:, None, None]
    return _hessian_from_f(t, idx, P, gf, Hf, basis)


def dirichlet_elastic_hessian(t: Any, m: Any, idx: np.ndarray, w: np.ndarray,
                              basis: Any = None) -> Any:
    """Analytic Hessian of ``Σ w_f A0 Tr(FQ)`` (linear in F)."""
    idx = np.asarray(idx, np.int64)
    P = _ff_strain(t, idx, "dirichlet_elastic")
    M = P["Q"] * (np.asarray(w, float) * P["A0"])[:, None, None]
    gf = np.stack([M[:, 0, 0], M[:, 0, 1] + M[:, 1, 0], M[:, 1, 1]], 1)
    return _hessian_from_f(t, idx, P, gf, np.zeros((len(idx), 3, 3)), basis)


register_method("linear_elastic", "facet", linear_elastic, linear_elastic_gradient,
                linear_elastic_hessian)
register_method("dirichlet_elastic", "facet", dirichlet_elastic, dirichlet_elastic_gradient,
                dirichlet_elastic_hessian)
_register_relaxed("relaxed_elastic_a", 0)
_register_relaxed("relaxed_elastic1_a", 1)
_register_relaxed("relaxed_elastic2_a", 2)
# the five-dimensional variants: reference shape in x4, x5 (no analytic Hessian)
register_method("linear_elastic_b", "facet", linear_elastic_b, linear_elastic_b_gradient)
_register_relaxed("relaxed_elastic", 0)
_register_relaxed("relaxed_elastic1", 1)
_register_relaxed("relaxed_elastic2", 2)
