"""Figure 4's solvers: damped Newton on all vertex coordinates and the
harmonic-energy continuation (:mod:`pyevolver.studies.fig4_vesicles`)."""
from __future__ import annotations

import copy
import math
from typing import Callable

import numpy as np
import scipy.sparse as sp

from ..evolve import gradient as GR
from ..evolve.hessian import _cholmod, lagrangian_gradient, lagrangian_hessian, solve_bordered
from ..evolve.iterate import _Constraints
from ..evolve.symfactor import ND_MIN, newton_solve
from ..constraints import restore_state, state
from ..model.surface import Surface
from ..session.core import Session
from .vesicle_shapes import min_angle


def _rigid_motions(X):
    """(3nv, 6) orthonormalised translations and infinitesimal rotations."""
    nv = len(X)
    R = np.zeros((3 * nv, 6))
    c = X - X.mean(0)
    for k in range(3):
        R[k::3, k] = 1.0
        e = np.zeros(3)
        e[k] = 1.0
        R[:, 3 + k] = np.cross(e, c).ravel()
    q, _ = np.linalg.qr(R)
    return q


def solve_step(K, B, r, d, points=None):
    """Solve ``[[K, B], [Bᵀ, 0]] [y; μ] = [r; d]`` (K sparse symmetric,
    possibly indefinite or singular along directions the border holds, such
    as the rigid motions); returns the stacked ``(y, μ)``.

    Above :data:`~pyevolver.evolve.symfactor.ND_MIN` unknowns the engine's
    ``hessian`` solver: one symmetric LDLᵀ of ``K + δI`` in the geometric
    nested-dissection order of ``points`` (n, 3), the border by its Schur
    complement, refined to round-off with ``K``
    (:func:`~pyevolver.evolve.symfactor.newton_solve`; then K itself);
    SuperLU on the whole bordered matrix only when that fails — with the
    dense border columns in it that costs 4.6 s against 0.2 s at 2,562
    vertices.
    """
    n = K.shape[0]
    if n > ND_MIN and points is not None:
        delta = 1e-8 * float(np.abs(K.diagonal()).mean())
        got = newton_solve(K, B, r, d, points=points, delta=delta)
        if got is None:
            got = newton_solve(K, B, r, d, points=points)
        if got is not None:
            return got[0]
    return solve_bordered(K, B, r, d, points=points)


def _bordered(K, B, r, d, cache, points=None):
    """Solve ``[[K, B], [Bᵀ, 0]] [y; μ] = [r; d]`` for the Newton step.

    With CHOLMOD, first as a positive definite K (supernodal Cholesky, about
    2.5 times faster than the LDLᵀ factorization; the symbolic analysis is
    kept in ``cache`` for the matrices of one pattern); when K is not
    positive definite, or without CHOLMOD, by :func:`solve_step`.
    """
    chol = _cholmod()
    if chol is not None:
        try:
            f = cache.get("factor")
            if f is None:
                f = cache["factor"] = chol.analyze(K, mode="supernodal")
            f.cholesky_inplace(K)
            Z = f(np.column_stack([r, B]))
            mu = np.linalg.solve(B.T @ Z[:, 1:], B.T @ Z[:, 0] - d)
            y = Z[:, 0] - Z[:, 1:] @ mu
            if np.all(np.isfinite(y)):
                return y
        except (chol.CholmodNotPositiveDefiniteError, np.linalg.LinAlgError):
            pass
    return solve_step(K, B, r, d, points)[:K.shape[0]]


def newton_lm(session: Session, tol: float = 1e-9, maxit: int = 80, mu: float = 1e-2,
              guard: Callable[[Surface], bool] | None = None) -> tuple[bool, int, float]:
    """Levenberg–Marquardt Newton iteration on all vertex coordinates.

    Each step solves the bordered system of ``min ½ dᵀ(H + μ D) d + ∇Lᵀ d``
    subject to the linearised fixed values (area quantity, body volume) and
    to no rigid motion (translations and rotations, exact null directions of
    the Lagrangian's Hessian ``H`` on a closed surface; the Evolver's
    ``hessian`` with ``hessian_normal`` off does not remove them).  ``D`` is
    the vertex area (a third of the star).  The move restores the fixed
    values as ``g`` does.  It is kept when the energy drops, and μ is then
    scaled by max(1/3, 1 − (2ρ − 1)³), ρ the ratio of the actual to the
    predicted decrease; otherwise μ grows by 2, 4, 8, ... and the step is
    solved again (Nielsen's rule, Madsen, Nielsen & Tingleff 2004,
    *Methods for non-linear least squares problems*, §3.2).  Multipliers
    are the least squares fit of ∇E on the constraint gradients.

    ``guard(surface)`` returning False stops the iteration (used to abandon
    a collapsing mesh early).  Returns ``(converged, steps, max |∇L|)``;
    converged when max |∇L| < ``tol`` with the fixed values met to 1e-10
    relative.
    """
    s = session.surface
    it = session.iterator
    cons = _Constraints(s)
    mobile = ~s.vattr["fixed"]
    gnorm = math.inf
    nu = 2.0
    for step in range(maxit):
        t = s.evaluate()
        gE = GR.energy_gradient(t)
        gs = cons.gradients(t)
        C = np.stack([g.ravel() for g in gs], 1)
        lam = np.linalg.lstsq(C, gE.ravel(), rcond=None)[0]
        gL = gE.ravel() - C @ lam
        targets = cons.targets(s)
        resid = targets - cons.values(t)
        gnorm = float(np.abs(gL).max())
        if gnorm < tol and np.all(np.abs(resid) < 1e-10 * np.abs(targets)):
            return True, step, gnorm

        H = lagrangian_hessian(s, cons, lam, lagrangian_gradient(cons, lam)).tocsc()
        mass = sp.diags(np.repeat(np.bincount(s.F.ravel(), weights=np.repeat(t.facet_area, 3),
                                              minlength=s.nv) / 3.0, 3)).tocsc()
        B = np.column_stack([C, _rigid_motions(s.X)])
        d = np.concatenate([resid, np.zeros(6)])
        E0 = t.energy
        X0 = state(s)
        cache = {}
        while True:
            dx = _bordered((H + mu * mass).tocsc(), B, -gL, d, cache,
                           np.repeat(s.X, 3, axis=0))
            pred = -(gL @ dx + 0.5 * dx @ (H @ dx))
            tt = it._move(X0, dx.reshape(-1, 3), 1.0, cons, None, None, mobile, targets,
                          None, trial=True)
            if math.isfinite(tt.energy) and tt.energy <= E0 + 1e-13 * abs(E0):
                rho = (E0 - tt.energy) / pred if pred > 0 else 1.0
                mu = max(mu * max(1 / 3, 1 - (2 * rho - 1) ** 3), 1e-12)
                nu = 2.0
                break
            restore_state(s, X0)
            mu *= nu
            nu *= 2.0
            if mu > 1e12:
                session.recalc()
                return False, step, gnorm
        session.recalc()
        if guard is not None and not guard(s):
            return False, step + 1, gnorm
    return False, maxit, gnorm


def _solve_stage(session, maxit, guard, flips):
    """Minimise at the current λ: :func:`newton_lm`; with ``flips`` > 0,
    then equiangulate (``u`` sweeps until none flips) and solve again, at
    most ``flips`` times, until a solve is followed by no flip.  Returns
    ``(converged, Newton steps, edges flipped)``."""
    ok, steps, _ = newton_lm(session, maxit=maxit, guard=guard)
    flipped = 0
    for _ in range(flips):
        if guard is not None and not guard(session.surface):
            break
        n = 0
        for _ in range(50):
            k = session.equiangulate(echo=False)
            n += k
            if k == 0:
                break
        flipped += n
        if n == 0:
            break
        ok, k, _ = newton_lm(session, maxit=maxit, guard=guard)
        steps += k
    return ok, steps, flipped


def harmonic_continuation(session: Session, lam_min: float = 1e-3, factor: float = 2.0,
                          min_angle_deg: float = 10.0, maxit: int = 80,
                          require_converged: bool = False, flips: int = 0,
                          log: list | None = None) -> float:
    """Lower λ (the modulus of quantity ``harm``) while the mesh stays healthy.

    At the current λ the surface is minimised by :func:`newton_lm` (at most
    ``maxit`` steps); then λ/``factor`` is tried from there, down to
    ``lam_min``.  A stage is kept while the smallest angle stays at least
    ``min_angle_deg`` (and, with ``require_converged``, Newton met its
    tolerance).  The first stage that fails is undone (the surface and λ of
    the last kept stage come back) and the continuation stops; after
    refining, :func:`run` calls it again from the λ reached.  The failure it
    guards against is abrupt: measured on all three shapes, the smallest
    angle drops from 35–45° to below 10° within one halving of λ while W
    drops sharply, mostly below the smooth minimum (docs/paper.md).

    ``flips`` > 0 lets the triangulation follow the surface: after each
    Newton solve the mesh is equiangulated (``u``) and solved again (see
    :func:`_solve_stage`), so the harmonic energy measures the distortion
    from the equilateral structure of the *current*, Delaunay-like
    triangulation instead of the icosphere's.  ``log`` (a list) receives
    one dict per stage.

    Returns the final λ.
    """
    def healthy(surf):
        return min_angle(surf.X, surf.F) >= min_angle_deg

    def harm():
        return session.surface.quantities["harm"]

    def entry(lam, ok, n, nflip, good):
        s = session.surface
        return {"lambda": lam, "converged": ok, "steps": n, "flips": nflip, "kept": good,
                "W": session.totals.quantity_values["willmore"],
                "min_angle_deg": min_angle(s.X, s.F)}
    lam = harm().modulus
    ok, n, nflip = _solve_stage(session, maxit, None, flips)
    good = (ok or not require_converged) and healthy(session.surface)
    if log is not None:
        log.append(entry(lam, ok, n, nflip, good))
    if not good:
        return lam
    while lam / factor >= lam_min * (1 - 1e-12):
        keep = copy.deepcopy(session.surface)
        harm().modulus = lam / factor
        session.recalc()
        ok, n, nflip = _solve_stage(session, maxit, healthy, flips)
        good = (ok or not require_converged) and healthy(session.surface)
        if log is not None:
            log.append(entry(lam / factor, ok, n, nflip, good))
        if not good:
            session._replace_surface(keep)
            harm().modulus = lam
            session.recalc()
            break
        lam = harm().modulus
    return lam

