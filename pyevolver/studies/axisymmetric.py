"""Axisymmetric reference shapes of the Canham problem (genus 0).

The accuracy reference for the paper's Figure 4: minimise the bending
energy ``W = ∫ H² dA`` (``H = (κ1 + κ2)/2``; a round sphere has W = 4π) of a
closed surface of revolution at fixed area ``A = 4π`` and volume
``V = v0 · 4π/3``, on the prolate, oblate/discocyte and stomatocyte branches
of the spontaneous-curvature model at ``C0 = 0`` (Seifert, Berndl &
Lipowsky 1991, *Shape transformations of vesicles: phase diagram for
spontaneous-curvature and bilayer-coupling models*, Phys. Rev. A 44, 1182;
their energy is ``F = (κ/2)∮(2H)² dA``, so ``F/(8πκ) = W/(4π)``).

Representation
--------------
The profile curve is parametrised by ``t = s/L ∈ [0, 1]`` (``s`` arclength,
``L`` the profile length) with the tangent angle ``ψ``; ``r' = cos ψ``,
``z' = sin ψ``, ``κ_meridian = ψ'``, ``κ_parallel = sin ψ / r``.  The poles
are ``t = 0`` (``ψ = 0``) and ``t = 1`` (``ψ = π``).  A smooth surface of
revolution has ``ψ - πt`` odd about both poles, so

    ψ(t) = π t + Σ_{k=1..K} a_k sin(kπt)

is the natural spectral basis: ``cos ψ`` is then even about both poles
(a cosine series) and ``r = L ∫ cos ψ dt`` a sine series once the closure
``∫_0^1 cos ψ dt = 0`` (``r(1) = 0``) holds.  Everything is evaluated on
``M`` midpoints ``t_j = (j + 1/2)/M``: ``r`` by exact integration of the
DCT-II interpolant of ``cos ψ``, the integrals of functions odd about both
poles (``r``, ``r² sin ψ``, ``(ψ' + sin ψ/r)² r``) by exact integration of
their DST-II interpolant.  The error decays exponentially in ``K`` for the
smooth minimisers.

With ``r̃ = r/L`` the energy ``W = (π/2) ∫ (ψ' + sin ψ / r̃)² r̃ dt`` is
scale invariant; the reduced volume ``v = 3V/(4π) / (A/(4π))^{3/2}`` is too,
with ``A = 2πL² ∫ r̃``, ``V = πL³ ∫ r̃² sin ψ``.  The problem solved is
``min W(a)`` subject to ``∫ cos ψ = 0`` and ``v(a) = v0`` (SLSQP with
analytic gradients, then Newton on the KKT equations with a differenced
Hessian of the Lagrangian), and ``L`` is chosen afterwards so that
``A = 4π``.

    python -m pyevolver.studies.axisymmetric --v0 0.85 --branch prolate [--n 64]

prints W, W/(4π), the constraint residuals and the shape descriptors.
"""
from __future__ import annotations

import argparse
import sys
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import BFGS, NonlinearConstraint, minimize

BRANCHES = ("prolate", "oblate", "stomatocyte")
#: the profile types (:func:`descriptors`) of each branch
SHAPES_OF = {"prolate": {"prolate", "sphere"}, "oblate": {"oblate", "discocyte", "sphere"},
             "stomatocyte": {"stomatocyte"}}


class NotConverged(RuntimeError):
    """The reference's minimisation failed (e.g. every trial shape of the
    branch's initial guess crossed the axis)."""


@dataclass(frozen=True)
class Helfrich:
    """Parameters of the bending energy, in units where ``A = 4π`` (``R0 = 1``).

    The energy minimised is (divided by ``2κ``)

        E = ∫ (H - c0/2)² dA + (π α / A) (M - 4π m0)²,   M = ∫ H dA,

    with ``H = (κ1 + κ2)/2`` (a sphere of radius R has H = 1/R): the
    spontaneous-curvature model (Seifert, Berndl & Lipowsky 1991,
    ``F = (κ/2)∮(C1 + C2 - C0)² dA``, so ``c0 = C0·R0``) plus, for
    ``alpha > 0``, area-difference elasticity (Miao, Seifert, Wortis &
    Döbereiner 1994, ``(κ̄π / (2AD²))(ΔA - ΔA0)²`` with the bilayer area
    difference ``ΔA = 2D·M``; ``alpha = κ̄/κ`` and ``m0 = ΔA0/(8πD R0)``, the
    reduced preferred area difference, 1 for the sphere).  A Gaussian
    modulus adds ``(κ_G/κ)·2π(1 - g)`` for genus g (Gauss–Bonnet), a constant
    left out here.
    """
    c0: float = 0.0
    alpha: float = 0.0
    m0: float = 1.0

    @property
    def plain(self) -> bool:
        return self.c0 == 0.0 and self.alpha == 0.0


class _Basis:
    """Collocation matrices for ``K`` sine modes on ``M`` midpoints; the
    energy of ``model`` (default: ``∫H² dA``)."""

    def __init__(self, K: int, M: int, model: Helfrich | None = None):
        self.K, self.M = K, M
        self.model = model if model is not None else Helfrich()
        t = (np.arange(M) + 0.5) / M
        k = np.arange(1, K + 1)
        self.t = t
        self.S = np.sin(np.pi * np.outer(t, k))                 # ψ - πt
        self.C = np.pi * k * np.cos(np.pi * np.outer(t, k))     # ψ' - π
        m = np.arange(M)
        # DCT-II analysis on midpoints: f_j = Σ_m c_m cos(mπ t_j), exact for m < M
        D = (2.0 / M) * np.cos(np.pi * np.outer(m, t))
        D[0] /= 2.0
        Iint = np.empty((M, M))
        Iint[:, 0] = t
        Iint[:, 1:] = np.sin(np.pi * np.outer(t, m[1:])) / (np.pi * m[1:])
        self.R = Iint @ D                                        # ∫_0^t of an even function
        # DST-II analysis: f_j = Σ_{m=1..M} b_m sin(mπ t_j)
        mp = np.arange(1, M + 1)
        Ds = (2.0 / M) * np.sin(np.pi * np.outer(mp, t))
        Ds[-1] /= 2.0
        self.Ds = Ds
        self.mp = mp
        self.q = Ds.T @ ((1.0 - (-1.0) ** mp) / (np.pi * mp))   # ∫_0^1 of an odd-odd function

    def fields(self, a):
        psi = np.pi * self.t + self.S @ a
        dpsi = np.pi + self.C @ a
        r = self.R @ np.cos(psi)
        return psi, dpsi, r

    def evaluate(self, a):
        """Values and gradients (w.r.t. ``a``) of ``W``, closure, ``v``."""
        psi, dpsi, r = self.fields(a)
        sn, cs = np.sin(psi), np.cos(psi)
        q = self.q
        h = dpsi + sn / r
        W = 0.5 * np.pi * q @ (h * h * r)
        gW_r = 0.5 * np.pi * q * (h * h - 2.0 * h * sn / r)
        gW_psi = 0.5 * np.pi * q * (2.0 * h * cs)
        gW_dpsi = 0.5 * np.pi * q * (2.0 * h * r)
        Atil = q @ r
        Vtil = q @ (r * r * sn)
        v = 1.5 * np.sqrt(2.0) * Vtil / Atil ** 1.5
        gv_r = v * (2.0 * r * sn * q / Vtil - 1.5 * q / Atil)
        gv_psi = v * (r * r * cs * q / Vtil)
        clo = np.mean(cs)
        g_clo = -(self.S.T @ sn) / self.M

        def pull(g_r, g_psi, g_dpsi):
            return self.S.T @ (g_psi - sn * (self.R.T @ g_r)) + self.C.T @ g_dpsi

        zero = np.zeros_like(r)
        gW = pull(gW_r, gW_psi, gW_dpsi)
        gv = pull(gv_r, gv_psi, zero)
        md = self.model
        if not md.plain:
            # M = ∫H dA = π L ∫(ψ' r̃ + sin ψ) dt with L = sqrt(2/Ã) at A = 4π
            Mt = q @ (dpsi * r + sn)
            with np.errstate(invalid="ignore"):     # Ã < 0: a trial shape through the axis
                root = np.sqrt(2.0 / Atil)
            Mv = np.pi * root * Mt
            gM = np.pi * root * (pull(q * dpsi, q * cs, q * r)
                                 - 0.5 * Mt / Atil * pull(q, zero, zero))
            dE_dM = -md.c0 + 2.0 * np.pi * md.alpha / (4 * np.pi) * (Mv - 4 * np.pi * md.m0)
            W = (W - md.c0 * Mv + np.pi * md.c0 ** 2
                 + np.pi * md.alpha / (4 * np.pi) * (Mv - 4 * np.pi * md.m0) ** 2)
            gW = gW + dE_dM * gM
        return W, gW, clo, g_clo, v, gv, Atil, Vtil

    def curvature_integrals(self, a):
        """``(∫H² dA, ∫H dA)`` of the shape ``a`` scaled to ``A = 4π``."""
        psi, dpsi, r = self.fields(a)
        sn = np.sin(psi)
        h = dpsi + sn / r
        Atil = self.q @ r
        return (0.5 * np.pi * self.q @ (h * h * r),
                np.pi * np.sqrt(2.0 / Atil) * self.q @ (dpsi * r + sn))


@dataclass
class CanhamResult:
    """Axisymmetric Canham minimiser at ``A = 4π``, ``V = v0·4π/3``.

    Attributes
    ----------
    W : float
        The model's energy (:class:`Helfrich`; by default the bending energy
        ∫H² dA, sphere: 4π).
    area, volume, v0 : float
        Area, enclosed volume and the prescribed reduced volume.
    L : float
        Profile length.
    s, r, z, psi : ndarray
        The profile on a uniform arclength grid from pole to pole.
    coef : ndarray
        The sine coefficients ``a_k``.
    lagrange : ndarray
        Multipliers of (closure, reduced volume).
    descriptors : dict
        Shape-type indicators (see :func:`descriptors`).
    willmore, mean_curvature : float
        ``∫H² dA`` and ``∫H dA`` (the reduced area difference is
        ``mean_curvature / 4π``).
    model : Helfrich
        The energy's parameters.
    """
    W: float
    area: float
    volume: float
    v0: float
    branch: str
    n: int
    L: float
    s: np.ndarray
    r: np.ndarray
    z: np.ndarray
    psi: np.ndarray
    coef: np.ndarray
    lagrange: np.ndarray
    closure: float
    descriptors: dict = field(default_factory=dict)
    willmore: float = float("nan")
    mean_curvature: float = float("nan")
    model: Helfrich = field(default_factory=Helfrich)


def _stomatocyte_guess(K: int, beta: float = 0.9, rho: float = 0.15,
                       depth: float = 0.4) -> np.ndarray:
    """Sine coefficients of a unit sphere with a pit: the outer arc (radius 1)
    runs from the bottom pole to ψ = π - β, a lip of radius ``rho`` turns the
    profile down (ψ = 3π/2), a straight descent of length ``depth`` follows,
    and an inner quarter circle of radius ``sin β - rho(1 + sin β)`` (negative
    curvature) ends on the axis with ψ = π.  Closed by construction."""
    R2 = np.sin(beta) - rho * (1 + np.sin(beta))
    lens = np.array([np.pi - beta, rho * (np.pi / 2 + beta), depth, R2 * np.pi / 2])
    kap = np.array([1.0, 1.0 / rho, 0.0, -1.0 / R2])
    edges = np.concatenate([[0.0], np.cumsum(lens)])
    L = edges[-1]
    basis_t = (np.arange(8 * K) + 0.5) / (8 * K)
    s = basis_t * L
    seg = np.minimum(np.searchsorted(edges, s, side="right") - 1, 3)
    psi0 = np.concatenate([[0.0], np.cumsum(kap * lens)])
    psi = psi0[seg] + kap[seg] * (s - edges[seg])
    S = np.sin(np.pi * np.outer(basis_t, np.arange(1, K + 1)))
    return np.linalg.lstsq(S, psi - np.pi * basis_t, rcond=None)[0]


def _initial_coef(branch: str, v0: float, K: int) -> np.ndarray:
    a = np.zeros(K)
    if branch == "prolate":
        a[1] = 0.2                      # tall: curvature concentrated at the poles
    elif branch == "oblate":
        a[1] = -0.3 if v0 > 0.7 else -0.6   # flat; β > 1/2 dimples the poles (discocyte)
    elif branch == "stomatocyte":
        # pit depth chosen so that the guess has roughly the reduced volume v0
        a = _stomatocyte_guess(K, depth=float(np.clip((0.76 - v0) / 0.36, 0.0, 1.2)))
    else:
        raise ValueError(f"unknown branch {branch!r}; expected one of {BRANCHES}")
    return a


def _solve(basis: _Basis, v0: float, a0: np.ndarray, coarse: bool = True,
           maxiter: int = 3000):
    """Constrained minimisation, then Newton–KKT polish.

    ``coarse``: start with scipy's ``trust-constr`` (BFGS Hessians, analytic
    gradients); its trust region keeps the iterates near the initial shape,
    where SLSQP's long first steps can push ``r`` through the axis.  Without
    it (a start already near the minimiser, e.g. a coarser solution padded
    with zeros) only the Newton iteration runs.  Returns ``(a, multipliers)``.
    """
    a = np.asarray(a0, dtype=float).copy()
    if coarse:
        def cfun(x):
            out = basis.evaluate(x)
            return np.array([out[2], out[4]])

        def cjac(x):
            out = basis.evaluate(x)
            return np.vstack([out[3], out[5]])

        nc = NonlinearConstraint(cfun, [0.0, v0], [0.0, v0], jac=cjac, hess=BFGS())
        with warnings.catch_warnings(), np.errstate(invalid="ignore"):
            # rank-deficient steps early on are harmless; trial shapes whose
            # r crosses the axis give NaN, which the trust region rejects
            warnings.simplefilter("ignore", UserWarning)
            res = minimize(lambda x: basis.evaluate(x)[:2], a, jac=True, hess=BFGS(),
                           method="trust-constr", constraints=[nc],
                           options={"maxiter": maxiter, "gtol": 1e-10, "xtol": 1e-14})
        a = res.x
    # Newton on ∇W = λ1 ∇c + λ2 ∇v, c = 0, v = v0
    K = basis.K
    _, gW, _, gc, _, gv, *_ = basis.evaluate(a)
    lam = np.linalg.lstsq(np.column_stack([gc, gv]), gW, rcond=None)[0]

    def lag_grad(x, lam):
        _, gW, _, gc, _, gv, *_ = basis.evaluate(x)
        return gW - lam[0] * gc - lam[1] * gv

    for _ in range(12):
        _, gW, c, gc, v, gv, *_ = basis.evaluate(a)
        F = np.concatenate([gW - lam[0] * gc - lam[1] * gv, [c, v - v0]])
        if np.max(np.abs(F)) < 1e-13:
            break
        eps = 1e-6
        H = np.empty((K, K))
        for i in range(K):
            e = np.zeros(K)
            e[i] = eps
            H[:, i] = (lag_grad(a + e, lam) - lag_grad(a - e, lam)) / (2 * eps)
        H = 0.5 * (H + H.T)
        J = np.zeros((K + 2, K + 2))
        J[:K, :K] = H
        J[:K, K] = -gc
        J[:K, K + 1] = -gv
        J[K, :K] = gc
        J[K + 1, :K] = gv
        d = np.linalg.solve(J, -F)
        a = a + d[:K]
        lam = lam + d[K:]
    _, gW, c, gc, v, gv, *_ = basis.evaluate(a)
    resid = float(np.max(np.abs(np.concatenate([gW - lam[0] * gc - lam[1] * gv,
                                                [c, v - v0]]))))
    if not resid < 1e-8:
        raise RuntimeError(f"Newton-KKT did not converge (residual {resid:.2e}); "
                           "try a smaller n first and pass its coef as coef0")
    return a, lam


def descriptors(psi: np.ndarray, r: np.ndarray, z: np.ndarray) -> dict:
    """Shape-type indicators of a profile sampled uniformly from pole to pole.

    ``height_width`` is (z-extent)/(2 max r); ``z_monotone`` whether z is
    monotone along the profile (convex-like prolate/oblate shapes);
    ``psi_min``/``psi_max`` the tangent-angle range (``psi_min < 0``: dimpled
    poles; ``psi_max > π``: the profile folds back); ``updown_asym`` =
    max |ψ(t) + ψ(1-t) - π| (0 for shapes symmetric under z → -z);
    ``r_interior_min`` whether r has an interior local minimum (a neck);
    ``pole_order`` = z(end pole) - z(start pole) (negative when the end pole
    lies below the start, i.e. the invagination reaches past the bottom);
    ``type`` one of sphere / prolate / oblate / discocyte / stomatocyte / other.
    """
    dz = np.diff(z)
    zmono = bool(np.all(dz >= -1e-12) or np.all(dz <= 1e-12))
    hw = float((z.max() - z.min()) / (2 * r.max()))
    asym = float(np.max(np.abs(psi + psi[::-1] - np.pi)))
    interior = r[1:-1]
    rmin = bool(np.any((interior < r[:-2]) & (interior < r[2:])))
    pmin, pmax = float(psi.min()), float(psi.max())
    if asym < 1e-6 and pmin >= -1e-9 and pmax <= np.pi + 1e-9:
        kind = "sphere" if abs(hw - 1) < 1e-6 else ("prolate" if hw > 1 else "oblate")
    elif asym < 1e-6 and pmin < 0:
        kind = "discocyte"
    elif asym > 1e-3 and pmax > np.pi:
        kind = "stomatocyte"
    else:
        kind = "other"
    return {"type": kind, "height_width": hw, "z_monotone": zmono,
            "psi_min": pmin, "psi_max": pmax, "updown_asym": asym,
            "r_interior_min": rmin, "pole_order": float(z[-1] - z[0])}


def canham_reference(v0: float, branch: str, n: int = 48, n_profile: int = 401,
                     coef0: np.ndarray | None = None, oversample: int = 4,
                     model: Helfrich | None = None) -> CanhamResult:
    """Minimal ``W = ∫H² dA`` over surfaces of revolution on one branch.

    Parameters
    ----------
    v0 : float
        Reduced volume ``3V/(4π) / (A/(4π))^{3/2}``, in (0, 1].
    branch : {"prolate", "oblate", "stomatocyte"}
        Which local minimum: the initial shape is tall, flat (biconcave for
        ``v0 < 0.7``), or a cup with an invagination.  ``"discocyte"`` is
        accepted for ``"oblate"``.
    n : int
        Number of sine modes ``K`` of ``ψ(t) - πt``.  Exponential convergence:
        ``n = 24`` gives the prolate (v0 = 0.85) and discocyte (0.62) to
        ~1e-14; the stomatocyte (0.50), with its narrow neck, needs
        ``n ≈ 200`` for 1e-8 (``n = 256``: 1e-10).
    n_profile : int
        Points of the returned profile arrays.
    coef0 : ndarray, optional
        Start from these coefficients (e.g. ``coef`` of a coarser result,
        padded or truncated to ``n``) instead of the branch's initial shape;
        only the Newton iteration runs then.
    oversample : int
        Collocation points per mode (``M = oversample · n``).
    model : Helfrich, optional
        Spontaneous curvature and area-difference elasticity; default
        ``∫H² dA`` (``c0 = 0``, no ADE).

    Returns
    -------
    CanhamResult
        Energy, area (4π), volume (v0·4π/3), profile and descriptors.

    Notes
    -----
    Seifert, Berndl & Lipowsky, Phys. Rev. A 44, 1182 (1991), give the
    branches and the phase diagram of this problem (their ``F/(8πκ)`` is our
    ``W/(4π)``); they are not used for any number here.
    """
    if branch == "discocyte":
        branch = "oblate"
    if branch not in BRANCHES:
        raise ValueError(f"unknown branch {branch!r}; expected one of {BRANCHES}")
    if not 0 < v0 <= 1:
        raise ValueError("v0 must lie in (0, 1]")
    n0 = min(n, 16)
    if coef0 is None:
        a = np.zeros(n0) if v0 == 1.0 else _initial_coef(branch, v0, n0)
        try:
            a, _ = _solve(_Basis(n0, 4 * n0, model), v0, a, coarse=True)
        except ValueError:       # scipy's trust region fed non-finite trial shapes
            a = np.full(n0, np.nan)
        if not np.all(np.isfinite(a)):
            raise NotConverged(
                f"the {branch} reference at v0 = {v0:g} did not converge from the branch's "
                "initial shape; start from a converged neighbour (coef0, or "
                "pyevolver.studies.phase_reference.follow)")
    else:
        a = np.asarray(coef0, dtype=float)
    basis = _Basis(n, oversample * n, model)
    a = np.concatenate([a[:n], np.zeros(max(0, n - len(a)))])
    a, lam = _solve(basis, v0, a, coarse=False)
    W, _, clo, _, v, _, Atil, Vtil = basis.evaluate(a)
    if not (np.all(np.isfinite(a)) and np.isfinite(W)):
        raise NotConverged(f"the {branch} reference at v0 = {v0:g} did not converge")
    willmore, mean_int = basis.curvature_integrals(a)
    L = np.sqrt(4 * np.pi / (2 * np.pi * Atil))
    # profile on a uniform grid including the poles, from the spectral interpolants
    psi_m, _, _ = basis.fields(a)
    t = np.linspace(0.0, 1.0, n_profile)
    k = np.arange(1, n + 1)
    psi = np.pi * t + np.sin(np.pi * np.outer(t, k)) @ a
    M = basis.M
    m = np.arange(M)
    c = (2.0 / M) * np.cos(np.pi * np.outer(m, basis.t)) @ np.cos(psi_m)
    c[0] /= 2.0
    rt = c[0] * t + np.sin(np.pi * np.outer(t, m[1:])) @ (c[1:] / (np.pi * m[1:]))
    b = basis.Ds @ np.sin(psi_m)
    zt = (1.0 - np.cos(np.pi * np.outer(t, basis.mp))) @ (b / (np.pi * basis.mp))
    r, z = L * rt, L * zt
    area = 2 * np.pi * L ** 2 * Atil
    volume = np.pi * L ** 3 * Vtil
    return CanhamResult(W=float(W), area=float(area), volume=float(volume), v0=v0,
                        branch=branch, n=n, L=float(L), s=L * t, r=r, z=z, psi=psi,
                        coef=a, lagrange=lam, closure=float(clo),
                        descriptors=descriptors(psi, r, z), willmore=float(willmore),
                        mean_curvature=float(mean_int), model=basis.model)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    p = argparse.ArgumentParser(prog="python -m pyevolver.studies.axisymmetric",
                                description=__doc__.split("\n")[0])
    p.add_argument("--v0", type=float, required=True)
    p.add_argument("--branch", required=True,
                   choices=list(BRANCHES) + ["discocyte"])
    p.add_argument("--n", type=int, default=48, help="sine modes (default 48)")
    args = p.parse_args(argv)
    try:
        res = canham_reference(args.v0, args.branch, n=args.n)
    except (NotConverged, ValueError) as exc:
        print(f"{p.prog}: {exc}", file=sys.stderr)
        return 1
    print(f"W = {res.W:.12f}")
    print(f"W/(4 pi) = {res.W / (4 * np.pi):.12f}")
    print(f"area - 4 pi = {res.area - 4 * np.pi:.2e}   "
          f"volume - v0*4pi/3 = {res.volume - args.v0 * 4 * np.pi / 3:.2e}   "
          f"closure r(L) = {res.closure * res.L:.2e}")
    for key, val in res.descriptors.items():
        print(f"{key} = {val}")
    kind = res.descriptors["type"]
    if kind not in SHAPES_OF[res.branch]:
        print(f"note: the minimisation left the {res.branch} branch (the result is a {kind}); "
              "follow the branch from a converged neighbour "
              "(python -m pyevolver.studies.phase_reference)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
