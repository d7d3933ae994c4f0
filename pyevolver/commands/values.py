"""Values and control-flow signals of the command language: element and
quantity references, user procedures, generators, number conversions (as C
converts), and the exceptions that carry ``break``/``continue``/``return``,
``quit``, ``load`` and Ctrl-C out of a running command.
"""
from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np

from ..errors import CommandError, ExpressionError
from ..expr import nodes as N

class SessionLike(Protocol):
    """What the commands use of a session (duck typing: no module of
    :mod:`pyevolver.commands` imports :mod:`pyevolver.session`)."""

    surface: Any
    totals: Any
    settings: dict
    toggles: dict
    variables: dict
    interp: Any

    def write(self, text: str) -> None: ...

    def note(self, text: str) -> None: ...

    def recalc(self, keep_cg: bool = False, reposition: bool = False) -> None: ...


def as_float(v, what="a value"):
    """``v`` as a float; strings, elements and quantities are refused."""
    if isinstance(v, np.ndarray) and v.size == 1:
        v = v.reshape(())[()]
    if not N.is_number(v) or isinstance(v, np.ndarray):
        raise ExpressionError(f"{what} must be a number, got {N._what(v)}")
    return float(v)

def is_true(v, what="a where condition"):
    """The truth of a ``where`` condition: numbers other than 0 (a string
    is false, as before); arrays and elements are refused."""
    if isinstance(v, str):
        return False
    if isinstance(v, np.ndarray) and v.size == 1:
        v = v.reshape(())[()]
    if not N.is_number(v) or isinstance(v, np.ndarray):
        raise ExpressionError(f"{what} must be a number, got {N._what(v)}")
    return bool(v != 0)

def as_int(v, what="a count"):
    """``v`` as an integer (truncated toward zero, as C converts): counts,
    indices, ids.  Strings, NaN and infinities are refused."""
    v = as_float(v, what)
    if not math.isfinite(v):
        raise ExpressionError(f"{what} must be a finite number, got {v:g}")
    return int(v)

# expression nodes of the command language

class ElemRef:
    """A reference to one element: kind in vertex/edge/facet/body, 0-based."""

    __slots__ = ("kind", "i", "sign")

    def __init__(self, kind, i, sign=1):
        self.kind = kind
        self.i = i
        self.sign = sign

    def __repr__(self):
        return f"{self.kind}[{self.i + 1}]"

class QRef:
    __slots__ = ("name",)

    def __init__(self, name):
        self.name = name

_KIND = {"vertex": "vertex", "vertices": "vertex", "edge": "edge", "edges": "edge",
         "facet": "facet", "facets": "facet", "face": "facet", "faces": "facet",
         "body": "body", "bodies": "body", "facetedge": "facetedge", "facetedges": "facetedge"}

class Proc:
    """A user command: ``name := {...}`` (no parameters), ``procedure``
    or ``function``."""

    __slots__ = ("name", "params", "body", "function", "text")

    def __init__(self, name, params, body, function=False):
        self.name = name
        self.params = params          # [(type, name)]
        self.body = body              # statement tuple, None for a prototype
        self.function = function

    def _nested(self):
        return (self.body,)

class Generator:
    """``vertex``, ``vertex[3]``, ``ee.vertex``, ``vertex[2].edge``, with an
    optional loop variable and ``where`` condition."""

    def __init__(self, base, var=None, where=None):
        self.base = base            # ("all", kind) / ("index", kind, expr) / ("sub", base, kind, idx) / ("varsub", name, kind, idx)
        self.var = var
        self.where = where

    def _nested(self):
        return (self.base, self.where)

    @property
    def kind(self):
        b = self.base
        if b[0] == "var":
            return None
        return b[1] if b[0] in ("all", "index") else b[2]

class _Break(Exception):
    def __init__(self, n=1):
        self.n = n

class _Continue(Exception):
    def __init__(self, n=1):
        self.n = n

class _Return(Exception):
    def __init__(self, value=None):
        self.value = value

class TimeLimitExceeded(CommandError):
    """A command ran past the session's time limit (``--timeout``)."""

class Interrupted(Exception):
    """Ctrl-C: the running command stops and the prompt returns."""

class Loaded(Exception):
    """``load`` replaced the session: the command that ran it ends."""

class Quit(Exception):
    def __init__(self, code=0):
        self.code = code

