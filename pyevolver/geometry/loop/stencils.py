"""Basis maps of Loop patches: control points -> limit position and its first
and second derivatives at quadrature points.

Regular patch (all corners valence 6).  The Loop limit surface over a
regular triangle is the three-direction quartic box spline: one polynomial
of total degree 4 in the patch parameters, a fixed linear combination of 12
control points (Loop 1987; Stam 1998; Cirak, Ortiz, Schröder 2000).  Here
it is *derived* from Loop's rules rather than typed in: each control point's
basis function is computed by subdividing a unit impulse on the regular
lattice three times, taking exact limit positions (the limit mask
½ v + 1/12 Σ neighbours) at the 45 level-3 lattice points of the patch, and
fitting the 15 monomials ``u^i v^j`` (i + j <= 4); the fit residual
(~1e-16) certifies that the limit is that quartic.

Lattice coordinates: the patch is ``a = (0,0), b = (1,0), c = (0,1)``, the
point with parameters ``(u, v)`` is ``a + u (b − a) + v (c − a)``; the 12
control points in the order of :mod:`.patches` are ``LATTICE12``.

Patch with one extraordinary corner of valence N (Stam 1998 evaluates it by
the eigen-decomposition of the subdivision matrix; here by explicitly
applying that matrix).  One Loop step splits the patch into four; the three
children away from the extraordinary corner are regular, the fourth is again
such a patch of half the size, whose N + 6 control points are a fixed linear
map ``A`` (N+6, N+6) of the parent's.  The domain is the union of the
regular children of levels 1..L, each integrated by the regular rule in its
own parameters; the remaining corner piece (parameter area 4^-L) is left
out, with L per valence chosen from the eigenvalues of ``A`` so that the
part of W left out is ~1e-10 relative (see :func:`ev_levels`).  The powers
of ``A`` are applied to the control points minus their limit point, which
keeps the deep levels accurate (:func:`patch_basis`).
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from .patches import HalfEdges, gather_ring, limit_weights, loop_subdivide, template

LATTICE12 = np.array([(0, 0), (1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1),
                      (2, -1), (2, 0), (1, 1), (0, 2), (-1, 2)])
MONOMIALS = [(i, d - i) for d in range(5) for i in range(d, -1, -1)]   # u^i v^j, 15

# lattice neighbours of (0, 0), counter-clockwise
_NB = [(1, 0), (0, 1), (-1, 1), (-1, 0), (0, -1), (1, -1)]


def _lattice_subdivide(A):
    """One regular Loop step on lattice values ``A[i, j]`` (zero-padded,
    periodic roll): the result ``B[2i, 2j]`` vertex points, ``B[2i+1, 2j]``,
    ``B[2i, 2j+1]``, ``B[2i+1, 2j+1]`` the points of the edges
    (i,j)-(i+1,j), (i,j)-(i,j+1), (i+1,j)-(i,j+1)."""
    def sh(di, dj):
        return np.roll(A, (-di, -dj), axis=(0, 1))          # sh[i, j] = A[i+di, j+dj]
    nb = sum(sh(*d) for d in _NB)
    n = A.shape[0]
    B = np.zeros((2 * n, 2 * n))
    B[0::2, 0::2] = 0.625 * A + 0.0625 * nb
    B[1::2, 0::2] = 0.375 * (A + sh(1, 0)) + 0.125 * (sh(0, 1) + sh(1, -1))
    B[0::2, 1::2] = 0.375 * (A + sh(0, 1)) + 0.125 * (sh(1, 0) + sh(-1, 1))
    B[1::2, 1::2] = 0.375 * (sh(1, 0) + sh(0, 1)) + 0.125 * (A + sh(1, 1))
    return B


def _lattice_limit(A):
    c, w = limit_weights(6)
    return c * A + w * sum(np.roll(A, (-d[0], -d[1]), axis=(0, 1)) for d in _NB)


def lattice_limit_values(levels=3, size=16):
    """Exact limit-surface values of the 12 regular basis functions at the
    lattice points ``(i, j)/2^levels`` (i + j <= 2^levels) of the patch.

    Returns ``(uv (m, 2), vals (m, 12))``."""
    o = size // 2 - 2
    m = 2 ** levels
    ij = np.array([(i, j) for i in range(m + 1) for j in range(m + 1 - i)])
    vals = np.empty((len(ij), 12))
    for k, (di, dj) in enumerate(LATTICE12):
        A = np.zeros((size, size))
        A[o + di, o + dj] = 1.0
        for _ in range(levels):
            A = _lattice_subdivide(A)
        L = _lattice_limit(A)
        vals[:, k] = L[o * m + ij[:, 0], o * m + ij[:, 1]]
    return ij / m, vals


@lru_cache(maxsize=None)
def regular_coefficients():
    """Monomial coefficients (12, 15) of the regular basis functions and the
    fit residual (max abs) that certifies them (see module docstring)."""
    uv, vals = lattice_limit_values(3)
    V = np.stack([uv[:, 0] ** i * uv[:, 1] ** j for i, j in MONOMIALS], 1)     # (45, 15)
    C, *_ = np.linalg.lstsq(V, vals, rcond=None)
    resid = float(np.abs(V @ C - vals).max())
    return C.T.copy(), resid


def _monomial_derivs(u, v):
    """(6, len(u), 15): value, d/du, d/dv, d²/du², d²/dudv, d²/dv² of each monomial."""
    u = np.asarray(u, float)
    v = np.asarray(v, float)
    out = np.zeros((6, len(u), 15))

    def pw(x, k):
        return x ** k if k >= 0 else np.zeros_like(x)
    for m, (i, j) in enumerate(MONOMIALS):
        out[0, :, m] = pw(u, i) * pw(v, j)
        out[1, :, m] = i * pw(u, i - 1) * pw(v, j)
        out[2, :, m] = j * pw(u, i) * pw(v, j - 1)
        out[3, :, m] = i * (i - 1) * pw(u, i - 2) * pw(v, j)
        out[4, :, m] = i * j * pw(u, i - 1) * pw(v, j - 1)
        out[5, :, m] = j * (j - 1) * pw(u, i) * pw(v, j - 2)
    return out


def regular_basis(u, v):
    """Regular-patch basis at parameters ``(u, v)``.

    Parameters
    ----------
    u, v : (m,) arrays
        Patch parameters (point ``a + u (b − a) + v (c − a)``).

    Returns
    -------
    B : (m, 6, 12)
        ``B[q, d, k]``: derivative ``d`` (x, x_u, x_v, x_uu, x_uv, x_vv) of the
        basis function of control point ``k`` (order of :mod:`.patches`).
    """
    C, _ = regular_coefficients()
    D = _monomial_derivs(u, v)                     # (6, m, 15)
    return np.einsum("dqm,km->qdk", D, C)


@lru_cache(maxsize=None)
def triangle_rule(n):
    """Collapsed Gauss–Jacobi rule with n² points on the triangle
    ``u, v >= 0, u + v <= 1`` (Duffy: u = ξ, v = (1 − ξ) η; Gauss–Jacobi with
    weight (1 − ξ) in ξ, Gauss–Legendre in η): exact for polynomials of
    degree 2n − 1.  Returns ``(u (n²,), v (n²,), w (n²,))``, Σ w = 1/2."""
    from scipy.special import roots_jacobi     # 0.4 s to import: only when used
    xj, wj = roots_jacobi(n, 1.0, 0.0)            # weight (1 - x) on [-1, 1]
    xi = (1 + xj) / 2
    wxi = wj / 4                                   # ∫0^1 (1-ξ) g dξ
    xl, wl = np.polynomial.legendre.leggauss(n)
    eta = (1 + xl) / 2
    weta = wl / 2
    U = np.repeat(xi, n)
    V = (1 - U) * np.tile(eta, n)
    W = np.repeat(wxi, n) * np.tile(weta, n)
    return U, V, W


@lru_cache(maxsize=None)
def ev_structure(N):
    """Per valence N: ``(A (N+6, N+6), R (3, 12, N+6))`` — the control points
    of the extraordinary child and of the three regular children (corner b,
    corner c, middle) after one Loop step, from the parent's N + 6."""
    T = template(N)
    S, F1, ok = loop_subdivide(T, N + 6)
    S = S.toarray()
    he = HalfEdges(F1, S.shape[0])
    # children of the patch (facet 0): 0 at corner a (extraordinary), 1, 2, 3 regular
    ev = gather_ring(he, np.array([0]), N)[0]
    regs = gather_ring(he, np.array([3 * 1, 3 * 2, 3 * 3]), 6)
    if not ok[ev].all() or not ok[regs].all():
        raise AssertionError("1-ring template too small")   # cannot happen for N >= 3
    return S[ev], np.stack([S[r] for r in regs])


def ev_eigen(N):
    """Subdominant eigenvalue λ and the largest eigenvalue modulus μ below it
    of the extraordinary child map ``A`` (Stam 1998)."""
    A, _ = ev_structure(N)
    ev = np.sort(np.abs(np.linalg.eigvals(A)))[::-1]
    lam = ev[1]
    mu = ev[ev < lam - 1e-9][0]
    return lam, mu


def ev_levels(N, tol=1e-10, cap=80):
    """Number of dyadic levels L integrated on a patch with a valence-N corner.

    The integrand of W over the level-n ring decays like ρ^n with
    ρ = max(λ², μ²/λ²) (area ∝ λ^2n, second fundamental form
    ∝ max(λ, μ/λ)^n); L is the smallest level with ρ^L <= tol (at most
    ``cap``): 12 to 17 levels for N <= 7, 69 for N = 12."""
    lam, mu = ev_eigen(N)
    rho = max(lam * lam, (mu / lam) ** 2)
    return max(1, min(int(np.ceil(np.log(tol) / np.log(rho))), cap))


@lru_cache(maxsize=None)
def patch_basis(N, n, composite=None):
    """Quadrature basis of a patch with corner valence N and base rule ``n``.

    ``composite`` (default: N != 6) integrates by the dyadic rings of regular
    children; for N = 6 that is a cross-check of the recursive construction
    against the box spline itself.

    Returns
    -------
    B : (Q, 6, N + 6)
        Position and derivatives at the Q quadrature points, each in the
        parameters of the (sub-)patch the point lies in.
    w : (Q,)
        Weights: ``∫ f dA ≈ Σ_q w_q f(q)`` with ``dA = |x_u × x_v| du dv``.
    """
    u, v, w = triangle_rule(n)
    Breg = regular_basis(u, v)                     # (q, 6, 12)
    if composite is None:
        composite = N != 6
    if not composite:
        return Breg, w
    A, R = ev_structure(N)
    L = ev_levels(N)
    # Control points at level n: 1 lᵀ + A^n (I − 1 lᵀ), l the limit-point
    # weights (lᵀ A = lᵀ).  Iterating on the part without the constant mode
    # keeps its relative precision (~1e-16 of λ^n, not of 1), and the
    # constant mode enters the position row only: derivatives of the regular
    # basis annihilate constants exactly.
    c, wn = limit_weights(N)
    lvec = np.zeros(N + 6)
    lvec[0], lvec[1:N + 1] = c, wn
    M = np.eye(N + 6) - np.outer(np.ones(N + 6), lvec)
    const = np.zeros((1, 6, N + 6))
    const[0, 0] = lvec
    blocks = []
    for _ in range(L):
        for k in range(3):
            blocks.append(Breg @ (R[k] @ M) + const)      # (q, 6, N+6)
        M = A @ M
    B = np.concatenate(blocks, 0)
    return B, np.tile(w, 3 * L)
