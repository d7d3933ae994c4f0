"""Whether the session's totals still describe its state, so that the
evaluation after a command can be skipped.

After every command the session evaluates the surface again (energies,
areas, volumes: :meth:`Session.refresh`).  Many commands have just done so
(``r``, ``u``, ``V`` replace the surface and evaluate the new one; ``g``
ends with the evaluation of its last move) or change nothing the
evaluation reads (``print``, ``printf``, ``list``...).  When an evaluation
is made, :func:`mark` records a fingerprint of everything the evaluation
can read: the surface's attributes (coordinates, element attributes,
constraint memberships, bodies, quantities and their methods, a few levels
deep; not its caches of derived data) and the session's variables,
toggles, settings and arrays.  Arrays enter by shape, type and a CRC-32 of
their bytes, so a change made in place (``set vertex x ...``, an attribute
assignment, a user of the API writing into ``surface.X``) changes the
fingerprint as a new array does; only the connectivity arrays ``E`` and
``FE``, which nothing changes in place, enter by identity.
:func:`is_fresh` says whether the totals are still the marked ones and the
fingerprint is unchanged; only then is the evaluation skipped.  Objects
beyond the depth followed enter by identity (kept alive with the record):
only a change made in place that deep (none is known) would go unseen.
"""
from __future__ import annotations

import zlib
from typing import Any

import numpy as np

#: how deep objects are followed (surface -> quantity -> method -> its fields)
DEPTH = 4
#: the surface's private caches of derived data (rebuilt from the state when
#: missing or out of date; their appearance must not force an evaluation)
CACHES = frozenset({"_topo", "_corners", "_corner_sides", "_lift_cache", "_rings",
                    "_attr_cache", "_free_boundary", "_loop_eval", "_edge_first",
                    "_along_first", "_fresh"})
#: arrays that enter by identity: the connectivity, never changed in place on
#: a surface in use (``Surface.topology`` caches on the same rule; operations
#: that change it build new arrays)
BY_IDENTITY = frozenset({"E", "FE"})
_SCALARS = (int, float, complex, str, bytes, bool, type(None))


def _array(a: np.ndarray) -> tuple:
    if a.dtype.hasobject:
        return ("O", a.shape, tuple(map(id, a.ravel().tolist())))
    if not a.flags.c_contiguous:
        a = np.ascontiguousarray(a)
    return (a.shape, a.dtype.str, zlib.crc32(memoryview(a).cast("B")) if a.size else 0)


def _fp(x: Any, depth: int, seen: dict) -> Any:
    if isinstance(x, _SCALARS):
        return x
    if isinstance(x, np.ndarray):
        return _array(x)
    if isinstance(x, np.generic):
        return x.item()
    key = id(x)
    if key in seen or depth <= 0:
        return ("id", key)
    seen[key] = x                 # (kept alive with the record: no reuse of the id)
    if isinstance(x, dict):
        return ("d", tuple((_fp(k, 1, seen), _fp(v, depth - 1, seen)) for k, v in x.items()))
    if isinstance(x, (list, tuple)):
        return ("l", tuple(_fp(v, depth - 1, seen) for v in x))
    if isinstance(x, (set, frozenset)):
        return ("s", key, len(x))
    d = getattr(x, "__dict__", None)
    if d is None or callable(x):
        return ("id", key)
    return ("o", key, tuple((k, _fp(v, depth - 1, seen) if k not in BY_IDENTITY
                             else _same(v, seen)) for k, v in d.items() if k not in CACHES))


def _same(x: Any, seen: dict) -> tuple:
    seen[id(x)] = x
    return ("id", id(x), getattr(x, "shape", None))


def fingerprint(session: Any) -> tuple:
    """A value that changes whenever anything an evaluation reads changes
    (equal fingerprints: the same state, as far as the evaluation can see),
    and the objects it names by identity (to be kept alive with it)."""
    s = session.surface
    seen: dict = {id(session.totals): session.totals}
    fp = (_fp(s, DEPTH + 1, seen),
          _fp(session.variables, DEPTH, seen), _fp(session.toggles, 2, seen),
          _fp(session.settings, 2, seen), _fp(session.arrays, 2, seen))
    return fp, seen


def mark(session: Any) -> None:
    """Record that ``session.totals`` is the evaluation of the current state."""
    if session.surface is None or session.totals is None:
        forget(session)
        return
    session._fresh = (session.totals, session.surface) + fingerprint(session)


def forget(session: Any) -> None:
    """The totals may no longer describe the state (the next check evaluates)."""
    session.__dict__.pop("_fresh", None)


def is_fresh(session: Any) -> bool:
    """True when the totals are those :func:`mark` recorded and nothing the
    evaluation reads has changed since (and no stale totals of autopop are
    kept)."""
    rec = session.__dict__.get("_fresh")
    if rec is None or session.__dict__.get("_stale_totals") is not None:
        return False
    totals, surface, fp, _ = rec
    if totals is not session.totals or surface is not session.surface:
        return False
    if getattr(totals, "surface", surface) is not surface:
        return False
    return fingerprint(session)[0] == fp
