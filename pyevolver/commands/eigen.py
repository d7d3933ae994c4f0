"""The eigenvalue commands of the Hessian: ``eigenprobe λ``,
``eigenprobe(λ, n)``, ``ritz(λ, n)``, ``lanczos λ``, ``lanczos(λ, n)`` and
``saddle [max]`` (the numbers are :mod:`pyevolver.evolve.eigen`'s; these
handlers read the arguments and print REF's lines).  ``last_eigenvalue``
and the ``eigenvalues`` array are set as in REF; ``hessian_menu``, an
interactive menu, stays refused.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import CommandError, dimension_error
from ..evolve.iterate import _Constraints
from . import registry
from .registry import Command
from .values import as_float, as_int

FAMILY = "eigen"
RITZ_SYNTAX = "Syntax: RITZ(probe_value, number_of_eigenvalues)"        # REF's messages
PROBE_SYNTAX = "Syntax: EIGENPROBE probe_value   or  EIGENPROBE(probe_value, iterationmax)"
LANCZOS_SYNTAX = "Syntax: lanczos rexpr   or   lanczos(expr,count)"


def _system(session: Any, what: str):
    """The constrained Hessian of the session's surface (hessian_system),
    after REF's checks: vertices, valid pressures."""
    from ..evolve import eigen as EG        # (the Hessian's modules: when first used)
    from ..evolve.hessian import hessian_system
    s = session.surface
    if s is None or s.nv == 0:
        raise CommandError(f"{what}: the surface has no vertices")
    it = session.iterator
    if not it.pressures_valid and len(_Constraints(s)):
        raise CommandError("Pressures invalid. Do regular iteration before Hessian "
                           "to set pressures.")
    note_beyond(session)
    if s.X.shape[1] > 3:
        raise dimension_error(s.sdim, "the Hessian's eigenvalues", "need")
    hs = hessian_system(it, normal=it.settings.hessian_normal, lowrank=True)
    mix = _mix(session)
    if mix is not None:
        EG.metric(hs, s, mix)
    return it, hs


def _mix(session: Any) -> float | None:
    """``linear_metric_mix`` when ``linear_metric`` is on, else None."""
    if not session.toggles.get("linear_metric"):
        return None
    mix = as_float(session.settings.get("linear_metric_mix", 0.5), "linear_metric_mix")
    if not 0.0 <= mix <= 1.0:
        raise CommandError(f"linear_metric_mix must be between 0 and 1 (it is {mix:g})")
    return mix


def note_beyond(session: Any) -> None:
    """Say once per session and reason (stderr) where the Hessian commands go
    further than the Evolver (:func:`pyevolver.evolve.eigen.beyond_reference`)."""
    from ..evolve import eigen as EG        # (the Hessian's modules: when first used)
    seen = session.__dict__.setdefault("_beyond_noted", set())
    for note in EG.beyond_reference(session.surface):
        if note not in seen:
            seen.add(note)
            session.write_err(note + "\n")


def _eps(session: Any) -> float:
    return float(session.settings.get("hessian_epsilon", 1e-10))


def _store(session: Any, values) -> None:
    vals = np.asarray(values, float)
    if len(vals):
        session.settings["last_eigenvalue"] = float(vals[0])
    session.arrays["eigenvalues"] = vals.copy()


def _shift(v: Any, what: str) -> float:
    """A finite probe value."""
    x = as_float(v, what)
    if not math.isfinite(x):
        raise CommandError(f"{what} must be finite (it is {x})")
    return x


def eigenprobe(session: Any, shift: float, iterations: int | None = None) -> Any:
    """``eigenprobe λ``: print the inertia of the Hessian relative to λ;
    ``eigenprobe(λ, n)``: then at most n inverse iterations towards the
    eigenvalue nearest λ (stored in ``last_eigenvalue``)."""
    from ..evolve import eigen as EG        # (the Hessian's modules: when first used)
    _, hs = _system(session, "eigenprobe")
    eps = _eps(session)
    if iterations is None:
        inert = EG.inertia(hs, shift, eps)
        session.write(inert.line())
        return inert
    r = EG.inverse_iteration(hs, shift, max(iterations, 0), eps)
    session.write(r.inertia.line())
    for line in r.lines:
        session.write(line)
    if math.isfinite(r.value):
        session.settings["last_eigenvalue"] = r.value
    session.last_eigenvector = r
    return r


def ritz(session: Any, shift: float, count: int, lanczos: bool = False) -> Any:
    """``ritz(λ, n)`` (and ``lanczos``): the inertia relative to λ and the n
    eigenvalues nearest λ, ascending (as REF prints them)."""
    from ..evolve import eigen as EG        # (the Hessian's modules: when first used)
    what = "lanczos" if lanczos else "ritz"
    _, hs = _system(session, what)
    if count < 0:
        raise CommandError(f"{what}: the number of eigenvalues must not be negative")
    r = EG.nearest(hs, shift, count, _eps(session))
    session.write(r.inertia.line())
    for j, v in enumerate(r.values, 1):
        if lanczos:
            session.write("%d  %20.15f\n" % (j, v))
        else:
            session.write("%3d. %20.15f\n" % (j, v))
    _store(session, r.values)
    session.last_eigenvector = r
    return r


def saddle(session: Any, max_step: float | None = None) -> Any:
    """``saddle [max]``: move down along the eigenvector of the lowest
    eigenvalue when it is negative."""
    from ..evolve import eigen as EG        # (the Hessian's modules: when first used)
    if max_step is not None and math.isnan(max_step):
        raise CommandError("the step limit of saddle is not a number")
    it, _ = _system(session, "saddle")
    r = EG.saddle_step(it, normal=it.settings.hessian_normal, max_step=max_step,
                       eps=_eps(session), mix=_mix(session))
    if not math.isfinite(r.value):
        session.write("No degrees of freedom.\n")
        return r
    session.settings["last_eigenvalue"] = r.value
    if r.step is None:
        session.write("Lowest eigenvalue %.15g. Not a saddle point.\n" % r.value)
        return r
    session.write("Lowest eigenvalue %.15g\n" % r.value)
    session.recalc(totals=r.totals)
    for w in r.warnings:
        session.write(w + "\n")
    session.write("stepsize %g\n" % r.step)
    t = session.totals
    session.write("1. %s: %#17.15g energy: %#17.15g \n"
                  % ("length" if session.surface.string else "area", t.total_area, t.energy))
    return r


# -- the registered commands: NAME expr and NAME(expr, expr) ---------------------------
def _bare_eigenprobe(interp, raw, arg):
    if arg is None:
        raise CommandError(PROBE_SYNTAX)
    eigenprobe(interp.session, _shift(interp.value(arg), "the probe value of eigenprobe"))


def _call_eigenprobe(session, args):
    if len(args) not in (1, 2):
        raise CommandError(PROBE_SYNTAX)
    shift = _shift(args[0], "the probe value of eigenprobe")
    n = as_int(args[1], "the iteration limit of eigenprobe") if len(args) > 1 else None
    eigenprobe(session, shift, n)


def _bare_ritz(interp, raw, arg):
    raise CommandError(RITZ_SYNTAX)


def _call_ritz(session, args):
    if len(args) != 2:
        raise CommandError(RITZ_SYNTAX)
    ritz(session, _shift(args[0], "the probe value of ritz"),
         as_int(args[1], "the number of eigenvalues of ritz"))


def _bare_lanczos(interp, raw, arg):
    if arg is None:
        raise CommandError(LANCZOS_SYNTAX)
    ritz(interp.session, _shift(interp.value(arg), "the probe value of lanczos"), 15,
         lanczos=True)


def _call_lanczos(session, args):
    if len(args) not in (1, 2):
        raise CommandError(LANCZOS_SYNTAX)
    n = as_int(args[1], "the number of eigenvalues of lanczos") if len(args) > 1 else 15
    ritz(session, _shift(args[0], "the probe value of lanczos"), n, lanczos=True)


def _bare_saddle(interp, raw, arg):
    saddle(interp.session, None if arg is None else
           as_float(interp.value(arg), "the step limit of saddle"))


def _call_saddle(session, args):
    saddle(session, as_float(args[0], "the step limit of saddle") if args else None)


for _names, _bare, _call, _usage, _help, _max in (
        (("eigenprobe",), _bare_eigenprobe, _call_eigenprobe,
         "eigenprobe value | eigenprobe(value, iterations)",
         "eigenvalue counts of the Hessian below, at and above value", 2),
        (("ritz",), _bare_ritz, _call_ritz, "ritz(value, n)",
         "the n eigenvalues of the Hessian nearest value", 2),
        (("lanczos",), _bare_lanczos, _call_lanczos, "lanczos value | lanczos(value, n)",
         "the eigenvalues of the Hessian nearest value (15 or n)", 2),
        (("saddle",), _bare_saddle, _call_saddle, "saddle [max]",
         "move down the eigenvector of a negative Hessian eigenvalue", 1)):
    registry.add(Command(_names, _bare, _usage, _help, FAMILY, call=_call, max_args=_max))
