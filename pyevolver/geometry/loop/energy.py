"""The true Willmore energy, area and volume of a Loop limit surface, and
their gradients with respect to the control points.

On a patch with parameters (u, v) and limit map x(u, v) (derivatives from
:mod:`.stencils`), with ``n = x_u × x_v``, ``E, F, G`` the first fundamental
form and ``L' = x_uu·n, M' = x_uv·n, N' = x_vv·n``::

    H  = (E N' − 2 F M' + G L') / (2 |n|³)      mean curvature (κ1 + κ2)/2
    W  = ∫ H² |n| du dv = ∫ Q² / (4 |n|⁵) du dv,  Q = E N' − 2 F M' + G L'
    A  = ∫ |n| du dv
    V  = ∫ x·n / 3 du dv                         (divergence theorem)

integrated by the rules of :func:`.stencils.patch_basis`.  Every derivative
of x is linear in the control points (``D = B P``), so the gradient is
``Bᵀ (∂density/∂D)`` summed over quadrature points, then ``Sᵀ`` when the
control mesh was subdivided first.

Default rule: n = 6 (36 points per regular sub-patch), from a convergence
test (``tests/geometry/test_loop.py::test_quadrature_order_converges``): relative
change of W from n to n + 1 on the 5×9 torus (R = 2, r = 1, a coarse and
strongly curved control mesh) 9e-4 (n = 4), 1.3e-5 (5), 4.8e-6 (6),
1.2e-7 (7); on the twice-refined icosahedron 8e-6, 5e-8, 1.3e-9, 3e-11.
"""
from __future__ import annotations

import numpy as np

from .patches import LoopTopology
from .stencils import patch_basis

DEFAULT_ORDER = 6
KINDS = ("W", "A", "V")


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _mm(A, B):
    """``A @ B``; small products by einsum, which avoids the start-up cost of
    threaded BLAS (large on a loaded machine: 10× for the 5×9 torus)."""
    if B.shape[1] < 4096:
        return np.einsum("ak,kb->ab", A, B)
    return A @ B


def densities(D):
    """Integrand densities per du dv from derivatives ``D (6, 3, ...)``
    (x, x_u, x_v, x_uu, x_uv, x_vv; xyz first).  Returns ``(W, A, V)``."""
    x, xu, xv, xuu, xuv, xvv = D
    n = _cross(xu, xv)
    Dn = _dot(n, n)
    E, Fm, G = _dot(xu, xu), _dot(xu, xv), _dot(xv, xv)
    Q = E * _dot(xvv, n) - 2 * Fm * _dot(xuv, n) + G * _dot(xuu, n)
    with np.errstate(divide="ignore", invalid="ignore"):
        W = Q * Q / (4 * Dn ** 2.5)
    return W, np.sqrt(Dn), _dot(x, n) / 3.0


def density_gradients(D, kind):
    """∂density/∂D (6, 3, ...) of density ``kind`` ("W", "A", "V")."""
    x, xu, xv, xuu, xuv, xvv = D
    n = _cross(xu, xv)
    Dn = _dot(n, n)
    g = np.zeros_like(np.asarray(D))
    with np.errstate(divide="ignore", invalid="ignore"):
        if kind == "W":
            E, Fm, G = _dot(xu, xu), _dot(xu, xv), _dot(xv, xv)
            Lp, Mp, Np = _dot(xuu, n), _dot(xuv, n), _dot(xvv, n)
            Q = E * Np - 2 * Fm * Mp + G * Lp
            k = Q / (2 * Dn ** 2.5)
            c = -1.25 * Q * Q / Dn ** 3.5
            a = [k * (E * xvv[i] - 2 * Fm * xuv[i] + G * xuu[i]) + c * n[i] for i in range(3)]
            gu, gv = _cross(xv, a), _cross(a, xu)
            for i in range(3):
                g[1, i] = gu[i] + 2 * k * (Np * xu[i] - Mp * xv[i])
                g[2, i] = gv[i] + 2 * k * (Lp * xv[i] - Mp * xu[i])
                g[3, i] = k * G * n[i]
                g[4, i] = -2 * k * Fm * n[i]
                g[5, i] = k * E * n[i]
        elif kind == "A":
            J = np.sqrt(Dn)
            a = [n[i] / J for i in range(3)]
            gu, gv = _cross(xv, a), _cross(a, xu)
            for i in range(3):
                g[1, i], g[2, i] = gu[i], gv[i]
        elif kind == "V":
            a = [x[i] / 3.0 for i in range(3)]
            gu, gv = _cross(xv, a), _cross(a, xu)
            for i in range(3):
                g[0, i] = n[i] / 3.0
                g[1, i], g[2, i] = gu[i], gv[i]
        else:
            raise ValueError(kind)
    return g


class LoopEvaluator:
    """W, area and volume of the Loop limit surface of a closed triangle mesh.

    Parameters
    ----------
    F : (nf, 3) int
        Counter-clockwise (outward) triangles of the control mesh.
    nv : int
        Number of control vertices.
    order : int
        Base quadrature rule (:func:`.stencils.triangle_rule`): order² points
        per regular (sub-)patch.

    Raises :class:`pyevolver.errors.UnsupportedError` for an open,
    non-manifold or inconsistently oriented mesh, or valence > 12.
    """

    CHUNK = 1 << 17        # quadrature points per block (memory bound)

    def __init__(self, F, nv, order=DEFAULT_ORDER, what="Loop subdivision surfaces"):
        self.topo = LoopTopology(F, nv, what)
        self.order = order
        self.nv = int(nv)
        self.nf = len(F)
        self.blocks = []           # (B (Q,6,K), w (Q,), ctrl (p,K), owner (p,))
        for N, (ctrl, owner) in sorted(self.topo.classes.items()):
            B, w = patch_basis(N, order)
            step = max(1, self.CHUNK // len(w))
            for s in range(0, len(ctrl), step):
                self.blocks.append((B, w, ctrl[s:s + step], owner[s:s + step]))
        self._key = None
        self._cache = None

    def control_points(self, X):
        X = np.asarray(X, float)
        S = self.topo.S
        return X if S is None else S @ X

    def _derivs(self, X):
        X = np.asarray(X, float)
        if self._key is not None and self._key.shape == X.shape and np.array_equal(self._key, X):
            return self._cache
        Xc = self.control_points(X)
        out = []
        for B, w, ctrl, owner in self.blocks:
            Q, _, K = B.shape
            P = Xc[ctrl]                                      # (p, K, 3)
            Pt = P.transpose(1, 2, 0).reshape(K, -1)          # (K, 3p)
            D = _mm(B.reshape(Q * 6, K), Pt).reshape(Q, 6, 3, -1).transpose(1, 2, 0, 3)
            out.append(D)                                     # (6, 3, Q, p)
        self._key = X.copy()
        self._cache = out
        return out

    def values(self, X):
        """Per facet of the control mesh: ``{"W", "A", "V"} -> (nf,)``, the
        Willmore energy ∫H² dA, area and volume of the part of the limit
        surface over that facet (sums are the totals)."""
        res = {k: np.zeros(self.nf) for k in KINDS}
        for D, (B, w, ctrl, owner) in zip(self._derivs(X), self.blocks):
            for k, dens in zip(KINDS, densities(D)):
                res[k] += np.bincount(owner, weights=w @ dens, minlength=self.nf)
        return res

    def samples(self, X):
        """Limit-surface points at all quadrature points and their area
        weights: ``(P (M, 3), a (M,))`` with ``a.sum()`` the area."""
        pts, wts = [], []
        for D, (B, w, ctrl, owner) in zip(self._derivs(X), self.blocks):
            _, A, _ = densities(D)
            pts.append(D[0].reshape(3, -1).T)
            wts.append((w[:, None] * A).ravel())
        return np.concatenate(pts), np.concatenate(wts)

    def totals(self, X):
        v = self.values(X)
        return {k: float(v[k].sum()) for k in KINDS}

    def gradient(self, X, kind, coef=None):
        """Gradient (nv, 3) of ``Σ_f coef_f value_kind[f]`` (coef (nf,),
        default all ones) with respect to the control-mesh vertices."""
        Xc_n = self.topo.nc
        g = np.zeros((3, Xc_n))
        for D, (B, w, ctrl, owner) in zip(self._derivs(X), self.blocks):
            Q, _, K = B.shape
            Gd = density_gradients(D, kind)                   # (6, 3, Q, p)
            scale = w[:, None] if coef is None else w[:, None] * np.asarray(coef)[owner][None, :]
            Gd = Gd * scale
            Gq = Gd.transpose(2, 0, 1, 3).reshape(Q * 6, -1)  # (Q*6, 3p)
            Gk = _mm(B.reshape(Q * 6, K).T, Gq).reshape(K, 3, -1)
            flat = ctrl.T.ravel()                             # (K*p,) matching Gk[k, :, p]
            for i in range(3):
                g[i] += np.bincount(flat, weights=Gk[:, i, :].ravel(), minlength=Xc_n)
        g = g.T
        S = self.topo.S
        return g if S is None else np.asarray(S.T @ g)


def loop_quantities(X, F, order=DEFAULT_ORDER):
    """Totals ``{"W", "A", "V"}`` of the Loop limit surface of ``(X, F)``."""
    return LoopEvaluator(F, len(X), order).totals(X)
