"""BFGS for nonsmooth energies: the paper's minimizer for Bobenko's energy.

``circle_willmore`` is not differentiable where a circumcircle angle β
vanishes, and plain gradient descent (``g``) stalls at such kinks.  Lewis &
Overton (*Nonsmooth optimization via quasi-Newton methods*, Math. Program.
141, 2013) show that BFGS with an inexact line search satisfying the weak
Wolfe conditions, bracketed by bisection and doubling, keeps making progress
on such functions (it is the core of GRANSO, which the paper used).

:func:`minimize` works on a flat vector with a ``fun(x) -> (f, g)`` callback;
the inverse Hessian is a dense matrix for up to ``dense_limit`` unknowns,
else the limited-memory two-loop recursion (Nocedal 1980) with ``memory``
pairs.  It returns a :class:`BFGSResult` and calls ``callback(result)`` after
every iteration (a true return value stops the run), as
``scipy.optimize.minimize`` does.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import UnsupportedError
from ..constraints import constrained_vertices
from .gradient import energy_gradient
from .iterate import _Constraints


@dataclass
class BFGSResult:
    """Outcome of :func:`minimize` (also passed to the callback each iteration)."""
    x: np.ndarray
    energy: float
    nit: int = 0
    nfev: int = 0
    message: str = ""
    success: bool = False
    step: float = 0.0
    history: list = field(default_factory=list)     # energies after each iteration
    area: float = math.nan       # the surface's area at ``x`` (minimize_surface)


def weak_wolfe(fun, x, f, g, d, c1=1e-4, c2=0.9, max_evals=60):
    """Step ``t`` along ``d`` with the weak Wolfe conditions
    ``f(x+td) <= f + c1 t g·d`` and ``g(x+td)·d >= c2 g·d`` (Lewis–Overton
    bracketing: bisect when a bound is known, else double).

    Returns ``(t, x1, f1, g1, nfev, ok)``; when no step satisfies both
    within ``max_evals`` evaluations, the best point with sufficient
    decrease found (or ``t = 0``) and ``ok = False``.
    """
    gd = float(g @ d)
    lo, hi, t = 0.0, math.inf, 1.0
    best = (0.0, x, f, g)
    for k in range(1, max_evals + 1):
        x1 = x + t * d
        f1, g1 = fun(x1)
        if not math.isfinite(f1) or f1 > f + c1 * t * gd:
            hi = t
        else:
            if f1 < best[2]:
                best = (t, x1, f1, g1)
            if float(g1 @ d) < c2 * gd:
                lo = t
            else:
                return t, x1, f1, g1, k, True
        t = 0.5 * (lo + hi) if hi < math.inf else 2.0 * lo
        if hi < math.inf and hi - lo <= 1e-16 * max(hi, 1.0):
            break
    return best + (k, False)


def minimize(fun: Callable, x0: np.ndarray, maxiter: int, callback: Callable | None = None,
             gtol: float = 1e-12, dense_limit: int = 3000, memory: int = 30) -> BFGSResult:
    """Minimize ``fun`` (``x -> (f, grad)``, ``x`` and ``grad`` of shape
    (n,)) from ``x0`` by BFGS with the weak Wolfe line search; see the
    module docstring."""
    x = np.asarray(x0, float).copy()
    f, g = fun(x)
    n = len(x)
    dense = n <= dense_limit
    Hinv = None
    pairs: list = []                                 # (s, y, 1/(s·y)) for L-BFGS
    res = BFGSResult(x, f, nfev=1)
    if not math.isfinite(f):
        res.message = "the energy is not finite at the start"
        return res
    for it in range(1, maxiter + 1):
        gn = float(np.linalg.norm(g))
        if gn <= gtol:
            res.message, res.success = "gradient below tolerance", True
            break
        if dense:
            d = -(g if Hinv is None else Hinv @ g)
        else:
            d = -_two_loop(g, pairs)
        if float(g @ d) >= 0:                        # lost descent: restart
            Hinv, pairs = None, []
            d = -g
        t, x1, f1, g1, ne, ok = weak_wolfe(fun, x, f, g, d)
        res.nfev += ne
        if t == 0.0:
            res.message = "the line search found no decrease (a kink or round-off)"
            res.success = True
            break
        s_, y = x1 - x, g1 - g
        sy = float(s_ @ y)
        if sy > 1e-300:
            if dense:
                if Hinv is None:
                    Hinv = np.eye(n) * (sy / float(y @ y))
                rho = 1.0 / sy
                Hy = Hinv @ y
                Hinv += (rho * rho * float(y @ Hy) + rho) * np.outer(s_, s_) \
                    - rho * (np.outer(Hy, s_) + np.outer(s_, Hy))
            else:
                pairs.append((s_, y, 1.0 / sy))
                if len(pairs) > memory:
                    pairs.pop(0)
        x, f, g = x1, f1, g1
        res.x, res.energy, res.nit, res.step = x, f, it, t
        res.history.append(f)
        if callback is not None and callback(res):
            res.message = "stopped by the callback"
            break
        if not ok and np.linalg.norm(s_) <= 1e-15 * max(1.0, float(np.linalg.norm(x))):
            res.message, res.success = "steps below round-off", True
            break
    else:
        res.message = "iteration limit"
    res.x, res.energy = x, f
    return res


def _two_loop(g, pairs):
    """Limited-memory inverse Hessian times ``g`` (Nocedal 1980)."""
    q = g.copy()
    alphas = []
    for s_, y, rho in reversed(pairs):
        a = rho * float(s_ @ q)
        alphas.append(a)
        q -= a * y
    if pairs:
        s_, y, _ = pairs[-1]
        q *= float(s_ @ y) / float(y @ y)
    for (s_, y, rho), a in zip(pairs, reversed(alphas)):
        b = rho * float(y @ q)
        q += (a - b) * s_
    return q


def check_free(surface) -> None:
    """Refuse (:class:`~pyevolver.errors.UnsupportedError`) a surface
    :func:`minimize_surface` cannot minimize: fixed volumes, FIXED
    quantities, mobile vertices on level-set constraints or boundaries."""
    s = surface
    if len(_Constraints(s)):
        raise UnsupportedError("bfgs with fixed volumes or FIXED quantities",
                               "the restoring of constraints is g's")
    mobile = ~s.vattr["fixed"]
    on = constrained_vertices(s)
    if "boundary" in s.vattr:
        on |= s.vattr["boundary"] != 0
    if np.any(on & mobile):
        raise UnsupportedError("bfgs on vertices with level-set constraints or boundaries")


def minimize_surface(surface, maxiter: int, callback: Callable | None = None) -> BFGSResult:
    """:func:`minimize` on the coordinates of the mobile vertices of a free
    surface (the ``bfgs`` command); the surface ends at the result's ``x``.

    Fixed vertices stay; bodies with fixed volumes, FIXED quantities,
    level-set constraints and boundaries are refused
    (:class:`~pyevolver.errors.UnsupportedError`).  ``callback(result)``
    after every iteration, with ``result.area`` the area at ``result.x``;
    a true value stops the run.  On an exception the coordinates are those
    of the last evaluation: the caller restores them.
    """
    s = surface
    check_free(s)
    idx = np.nonzero(~s.vattr["fixed"])[0]
    areas: dict = {}                 # id of an evaluated point -> its area

    def fun(x):
        s.X[idx] = x.reshape(-1, 3)
        t = s.evaluate()
        areas.clear()
        areas[id(x)] = t.total_area
        return t.energy, energy_gradient(t)[idx].ravel()

    def cb(r):
        area = areas.get(id(r.x))
        if area is None:     # the line search kept an earlier point
            s.X[idx] = r.x.reshape(-1, 3)
            area = s.evaluate().total_area
        r.area = area
        return callback is not None and callback(r)

    r = minimize(fun, s.X[idx].ravel().copy(), int(maxiter), callback=cb)
    s.X[idx] = r.x.reshape(-1, 3)
    return r
