"""OPTIMIZING_PARAMETER: variables that ``g`` moves along with the vertices.

Surface Evolver 2.70 manual, datafile chapter, "Optimizing parameter": such a
variable "joins the vertex coordinates as an independent variable during
optimization"; its gradient is taken numerically, by central differences
with its PDELTA (default 0.0001), and its motion is multiplied by its PSCALE
(default 1).  In a ``g`` step the parameter moves by ``−scale · pscale · ∂E/∂p``
alongside the vertices' ``scale · force`` (the same line search), as
evolver-nox-d does (tests/evolve/test_optparams.py compares the values after
each step).  Changing a parameter moves what depends on it: vertices on
parametric boundaries are put where their boundary parameters now say and
PERIODS given by expressions are re-evaluated.

Not done here (refused by name where they are used): optimizing parameters
together with fixed volumes or FIXED quantities (even a parameter that no
fixed value depends on changes how evolver-nox-d restores the volumes: on
cube.fe with an optimizing parameter in a constraint's energy integrand, REF's
``m 0.2; g 1`` ends 2.5e-5 away in vertex[5].z from the same run with a plain
parameter, which pyevolver reproduces), with ``conj_grad`` and in
``hessian`` / ``newton`` / ``bfgs``.
"""
from __future__ import annotations

import numpy as np

from ..constraints import boundary_eval, boundary_groups
from ..errors import UnsupportedError
from ..expr import nodes as N
from ..model.surface import Surface


def names(s: Surface) -> list[str]:
    """The optimizing parameters of ``s`` (declaration order)."""
    return list(getattr(s, "optimizing", None) or {})


def values(s: Surface) -> np.ndarray:
    """(k,) the current values of the optimizing parameters."""
    return np.array([float(s.params[n]) for n in names(s)])


def set_values(s: Surface, vals: np.ndarray) -> None:
    """Give the optimizing parameters the values ``vals`` (k,) and move what
    depends on them: PERIODS given by expressions, vertices on parametric
    boundaries (all of them, FIXED ones included, as the Evolver does)."""
    for n, v in zip(names(s), vals):
        s.params[n] = float(v)
    exprs = getattr(s, "period_exprs", None)
    if exprs is not None and s.periods is not None:
        env = N.MapEnv(s.params)
        sd = s.sdim
        P = np.array([float(e) if isinstance(e, float) else float(e.ev(env))
                      for e in exprs]).reshape(sd, sd)
        if not np.array_equal(P, s.periods[:sd, :sd]):
            s.periods = s.periods.copy()
            s.periods[:sd, :sd] = P
            s.__dict__.pop("_lift_cache", None)
    if s.boundaries and "params" in s.vattr:
        groups = boundary_groups(s)
        if groups:
            s.X = s.X.copy()
            for bid, rows in groups:
                s.X[rows], _ = boundary_eval(s, bid, s.vattr["params"][rows])


def gradient(s: Surface) -> np.ndarray:
    """(k,) central differences ``(E(p + δ) − E(p − δ)) / 2δ`` of the total
    energy, each parameter with its own PDELTA δ; the surface is left as it was."""
    ks = names(s)
    base = values(s)
    X0 = s.X
    periods0 = s.periods
    out = np.zeros(len(ks))
    try:
        for i, n in enumerate(ks):
            d = float(s.optimizing[n][0])
            e = []
            for sign in (1.0, -1.0):
                v = base.copy()
                v[i] += sign * d
                set_values(s, v)
                e.append(s.evaluate().energy)
            out[i] = (e[0] - e[1]) / (2.0 * d)
    finally:
        for n, v in zip(ks, base):
            s.params[n] = float(v)
        s.X = X0
        if s.periods is not periods0:
            s.periods = periods0
            s.__dict__.pop("_lift_cache", None)
    return out


def scales(s: Surface) -> np.ndarray:
    """(k,) the PSCALE of each optimizing parameter."""
    return np.array([float(s.optimizing[n][1]) for n in names(s)])


def refuse(s: Surface, what: str) -> None:
    """Refuse ``what`` by name when ``s`` has optimizing parameters."""
    if names(s):
        raise UnsupportedError(f"OPTIMIZING_PARAMETER with {what}")
