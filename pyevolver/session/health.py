"""The check after every command: values that became infinite or NaN make
the command fail (the session restores the state before it); degenerate
facets are reported with the Evolver's warning.

The Evolver prints ``WARNING! Zero area for facet N.`` when its motion meets
a facet of zero area; pyevolver prints the same text after a command that
ran iterations and left such facets, once for each new set of them.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import CommandError
from ..commands import fresh

#: most zero-area facets named one by one (then a count)
MAX_NAMED = 10


def check(session: Any, before: Any = None, motion: Any = None) -> None:
    """Recompute the energies (as after every command) and fail when the
    command made coordinates or the energy infinite or NaN.

    ``before``: the totals before the command (an energy already infinite
    before the command is not the command's fault); ``motion``: the last
    motion of ``g`` before it (``Session._last_motion``).  The warnings of zero-area facets and
    unconverged projections come after a command that ran iterations (``g``,
    ``hessian``, ...), as the Evolver prints them from its motion.
    """
    s = session.surface
    if s is None:
        return
    if not np.all(np.isfinite(s.X)):
        # e.g. a huge jiggle or a boundary formula out of its domain
        raise CommandError("the command would make vertex coordinates infinite or NaN")
    if not fresh.is_fresh(session):     # (nothing changed since the last evaluation)
        session.refresh()
    t = session.totals
    e = getattr(t, "energy", 0.0)
    if t is not None and not np.isfinite(e):
        e0 = getattr(before, "energy", 0.0)
        if before is None or np.isfinite(e0):
            raise CommandError(f"the command would make the total energy {_word(e)} "
                               f"(an overflow, or a formula out of its domain); "
                               f"the surface is as it was before it")
    if session.__dict__.get("_last_motion") is not motion:   # REF warns in its motion
        warn_zero_area(session, before)             # the facets the motion started from
        warn_zero_area(session)
        warn_unconverged(session)
    elif s.__dict__.pop("_unconverged", None) is not None:
        pass                          # (a projection outside an iteration: REF's own rules)


def warn_unconverged(session: Any) -> None:
    """REF's WARNING 1792 for the first vertex a projection onto its
    level-set constraint left unconverged during the command."""
    s = session.surface
    rec = s.__dict__.pop("_unconverged", None) if s is not None else None
    if rec is None:
        return
    row, cid, res, maxit, tol = rec
    vid = int(s.ids("vertex")[row]) if row < s.nv else row + 1
    session.write_err(f"WARNING 1792: Vertex {vid} doesn't converge to constraint {cid} "
                      f"after {maxit} iterations. \n maxdiff = {res:g}, constraint_tolerance "
                      f"{tol:g}\n\n")


#: the numerical failures a command or a load turns into a plain message
NUMERICAL = (np.linalg.LinAlgError, FloatingPointError, ZeroDivisionError)


def explain(exc: BaseException, load: bool = False) -> str:
    """A numerical failure inside a command (``load``: in the first
    evaluation of a loaded datafile) in plain words."""
    text = str(exc).lower()
    if isinstance(exc, np.linalg.LinAlgError) and "singular" in text:
        what = ("a singular linear system (e.g. a constraint whose gradient vanishes at a "
                "vertex, or facets of zero area)")
    elif isinstance(exc, np.linalg.LinAlgError):
        what = f"a linear system that could not be solved ({exc})"
    elif isinstance(exc, ZeroDivisionError):
        what = "a division by zero"
    else:
        what = f"a floating-point error ({exc})"
    if load:
        return (f"evaluating the loaded surface met {what}: coordinates, attributes or "
                f"parameters out of range?")
    return f"the command met {what} and was stopped; the surface is as it was before it"


def _word(v: float) -> str:
    return "NaN" if np.isnan(v) else "infinite"


def warn_zero_area(session: Any, totals: Any = None) -> None:
    """``WARNING! Zero area for facet N.`` for the facets of zero area (in
    ``totals``, default the session's), when that set changed since the
    last warning."""
    s, t = session.surface, totals if totals is not None else session.totals
    if getattr(t, "surface", s) is not s:
        return
    area = getattr(t, "facet_area", None)
    if s is None or area is None or not len(area):
        return
    zero = np.flatnonzero(np.asarray(area) == 0)
    key = (id(s), tuple(zero[:MAX_NAMED + 1]), len(zero))
    if key == session.__dict__.get("_zero_area_warned"):
        return
    session._zero_area_warned = key
    if not len(zero):
        return
    ids = s.ids("facet")[zero]
    for fid in ids[:MAX_NAMED]:
        session.write_err(f"WARNING! Zero area for facet {int(fid)}.\n")
    if len(ids) > MAX_NAMED:
        session.write_err(f"WARNING! Zero area for {len(ids) - MAX_NAMED} more facets.\n")


def check_loaded(session: Any, scene: Any) -> None:
    """After loading: a coordinate or energy that overflowed is named with
    its line (the datafile loads; a command that keeps it non-finite fails
    cleanly), and zero-area facets are reported."""
    s, t = session.surface, session.totals
    if s is None:
        return
    where = scene.filename
    bad = np.flatnonzero(~np.all(np.isfinite(s.X), axis=1))
    if len(bad):
        vid = int(s.ids("vertex")[bad[0]])
        block = scene.vertices
        try:
            where = f"{where}:{block.lines[list(block.ids).index(vid)]}"
        except (ValueError, IndexError):
            pass
        session.write_err(f"{where}: warning: vertex {vid} has an infinite or NaN coordinate "
                          f"(a number beyond the floating-point range)\n")
    elif t is not None and not np.isfinite(getattr(t, "energy", 0.0)):
        session.write_err(f"{where}: warning: the total energy is {_word(t.energy)} "
                          f"(an overflow: coordinates or parameters too large)\n")
