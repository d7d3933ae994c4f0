"""``newton N``: damped Newton steps with exact Hessians (pyevolver's own).

The Evolver's ``hessian`` takes the plain Newton step.  Far from a minimum,
or on energies whose Hessian is singular (rigid motions, the tangential
motions of a scale- or Möbius-invariant energy such as the squared mean
curvature, ``hessian_normal off``), that step can be an ascent direction or
arbitrarily long.  ``newton`` takes the Levenberg–Marquardt step instead
(Nocedal & Wright, *Numerical Optimization*, 2nd ed., §3.4 and §4.3; the
bordered system of :mod:`.hessian`):

    [ K + δI   C ] [ dy ]   [ −∇E ]
    [ Cᵀ       0 ] [ −ν ] = [ t − v ]

with ``K`` the Hessian of the Lagrangian on the free coordinates of every
mobile vertex (all three directions, or the tangent space of its level-set
constraints: tangential motion matters for energies that are not invariant
under it, e.g. ``harmonic_energy``), ``C`` the gradients of the fixed
volumes and quantities and the multipliers fitted to ``∇E`` by least
squares.  δ is raised until ``K + δI`` is positive definite (a Cholesky
factorization succeeds; CHOLMOD when installed) and adapted by the ratio
of the actual decrease of the energy, after the fixed values are restored
as in ``g``, to the decrease the quadratic model predicts: a step is taken
only when the energy decreases.  δ > 0 also makes the rigid motions, whose
Hessian eigenvalues are zero, harmless: the gradient has no component along
them.  Near a nondegenerate minimum δ → 0 and the steps become Newton
steps (quadratic convergence).  A quantity FUNCTION nonlinear in its
instances' values adds a dense low-rank term ``W diag(±1) Wᵀ`` to ``K``
(:func:`.hessian.lowrank_border`): it is kept out of the sparse matrix and
enters the test and the solve through the Schur complement of the bordered
matrix (:func:`_factor_lowrank`).
"""
from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..constraints import restore_state, state
from ..errors import UnsupportedError, dimension_error
from . import fastpath as FP
from . import gradient as GR
from . import hessian_nd
from .eigen import ShiftedFactor
from .hessian import (_cholmod, constraint_curvature, hessian_system, lagrangian_gradient,
                      lagrangian_hessian, lowrank_border, solve_bordered, tangent_basis)
from .iterate import Iterator, StepResult, _Constraints
from . import symfactor as SF
from .symfactor import newton_solve
from ..threads import blas_limited
from . import string_hessian  # noqa: F401  (installs the string model's Hessian)


@dataclass
class NewtonResult:
    """Outcome of :func:`damped_newton` (also passed to the callback)."""
    energy: float
    nit: int = 0
    nfev: int = 0
    delta: float = 0.0
    message: str = ""
    success: bool = False
    history: list = field(default_factory=list)      # energies after each step
    totals: Any = None                                 # the evaluation after the last step


def _factor(M):
    """Solve function for the symmetric matrix ``M`` when it is positive
    definite, None when it is not.  Without CHOLMOD, SuperLU in symmetric mode
    (symmetric fill-reducing order, no pivoting off the diagonal): then
    ``P M Pᵀ = L U`` with ``U = D Lᵀ``, and by Sylvester's law of inertia M is
    positive definite exactly when every pivot ``U_ii`` is positive — the
    test CHOLMOD's Cholesky makes, so both solvers damp the same steps."""
    chol = _cholmod()
    if chol is not None:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return chol.cholesky(M.tocsc(), mode="supernodal")
        except chol.CholmodNotPositiveDefiniteError:
            return None
    import scipy.sparse.linalg as spla   # 0.1 s and 8 MB at start-up: when first used
    try:
        lu = spla.splu(M.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:                      # exactly singular
        return None
    if np.array_equal(lu.perm_r, lu.perm_c) and np.any(lu.U.diagonal() <= 0):
        return None
    return lu.solve


def _factor_lowrank(M, W, sign):
    """Solve function for ``M + W diag(sign) Wᵀ`` (``M`` sparse, ``W``
    (n, r) dense: the rank term of a nonlinear FUNCTION quantity, see
    :func:`.hessian.lowrank_border`) when it is positive definite, None when
    it is not.  One LDLᵀ of ``M`` (SuperLU in symmetric mode) and the Schur
    complement ``S = diag(sign) + Wᵀ M⁻¹ W`` of the bordered matrix
    ``[[M, W], [Wᵀ, −diag(sign)]]``: its inertia is that of ``M + W diag(sign) Wᵀ``
    plus that of ``−diag(sign)`` (Haynsworth), which gives the count of
    :func:`.symfactor.negative_count`; solves by the Sherman–Morrison–Woodbury
    formula ``M⁻¹ − M⁻¹ W S⁻¹ Wᵀ M⁻¹``."""
    try:
        f = SF.LDL(M)
    except RuntimeError:                      # exactly singular
        return None
    if f.pivots is None or not np.all(f.pivots != 0):
        return None                           # (pivoted off the diagonal: no inertia)
    Z = f.solve(W)
    S = np.diag(sign) + W.T @ Z
    if SF.negative_count(f.pivots, S, 0.0, -sign) != 0:
        return None
    try:
        Sinv = np.linalg.inv(S)
    except np.linalg.LinAlgError:
        return None

    def solve(R):
        Y = f.solve(R)
        return Y - Z @ (Sinv @ (W.T @ Y))
    return solve


def _solve(f, B, r, d):
    """``[[M, B], [Bᵀ, 0]] [y; μ] = [r; d]`` with ``f`` solving M (Schur complement)."""
    if B is None:
        return f(r), None
    Z = f(np.column_stack([r, B]))
    S = B.T @ Z[:, 1:]
    mu = np.linalg.lstsq(S, B.T @ Z[:, 0] - d, rcond=None)[0]
    return Z[:, 0] - Z[:, 1:] @ mu, mu


def damped_newton(it: Iterator, n: int, callback: Callable | None = None,
                  delta0: float | None = None, rtol: float = 1e-10) -> NewtonResult:
    """At most ``n`` damped Newton steps on the surface of ``it``.

    Parameters
    ----------
    it : Iterator
        Gives the surface and the restoring of the fixed values; keeps the
        damping from run to run (``it.newton_delta``).
    n : int
        Maximal number of (accepted) steps.
    callback : callable, optional
        ``callback(result)`` after every step (``result.totals`` the new
        evaluation); a true value stops the run.
    delta0 : float, optional
        Initial damping; by default the one the last run ended with, else
        1e-4 times the mean absolute diagonal of ``K``.
    rtol : float
        Converged when the model predicts a decrease below ``rtol · |E|``:
        near a minimum the predicted decrease falls quadratically, and along
        nearly flat directions (the slightly indefinite tangential modes of
        area or Willmore energies) the steps would only creep.

    Returns
    -------
    NewtonResult
    """
    if it.surface.X.shape[1] > 3:
        raise dimension_error(it.surface.sdim, "damped Newton steps", "need")
    res = NewtonResult(energy=it.surface.evaluate().energy)
    delta = delta0 if delta0 is not None else it.newton_delta
    for k in range(1, int(n) + 1):
        s = it.surface
        mobile = it._mobile()
        cons = _Constraints(s)
        t = s.evaluate()
        f0 = t.energy
        basis, grads = tangent_basis(s, mobile, normal=False)
        T = basis.matrix()
        gE = GR.energy_gradient(t)
        gE[~mobile] = 0.0
        gy = T.T @ gE.ravel()
        B = d = None
        lam = np.zeros(len(cons))
        gs = []
        if len(cons):
            gs, _, _ = it._constrained_dirs(t, cons, mobile)
            B = np.asarray(T.T @ np.stack([g.ravel() for g in gs], axis=1))
            lam = np.linalg.lstsq(B, gy, rcond=None)[0]
            d = cons.targets(s) - cons.values(t)

        terms: list = []            # (a nonlinear FUNCTION's rank term W diag(sign) Wᵀ)
        K = lagrangian_hessian(s, cons, lam, lagrangian_gradient(cons, lam), basis, t=t,
                               lowrank=terms)
        W, sign = (lowrank_border(t, terms, T) or (None, None)) if terms else (None, None)
        gL = gE - sum((l * g for l, g in zip(lam, gs)), np.zeros_like(gE))
        Hc = constraint_curvature(s, grads, gL)
        if Hc is not None:
            K = K - T.T @ Hc @ T
        K = sp.csc_matrix(K)
        diag = float(np.mean(np.abs(K.diagonal()))) if K.shape[0] else 0.0
        if not diag > 0:
            res.message = "no free coordinates or a zero Hessian"
            break
        floor = 1e-12 * diag
        if delta is None:
            delta = 1e-4 * diag
        delta = max(delta, floor)
        X0 = state(s)
        targets = cons.targets(s)
        accepted = False
        for _trial in range(60):
            M = K + delta * sp.identity(K.shape[0], format="csc")
            f = _factor(M) if W is None else _factor_lowrank(M, W, sign)
            if f is None:
                delta *= 4.0
                continue
            dy, _ = _solve(f, B, -gy, d)
            Kdy = K @ dy if W is None else K @ dy + W @ (sign * (W.T @ dy))
            pred = -(gy @ dy + 0.5 * dy @ Kdy)
            if not (pred > 0) or not np.all(np.isfinite(dy)):
                delta *= 4.0
                continue
            if pred <= rtol * max(abs(f0), 1e-300):
                res.message, res.success = "converged (predicted decrease below rtol)", True
                break
            dx = (T @ dy).reshape(s.X.shape)
            t1 = it._move(X0, dx, 1.0, cons, None, None, mobile, targets, None, trial=True)
            res.nfev += 1
            f1 = t1.energy
            ratio = (f0 - f1) / pred if math.isfinite(f1) else -math.inf
            if f1 < f0 and ratio > 0.1:
                accepted = True
                if ratio > 0.75:
                    delta = max(delta / 8.0, floor)
                elif ratio < 0.25:
                    delta *= 2.0
                break
            restore_state(s, X0)
            delta *= 4.0
        it.newton_delta = delta
        if not accepted:
            restore_state(s, X0)
            it.cg_history = None
            if not res.message:
                res.message = "no decrease found (round-off or a kink)"
                res.success = True
            break
        # multipliers for the pressures report, as g stores them
        for kk, q in enumerate(cons.quantities):
            q.pressure = lam[len(cons.bodies) + kk]
        b = s.bodies
        if b.n:
            b.lagrange[:] = 0.0
            for kk, i in enumerate(cons.bodies):
                b.lagrange[i] = lam[kk]
        it.pressures_valid = True
        it.cg_history = None
        res.totals = s.evaluate()
        res.energy, res.nit, res.delta = res.totals.energy, k, delta
        res.history.append(res.energy)
        if callback is not None and callback(res):
            res.message = "stopped by the callback"
            break
    else:
        res.message = res.message or "iteration limit"
    res.energy = it.surface.evaluate().energy
    return res


def _index(hs, piv, eps, B=None, D=None):
    """The number of negative eigenvalues of the constrained Hessian, for
    REF's warning 1825.  The pivots of the step's own LDLᵀ (CHOLMOD) count
    them at no cost; when they find some (their signs can err for
    eigenvalues within round-off of 0: rigid motions) the count is that of
    one factorization at −δ, δ = max(eps, 1e-8 × the mean |diagonal|).
    ``B``, ``D``: the border of :meth:`.hessian.HessianSystem.border` (by
    default the system's own, without a low-rank term)."""
    B = hs.B if B is None else B
    if piv and SF.negative_count(piv[0], piv[1], 0.0, D) == 0:
        return 0
    delta = max(eps, 1e-8 * float(np.abs(hs.K.diagonal()).mean()))
    try:
        return ShiftedFactor(hs.K, B, -delta, 0.0, nudge=True,
                             points=hs.points, D=D).inertia().below
    except UnsupportedError:       # (singular where it cannot be resolved: no warning)
        return 0


_SCALED = ("hessian: the Newton step raised the energy; "
           "step scaled by %g (pyevolver's hessian_backtrack)\n")


def _no_rise(E, e0, scale, fallbacks):
    """``scale`` when the move there does not raise the energy above ``e0``,
    else the first of ``fallbacks`` that does not, else 0 (no move).
    ``E(scale)`` moves from the start and restores the fixed values; a rise
    within round-off (1e-13 relative) is no rise."""
    top = e0 + 1e-13 * abs(e0)
    for s in [scale] + list(fallbacks):
        if s > 0 and E(s) <= top:
            return s
    return 0.0


#: a Newton step longer than this many times the surface's extent comes
#: from a singular Hessian: it is not taken
SINGULAR_STEP = 1e2


def _absurd_step(hs, s, sol) -> bool:
    """Is the Newton step :data:`SINGULAR_STEP` times the surface's extent?
    A singular Hessian (motions that cost no energy while the force has a
    part along them: 100grain.fe after ``g 5``, 101 zero eigenvalues) makes
    it blow up; the Evolver takes such a step (100grain.fe ``g 5; hessian``:
    length 6e13), pyevolver warns and stays."""
    n = hs.K.shape[0]
    extent = float(np.ptp(s.X, axis=0).max()) if s.nv else 0.0
    return bool(n) and bool(np.abs(sol[:n]).max(initial=0.0)
                            > SINGULAR_STEP * max(extent, 1e-300))


@blas_limited
def hessian_step(it: Iterator, seek: bool = False, max_scale: float | None = None,
                 normal: bool = True, eps: float = 1e-10) -> StepResult:
    """The ``hessian`` command: one Newton step on the constrained problem
    (the bordered system of :mod:`.hessian`); with ``seek`` (``hessian_seek``)
    a line search along the Newton direction, scale at most ``max_scale``
    (default 1).

    The multipliers of the last ``g`` or ``hessian`` step enter the Hessian
    of the Lagrangian; the new ones are stored as the pressures.  A step to
    a non-finite energy is undone: ``message`` "infinite", ``printed``
    False.  When the constrained Hessian has eigenvalues below ``−eps``
    (``hessian_epsilon``) the step is still taken and ``warnings`` starts
    with REF's "WARNING 1825: Hessian not positive definite. Index: N"
    (N their number, from the inertia: :func:`_index`).  With
    ``check_increase`` a ``hessian`` step that raises the energy is undone
    (REF's WARNING 1596; ``message`` "increase").

    Returns
    -------
    StepResult
        ``totals`` the evaluation after the step.
    """
    s = it.surface
    FP.forget(it)
    hs = hessian_nd.system(it, normal, lowrank=True)
    # the evaluation K was formed at: only its energy is needed from here on
    # (its cached geometry, 60 MB at 81,920 facets, goes before the factorization)
    e0 = (hs.totals if hs.totals is not None else s.evaluate()).energy
    hs.totals = None
    n = hs.K.shape[0]
    got = None
    piv: list = []
    B, d, D = hs.border()       # (with a nonlinear FUNCTION's rank term: D, see there)
    if n > SF.ND_MIN:
        # one LDLᵀ of K + δI gives the index and, refined, the step with K
        # (small systems: the direct solve and, when its pivots find negative
        # ones, a second factorization for the index; they cost nothing there)
        delta = max(eps, 1e-8 * float(np.abs(hs.K.diagonal()).mean()))
        got = newton_solve(hs.K, B, hs.rhs, d, points=hs.points, delta=delta, D=D)
        if got is None:          # an eigenvalue near −δ: factor K itself
            got = newton_solve(hs.K, B, hs.rhs, d, points=hs.points, D=D)
            if got is not None:
                got = (got[0], None)     # (K's pivots are not the index's)
    if got is not None:
        sol, index = got
    else:
        sol = solve_bordered(hs.K, B, hs.rhs, d, points=hs.points, pivots=piv, D=D)
        index = None
    if index is None and n:
        index = _index(hs, piv, eps, B, D)
    report: list[str] = []
    absurd = _absurd_step(hs, s, sol)
    if absurd:
        report.append("WARNING: the Hessian is singular (motions that cost no energy, with "
                      "a force along them): the Newton step would move the surface "
                      f"{np.abs(sol[:n]).max():.3g} and is not taken.\n")
    cons, mobile = hs.cons, hs.mobile
    lam = hs.lam if absurd or not len(cons) else -sol[n:n + len(cons)]
    dx = np.zeros(s.X.shape) if absurd else (hs.T @ sol[:n]).reshape(s.X.shape)
    if n:
        if index:
            report.append(f"WARNING 1825: Hessian not positive definite. Index: {index}\n")
    targets = cons.targets(s)
    X0 = state(s)

    def E(scale, report=None):
        e = it._move(X0, dx, scale, cons, None, None, mobile, targets, report).energy
        return e if math.isfinite(e) else math.inf
    scale = 1.0
    if seek:
        smax = 1.0 if max_scale is None else max_scale
        scale, _, best = it._line_search(E, smax, smax)
        scale = _no_rise(E, e0, scale, [best])
    elif it.settings.hessian_backtrack and not it.settings.check_increase:
        scale = _no_rise(E, e0, 1.0, [0.5 ** k for k in range(1, 41)])
        if scale != 1.0:
            report.append(_SCALED % scale)
        if scale == 0.0:        # no fraction of the step helps: the surface stays
            restore_state(s, X0)
            t = s.evaluate()
            return StepResult(t.energy, t.total_area, 0.0, hs.lam, {}, True,
                              warnings=report, totals=t)
    t = it._move(X0, dx, scale, cons, None, None, mobile, targets, report)
    if not math.isfinite(t.energy):
        restore_state(s, X0)
        it.cg_history = None
        t = s.evaluate()
        return StepResult(t.energy, t.total_area, scale, lam, {}, False, message="infinite",
                          warnings=report, totals=t)
    if not seek and it.settings.check_increase and t.energy > e0:
        # check_increase: REF undoes a Newton step that raises the energy
        restore_state(s, X0)
        it.cg_history = None
        t = s.evaluate()
        report.append("WARNING 1596: Hessian move would have raised energy.  "
                      "Restoring coords.\n")
        return StepResult(t.energy, t.total_area, 0.0, lam, {}, True, message="increase",
                          warnings=report, totals=t)
    b = s.bodies
    qp = {}
    if b.n:
        b.lagrange[:] = 0.0
    for k, i in enumerate(cons.bodies):
        b.lagrange[i] = lam[k]
    for k, q in enumerate(cons.quantities):
        q.pressure = lam[len(cons.bodies) + k]
        qp[q.name] = q.pressure
    it.cg_history = None
    # (t: the evaluation the move ended with; the multipliers do not enter it)
    return StepResult(t.energy, t.total_area, scale,
                      b.lagrange.copy() if b.n else np.zeros(0), qp, True, warnings=report,
                      totals=t)
