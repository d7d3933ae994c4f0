"""Second-order jets of small per-element functions, vectorized over elements.

A curvature energy is a sum of smooth functions of a few vertices (the
three corners of a facet, the four vertices of an edge's two facets).  Their
Hessians are long to write out by hand; these jets carry the value, the
gradient and the Hessian through the few operations the energies use
(differences, cross and dot products, norms, quotients, ``atan2``), so each
element's exact ``n × n`` Hessian (``n = 3 × points``) comes from the same
expression as its value.  Forward-mode second-order differentiation
(Griewank & Walther, *Evaluating Derivatives*, 2008, ch. 13), specialised
to 3-vectors: a vector jet never stores its (m, 3, n, n) Hessian, only
a function giving the Hessian of ``w · V`` for a vector ``w`` held fixed.

Shapes: ``m`` elements, ``n`` local coordinates.  :class:`S` has ``v (m,)``,
``g (m, n)``, ``H (m, n, n)``; :class:`V` has ``v (m, 3)``, ``J (m, 3, n)``
and ``hc(w) -> (m, n, n)``.
"""
from __future__ import annotations

import numpy as np


def skew(v):
    """(m, 3) -> (m, 3, 3) matrices ``[v]×`` with ``[v]× u = v × u``."""
    z = np.zeros(len(v))
    return np.stack([np.stack([z, -v[:, 2], v[:, 1]], 1),
                     np.stack([v[:, 2], z, -v[:, 0]], 1),
                     np.stack([-v[:, 1], v[:, 0], z], 1)], 1)


class S:
    """Scalar jet: value ``v``, gradient ``g`` and Hessian ``H``."""

    __slots__ = ("v", "g", "H")

    def __init__(self, v, g, H):
        self.v, self.g, self.H = v, g, H

    def __add__(self, o):
        if isinstance(o, S):
            return S(self.v + o.v, self.g + o.g, self.H + o.H)
        return S(self.v + o, self.g, self.H)

    def __sub__(self, o):
        if isinstance(o, S):
            return S(self.v - o.v, self.g - o.g, self.H - o.H)
        return S(self.v - o, self.g, self.H)

    def __neg__(self):
        return S(-self.v, -self.g, -self.H)

    def __mul__(self, o):
        if isinstance(o, S):
            H = (self.v[:, None, None] * o.H + o.v[:, None, None] * self.H
                 + self.g[:, :, None] * o.g[:, None, :] + o.g[:, :, None] * self.g[:, None, :])
            return S(self.v * o.v, self.v[:, None] * o.g + o.v[:, None] * self.g, H)
        o = np.asarray(o, float)
        if o.ndim == 1:
            return S(self.v * o, self.g * o[:, None], self.H * o[:, None, None])
        return S(self.v * o, self.g * o, self.H * o)

    __radd__ = __add__
    __rmul__ = __mul__

    def __truediv__(self, o):
        if isinstance(o, S):
            return self * o.apply(1.0 / o.v, -1.0 / o.v ** 2, 2.0 / o.v ** 3)
        return self * (1.0 / np.asarray(o, float))

    def apply(self, f, f1, f2):
        """``φ(self)`` given ``φ``, ``φ'`` and ``φ''`` at the values (m,)."""
        return S(f, f1[:, None] * self.g,
                 f1[:, None, None] * self.H + f2[:, None, None] * self.g[:, :, None] * self.g[:, None, :])

    def sqrt(self):
        r = np.sqrt(self.v)
        with np.errstate(all="ignore"):
            return self.apply(r, 0.5 / r, -0.25 / (r * self.v))


def atan2(y, x):
    """Jet of ``atan2(y, x)``: dθ = (x dy − y dx)/R with R = x² + y²."""
    R = x.v * x.v + y.v * y.v
    with np.errstate(all="ignore"):
        a, b = x.v / R, -y.v / R
    g = a[:, None] * y.g + b[:, None] * x.g
    # d²θ = (x d²y − y d²x)/R − (x dy − y dx)(x dx + y dy)·2/R² (the
    # antisymmetric dx dy − dy dx drops out of the symmetric Hessian)
    q = x.v[:, None] * x.g + y.v[:, None] * y.g
    with np.errstate(all="ignore"):
        t = g[:, :, None] * q[:, None, :] / R[:, None, None]
    H = a[:, None, None] * y.H + b[:, None, None] * x.H - t - np.swapaxes(t, 1, 2)
    return S(np.arctan2(y.v, x.v), g, H)


class V:
    """Vector jet: value ``v`` (m, 3), Jacobian ``J`` (m, 3, n) and ``hc``,
    ``hc(w)`` the Hessian (m, n, n) of ``w · V`` at fixed ``w`` (m, 3)
    (None when V is linear)."""

    __slots__ = ("J", "_hc", "coef", "v")

    def __init__(self, v, J, hc=None, coef=None):
        # coef (k,): V = Σ_i coef_i x_i, the same combination of the points
        # for every element (then J = coef ⊗ I and products have closed forms)
        self.v, self.J, self._hc, self.coef = v, J, hc, coef

    def hc(self, w):
        if self._hc is None:
            m, _, n = self.J.shape
            return np.zeros((m, n, n))
        return self._hc(w)

    def __add__(self, o):
        return V(self.v + o.v, self.J + o.J, _sum_hc(self, o, 1.0), _combine(self, o, 1.0))

    def __sub__(self, o):
        return V(self.v - o.v, self.J - o.J, _sum_hc(self, o, -1.0), _combine(self, o, -1.0))

    def __mul__(self, s):
        """``s V`` for a scalar jet (or array) ``s``."""
        if not isinstance(s, S):
            s = np.asarray(s, float)
            sv = s if s.ndim else np.full(len(self.v), float(s))
            hc = None if self._hc is None else (lambda w: self.hc(w * sv[:, None]))
            coef = self.coef * float(s) if (self.coef is not None and not s.ndim) else None
            return V(self.v * sv[:, None], self.J * sv[:, None, None], hc, coef)
        a = self

        def hc(w):
            Jw = _vJ(w, a.J)
            wa = np.einsum("mk,mk->m", w, a.v)
            out = wa[:, None, None] * s.H + s.g[:, :, None] * Jw[:, None, :] \
                + Jw[:, :, None] * s.g[:, None, :]
            if a._hc is not None:
                out += a.hc(w * s.v[:, None])
            return out
        return V(a.v * s.v[:, None], a.J * s.v[:, None, None] + a.v[:, :, None] * s.g[:, None, :], hc)

    __rmul__ = __mul__


def _combine(a, b, sign):
    if a.coef is None or b.coef is None:
        return None
    return a.coef + sign * b.coef


def _kron3(C, Q):
    """(m, 3k, 3k) matrices with 3×3 blocks ``C_ij Q`` for C (k, k), Q (m, 3, 3)."""
    k = len(C)
    out = C[None, :, None, :, None] * Q[:, None, :, None, :]
    return out.reshape(len(Q), 3 * k, 3 * k)


def _sum_hc(a, b, sign):
    if a._hc is None and b._hc is None:
        return None
    return lambda w: a.hc(w) + sign * b.hc(w)


def points(P):
    """Vector jets of the points ``P`` (m, k, 3) themselves, n = 3k."""
    m, k, _ = P.shape
    out = []
    for i in range(k):
        J = np.zeros((m, 3, 3 * k))
        J[:, :, 3 * i:3 * i + 3] = np.eye(3)
        coef = np.zeros(k)
        coef[i] = 1.0
        out.append(V(P[:, i].copy(), J, coef=coef))
    return out


def _vJ(v, Jm):
    """``vᵀ J`` (m, n) for vectors v (m, 3) and Jacobians J (m, 3, n)."""
    return v[:, 0, None] * Jm[:, 0] + v[:, 1, None] * Jm[:, 1] + v[:, 2, None] * Jm[:, 2]


def _JtJ(A, B):
    """``Aᵀ B`` (m, n, n) for Jacobians A, B (m, 3, n): three outer products
    (faster than a batched matmul of 3-row matrices)."""
    out = A[:, 0, :, None] * B[:, 0, None, :]
    out += A[:, 1, :, None] * B[:, 1, None, :]
    out += A[:, 2, :, None] * B[:, 2, None, :]
    return out


def dot(a, b):
    """Scalar jet of ``a · b``."""
    g = _vJ(b.v, a.J) + _vJ(a.v, b.J)
    if a.coef is not None and b.coef is not None:
        C = np.outer(a.coef, b.coef)
        H = _kron3(C + C.T, np.broadcast_to(np.eye(3), (len(g), 3, 3)))
    else:
        JJ = _JtJ(a.J, b.J)
        H = JJ + np.swapaxes(JJ, 1, 2)
    if a._hc is not None:
        H += a.hc(b.v)
    if b._hc is not None:
        H += b.hc(a.v)
    return S(np.einsum("mk,mk->m", a.v, b.v), g, H)


def cross(a, b):
    """Vector jet of ``a × b``."""
    v = np.cross(a.v, b.v)
    J = np.cross(a.v[:, :, None], b.J, axis=1) - np.cross(b.v[:, :, None], a.J, axis=1)

    def hc(w):
        # w·(a×b): a·(b×w) and b·(w×a) through the Hessians of a and b,
        # and 2 w·(da × db) = −2 daᵀ [w]× db
        if a.coef is not None and b.coef is not None:
            C = np.outer(a.coef, b.coef)
            out = _kron3(C.T - C, skew(w))            # [w]×ᵀ = −[w]×
        else:
            K = _JtJ(a.J, np.cross(w[:, :, None], b.J, axis=1))
            out = -(K + np.swapaxes(K, 1, 2))
        if a._hc is not None:
            out += a.hc(np.cross(b.v, w))
        if b._hc is not None:
            out += b.hc(np.cross(w, a.v))
        return out
    return V(v, J, hc)


def cross_const(a, c):
    """Vector jet of ``a × c`` for a constant vector ``c`` (m, 3)."""
    J = -np.cross(c[:, :, None], a.J, axis=1)
    hc = None if a._hc is None else (lambda w: a.hc(np.cross(c, w)))
    return V(np.cross(a.v, c), J, hc)


def norm(a):
    """Scalar jet of ``|a|``."""
    return dot(a, a).sqrt()
