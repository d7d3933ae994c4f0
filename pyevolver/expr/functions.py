"""Constants, functions and operators of the Evolver expression language.

The numeric layer under :mod:`pyevolver.expr.nodes`: named constants
(``pi``, ``e``, the colours), the one- and two-argument functions (with the
elliptic integrals of Abramowitz & Stegun ch. 17), the binary and comparison
operators with the Evolver's conventions (``5 % 0`` is nan, ``idiv``
truncates), and whole-array values of the command language.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..errors import ExpressionError

COLOURS = {
    "clear": -1, "transparent": -1, "black": 0, "blue": 1, "green": 2,
    "cyan": 3, "red": 4, "magenta": 5, "brown": 6, "lightgray": 7,
    "darkgray": 8, "lightblue": 9, "lightgreen": 10, "lightcyan": 11,
    "lightred": 12, "lightmagenta": 13, "yellow": 14, "white": 15,
}

CONSTANTS = {"pi": math.pi, "e": math.e, **{k: float(v) for k, v in COLOURS.items()}}


def _acos(a):
    return np.arccos(np.clip(a, -1.0, 1.0))


def _asin(a):
    return np.arcsin(np.clip(a, -1.0, 1.0))


FUNC1 = {
    "abs": np.abs, "sqr": lambda a: a * a, "sqrt": np.sqrt, "sin": np.sin,
    "cos": np.cos, "tan": np.tan, "asin": _asin, "acos": _acos,
    "atan": np.arctan, "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh,
    "asinh": np.arcsinh, "acosh": np.arccosh, "atanh": np.arctanh,
    "exp": np.exp, "log": np.log, "ceil": np.ceil, "floor": np.floor,
}


def _domain(bad, msg):
    if np.any(bad):
        raise ExpressionError(msg)


def _ellipk(m):
    """Complete elliptic integral of the first kind K(m), parameter m
    (Abramowitz & Stegun 17.3.1; the Evolver's convention)."""
    _domain(np.asarray(m) >= 1, "ellipticK domain violation, parameter >= 1.")
    from scipy.special import ellipk      # 0.4 s to import: only when used
    return ellipk(m)


def _ellipe(m):
    """Complete elliptic integral of the second kind E(m) (A&S 17.3.3)."""
    _domain(np.asarray(m) > 1, "ellipticE domain violation, parameter > 1.")
    from scipy.special import ellipe
    return ellipe(m)


def _ellipf(phi, m):
    """Incomplete elliptic integral of the first kind F(phi|m) (A&S 17.2.7)."""
    _domain(np.asarray(m) * np.sin(phi) ** 2 > 1,
            "incompleteEllipticF domain violation, m*sin(phi)^2 > 1.")
    from scipy.special import ellipkinc
    return ellipkinc(phi, m)


def _ellipeinc(phi, m):
    """Incomplete elliptic integral of the second kind E(phi|m) (A&S 17.2.8)."""
    _domain(np.asarray(m) * np.sin(phi) ** 2 > 1,
            "incompleteEllipticE domain violation, m*sin(phi)^2 > 1.")
    from scipy.special import ellipeinc
    return ellipeinc(phi, m)


FUNC1["elliptick"] = _ellipk
FUNC1["elliptice"] = _ellipe
FUNC2 = {
    "atan2": np.arctan2, "pow": np.power, "maximum": np.maximum,
    "minimum": np.minimum, "incompleteellipticf": _ellipf,
    "incompleteelliptice": _ellipeinc,
}


def _wrap_fields(w):
    """(k, ...) signed per-axis wraps of torus-group codes (6-bit fields,
    5-bit two's complement: 31 is -1; pyevolver.model.symmetry)."""
    c = np.asarray(np.rint(w), dtype=np.int64)
    f = np.stack([(c >> (6 * d)) & 31 for d in range(5)])
    return np.where(f >= 16, f - 32, f)


def _wrap_code(f):
    return sum((f[d] & 31) << (6 * d) for d in range(len(f))).astype(float)


def _wrap_compose(a, b):
    """The torus group's product of two wrap codes (the translations add)."""
    return _wrap_code(_wrap_fields(a) + _wrap_fields(b))


def _wrap_inverse(a):
    """The torus group's inverse of a wrap code."""
    return _wrap_code(-_wrap_fields(a))


FUNC1["wrap_inverse"] = _wrap_inverse
FUNC2["wrap_compose"] = _wrap_compose
# recognised but refused
UNSUPPORTED_FUNCS = {
    "usr1", "usr2", "usr3", "usr4", "usr5",
    "usr6", "usr7", "usr8", "usr9", "usr10",
}


class ArrayValue(np.ndarray):
    """A whole array as a value in the command language (``vn :=
    ff.vertex[1].vertex_normal``, ``2*vn``, ``vn*vn`` the dot product), as
    opposed to the per-point arrays of a vectorized formula evaluation."""


def array_value(a: Any) -> ArrayValue:
    """``a`` as a float :class:`ArrayValue` (a copy)."""
    return np.array(a, dtype=float).view(ArrayValue)


def _num(v):
    """Python float for scalars, array otherwise."""
    if isinstance(v, np.ndarray) and v.ndim == 0 and not isinstance(v, ArrayValue):
        return float(v)
    return v


def is_number(v: Any) -> bool:
    """True for the values arithmetic accepts: numbers and numpy arrays (not
    strings, elements or quantities)."""
    return isinstance(v, (float, int, np.ndarray, np.number))


def _mod(a, b):
    if not isinstance(b, np.ndarray) and b == 0:
        return math.nan * (a if isinstance(a, np.ndarray) else 1.0)  # REF: 5 % 0 is nan
    with np.errstate(all="ignore"):
        return a - np.floor(np.true_divide(a, b)) * b


def _idiv(a, b):
    a = np.trunc(a)
    b = np.trunc(b)
    if not isinstance(b, np.ndarray) and b == 0:
        raise ExpressionError("division by zero (idiv)")
    with np.errstate(all="ignore"):
        return np.trunc(np.true_divide(a, b))


BINOPS = {
    "+": lambda a, b: a + b,
    "-": lambda a, b: a - b,
    "*": lambda a, b: a * b,
    "/": lambda a, b: a / b,
    "^": lambda a, b: np.power(a, b) if isinstance(a, np.ndarray) or isinstance(b, np.ndarray) else _pow(a, b),
    "%": _mod,
    "mod": _mod,
    "imod": lambda a, b: _mod(np.trunc(a), np.trunc(b)),
    "idiv": _idiv,
}


def _pow(a, b):
    a = float(a)
    b = float(b)
    try:
        r = a ** b
    except ZeroDivisionError:
        return math.inf
    except OverflowError:
        return math.inf
    if isinstance(r, complex):
        return math.nan
    return r


CMPOPS = {
    "==": lambda a, b: a == b, "!=": lambda a, b: a != b,
    "<": lambda a, b: a < b, ">": lambda a, b: a > b,
    "<=": lambda a, b: a <= b, ">=": lambda a, b: a >= b,
}


def _what(v):
    """How a non-number is named in messages."""
    if isinstance(v, str):
        return "a string"
    if isinstance(v, np.ndarray):
        return f"an array of shape {list(v.shape)}"
    kind = getattr(v, "kind", None)
    if isinstance(kind, str):
        return f"a {kind}"
    return "a quantity" if hasattr(v, "name") else "something else"


def _bool(v):
    if isinstance(v, np.ndarray):
        return v.astype(float)
    return 1.0 if v else 0.0
