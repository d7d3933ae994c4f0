"""Solvers of the discrete phase study besides the damped minimisation
(:func:`~pyevolver.studies.vesicle_newton.newton_lm`): restoring the fixed
values after a continuation step in ``v``, and plain Newton on the
constrained critical-point equations, which converges to saddles too (the
unstable parts of a branch, where any descent leaves the branch)."""
from __future__ import annotations

import math

import numpy as np

from ..constraints import state
from ..evolve import gradient as GR
from ..evolve.hessian import lagrangian_gradient, lagrangian_hessian
from ..evolve.iterate import _Constraints
from ..session.core import Session
from .vesicle_newton import _rigid_motions, solve_step


def restore(session: Session, rounds: int = 5) -> None:
    """Move the surface onto its fixed values (area quantity, body volume)
    along the constraint gradients, as ``g`` does after a step; used when
    the target volume changed (a newton_lm step must lower the energy, and
    restoring a changed volume may raise it).  At most ``rounds`` times the
    Evolver's restoring iteration (which stops at its target tolerance)."""
    s = session.surface
    cons = _Constraints(s)
    targets = cons.targets(s)
    for _ in range(rounds):
        session.iterator._move(state(s), np.zeros_like(s.X), 1.0, cons, None, None,
                               ~s.vattr["fixed"], targets, None, trial=True)
        session.recalc()
        if np.all(np.abs(targets - cons.values(s.evaluate())) < 1e-12 * np.abs(targets)):
            break


def _grad_lagrangian(s, cons):
    """(gL, C, lam, resid, targets) at the surface's current shape."""
    t = s.evaluate()
    gE = GR.energy_gradient(t)
    C = np.stack([g.ravel() for g in cons.gradients(t)], 1)
    lam = np.linalg.lstsq(C, gE.ravel(), rcond=None)[0]
    targets = cons.targets(s)
    return gE.ravel() - C @ lam, C, lam, targets - cons.values(t), targets


def newton_critical(session: Session, tol: float = 1e-9, maxit: int = 30
                    ) -> tuple[bool, int, float]:
    """Newton on ``∇L = 0`` with the fixed values and no rigid motion (the
    bordered system of :func:`newton_lm` with μ = 0, solved by the engine's
    indefinite solver), the step halved until max |∇L| drops (at most 8
    times; then the shorter step is kept anyway): it converges to a saddle
    as well as to a minimum from a close enough start; abandoned when the
    energy passes twice its start (a diverging iteration).  Returns
    ``(converged, steps, max |∇L|)``."""
    s = session.surface
    it = session.iterator
    cons = _Constraints(s)
    mobile = ~s.vattr["fixed"]
    gnorm = math.inf
    E0 = s.evaluate().energy
    for step in range(maxit):
        gL, C, lam, resid, targets = _grad_lagrangian(s, cons)
        gnorm = float(np.abs(gL).max())
        if not math.isfinite(gnorm) or s.evaluate().energy > 2 * abs(E0):
            return False, step, gnorm          # diverging (mesh folding up)
        if gnorm < tol and np.all(np.abs(resid) < 1e-10 * np.abs(targets)):
            return True, step, gnorm

        H = lagrangian_hessian(s, cons, lam, lagrangian_gradient(cons, lam)).tocsc()
        B = np.column_stack([C, _rigid_motions(s.X)])
        d = np.concatenate([resid, np.zeros(B.shape[1] - len(resid))])
        dx = solve_step(H, B, -gL, d, np.repeat(s.X, 3, axis=0))[:H.shape[0]].reshape(-1, 3)
        X0 = state(s)
        scale = 1.0
        for _ in range(8):
            it._move(X0, dx, scale, cons, None, None, mobile, targets, None, trial=True)
            new = float(np.abs(_grad_lagrangian(s, cons)[0]).max())
            if math.isfinite(new) and new < gnorm:
                break
            scale *= 0.5
        session.recalc()
    return False, maxit, gnorm
