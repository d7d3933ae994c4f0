"""``set vertex z z*1.5`` and ``where z > 0.5`` over whole vertex columns.

``set gen attr expr`` computes every element's value first, then assigns
them (as the Evolver's ``set`` does), so the values do not depend on the
order of the elements.  Evaluated element by element through the
interpreter that costs tens of microseconds a vertex (two seconds on a
40,962-vertex sphere).  When the expression is plain arithmetic — numbers,
the vertex's coordinates, scalar variables, ``+ - * /`` and unary minus —
it is evaluated once on the coordinate columns of the selected vertices,
with the same IEEE operations on the same operands, so every value is the
one the element-by-element evaluation gives (tests/commands/test_columns.py).
Anything else — functions, powers, comparisons, element references, arrays,
a variable that shadows a coordinate with something other than a number,
a non-finite value (an error the element loop reports with its element) —
returns None and the element loop runs as before.

A ``where`` condition over all the vertices (``set vertex fixed where z >
0.9``, ``list vertex where id < 10``) is evaluated the same way when it is
made of comparisons, ``and``, ``or``, ``not`` and such arithmetic of the
coordinates, ``id`` and scalar variables (:func:`where_mask`); a division
there only by a non-zero number, since the element loop's ``and``/``or``
stop early and would never divide where the columns do.
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ..expr import nodes as N

#: coordinate names of a vertex and their columns
COORDS = {"x": 0, "y": 1, "z": 2, "x1": 0, "x2": 1, "x3": 2}
_OPS = frozenset("+-*/")


def _scalar(env: Any, name: str) -> Optional[float]:
    """The number ``name`` is in ``env`` before any element attribute (a
    local, a session variable), or None."""
    s = env.session
    for scope in (env.scopes[-1] if env.scopes else {}, s.variables):
        if name in scope:
            v = scope[name]
            if isinstance(v, (float, int)) and not isinstance(v, bool):
                return float(v)
            return np.nan                       # (a string, an element...: not here)
    return None


def _names_ok(root: Any, env: Any, gen: Any, sdim: int, logic: bool = False) -> bool:
    """Whether ``root`` is plain arithmetic on numbers, coordinates and
    scalar variables (walked iteratively: long flat sums are fine); with
    ``logic`` also comparisons, ``and``, ``or``, ``not`` and ``id``, and
    divisions only by a non-zero number."""
    s = env.session
    stack = [root]
    while stack:
        n = stack.pop()
        t = type(n)
        if t is N.Num:
            continue
        if t is N.Neg or (logic and t is N.Not):
            stack.append(n.a)
            continue
        if t is N.Bin and n.op in _OPS:
            if logic and n.op == "/" and not (type(n.b) is N.Num and n.b.value != 0):
                return False
            stack.append(n.a)
            stack.append(n.b)
            continue
        if logic and (t is N.Cmp or t is N.And or t is N.Or):
            stack.append(n.a)
            stack.append(n.b)
            continue
        if t is not N.Var:
            return False
        name = n.name
        if name == gen.var or any(var == name for var, _ in env.frames) or name in s.arrays:
            return False
        v = _scalar(env, name)
        if v is not None:
            if v != v:                              # (NaN: not a number here)
                return False
            continue
        if logic and name == "id":
            continue
        if name not in COORDS or COORDS[name] >= sdim or ("vertex", name) in s.surface.extra:
            return False
    return True


class _Columns:
    """The environment of the column evaluation: coordinates as arrays."""

    def __init__(self, env: Any, X: np.ndarray, idx: np.ndarray):
        self.env, self.X, self.idx = env, X, idx

    def lookup(self, name: str) -> Any:
        v = _scalar(self.env, name)
        if v is not None:
            return v
        if name == "id":
            return self.env.session.surface.ids("vertex")[self.idx].astype(float)
        return self.X[self.idx, COORDS[name]]


def column_values(session: Any, gen: Any, els: list, expr: Any,
                  env: Any) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """``(indices, values)``: the vertices ``els`` and the values of
    ``expr`` at them, (n,) arrays; None when the column evaluation does not
    apply (the element loop then runs)."""
    s = session.surface
    if gen.kind != "vertex" or not els or s is None or env.frames:
        return None
    if not _names_ok(expr, env, gen, min(s.sdim, s.X.shape[1])):
        return None
    idx = np.fromiter((e.i for e in els), np.int64, len(els))
    v = expr.ev(_Columns(env, s.X, idx))
    out = np.broadcast_to(np.asarray(v, dtype=float), idx.shape)
    if not np.all(np.isfinite(out)):
        return None                              # (the loop names the element)
    return idx, out


def where_mask(session: Any, gen: Any, els: list, env: Any) -> Optional[np.ndarray]:
    """The truth of ``gen``'s ``where`` condition at each of ``els`` ((n,)
    bool), when ``gen`` is every vertex (``els`` in index order) and the
    condition qualifies; else None (the element loop)."""
    s = session.surface
    if gen.kind != "vertex" or gen.base[0] != "all" or s is None or env.frames \
            or len(els) != s.nv or not els:
        return None
    if not _names_ok(gen.where, env, gen, min(s.sdim, s.X.shape[1]), logic=True):
        return None
    idx = np.arange(len(els))
    v = gen.where.ev(_Columns(env, s.X, idx))
    if isinstance(v, str):
        return None
    return np.broadcast_to(np.asarray(v, dtype=float) != 0, idx.shape)
