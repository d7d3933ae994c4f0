"""Expression trees of the Evolver expression language.

The same tree serves two purposes:

* *formulas* (constraint level sets, boundary parametrisations, integrands)
  are evaluated over whole numpy arrays of coordinates at once;
* *command expressions* are evaluated on scalars inside the interpreter.

An environment object supplies names: ``env.lookup(name)`` returns a number,
a string or an array.  The command interpreter extends the tree with element
references and aggregates (see :mod:`pyevolver.commands.nodes`), which share
the :class:`Node` interface.

Derivatives (:func:`diff`) are symbolic, as the Evolver differentiates its
expression trees; they are used for constraint gradients and projections.
"""
from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from ..errors import ExpressionError
from .functions import BINOPS, CMPOPS, FUNC1, FUNC2, _bool, _num, _what
# (also the names of the language, used as nodes.X by the readers and the interpreter)
from .functions import (COLOURS, CONSTANTS, UNSUPPORTED_FUNCS, ArrayValue,  # noqa: F401
                        array_value, is_number)

# ---------------------------------------------------------------------------
# nodes


class Env(Protocol):
    """What :meth:`Node.ev` needs of an environment: ``lookup(name)``
    returns a number, a string or an (n,) array, or raises
    :class:`~pyevolver.errors.ExpressionError` for an unknown name."""

    def lookup(self, name: str) -> Any: ...


class Node:
    """Base class of expression nodes (immutable)."""

    __slots__ = ()
    pos = None  # (line, column) of the node, when known

    def ev(self, env: Env) -> Any:  # pragma: no cover - abstract
        """Evaluate in ``env``.

        Parameters
        ----------
        env : Env
            Supplies the names (parameters, coordinates as (n,) arrays).

        Returns
        -------
        float, str or numpy.ndarray
            A scalar, a string, or an (n,) array when a name is an array.
        """
        raise NotImplementedError

    def is_const(self) -> bool:
        """True when the value needs no environment."""
        return False

    def names(self) -> set[str]:
        """Set of variable names used by the expression."""
        out = set()
        self._names(out)
        return out

    def _names(self, out):
        for c in self.children():
            c._names(out)

    def children(self) -> tuple | list:
        """The sub-expressions."""
        return ()


class Num(Node):
    __slots__ = ("value",)

    def __init__(self, value):
        self.value = float(value)

    def ev(self, env):
        return self.value

    def is_const(self):
        return True

    def __repr__(self):
        return f"Num({self.value!r})"


class Str(Node):
    __slots__ = ("value",)

    def __init__(self, value):
        self.value = value

    def ev(self, env):
        return self.value

    def __repr__(self):
        return f"Str({self.value!r})"


class Var(Node):
    """A name: parameter, variable, internal variable, coordinate, attribute."""

    __slots__ = ("name", "line", "column")

    def __init__(self, name, line=None, column=None):
        self.name = name.lower()
        self.line = line
        self.column = column

    def ev(self, env):
        return env.lookup(self.name)

    def _names(self, out):
        out.add(self.name)

    def __repr__(self):
        return f"Var({self.name!r})"


class Index(Node):
    """``name[i]``: the i-th entry (from 1) of an array attribute in a formula
    of vertex values (``x4 = ref_coord[1]``); over n points the attribute
    is an (n, k) array and the result its column i."""

    __slots__ = ("name", "index", "line", "column")

    def __init__(self, name, index, line=None, column=None):
        self.name = name.lower()
        self.index = index
        self.line = line
        self.column = column

    def ev(self, env):
        base = np.asarray(env.lookup(self.name), dtype=float)
        k = self.index.ev(env)
        if np.ndim(k) or not np.isfinite(k) or k != int(k):
            raise ExpressionError(f"{self.name}[...]: the index must be one integer")
        size = base.shape[-1] if base.ndim else 0
        if not 1 <= int(k) <= size:
            raise ExpressionError(f"{self.name}[{int(k)}]: index out of range 1 to {size}")
        return base[..., int(k) - 1]

    def _names(self, out):
        out.add(self.name)
        self.index._names(out)

    def children(self):
        return (self.index,)

    def __repr__(self):
        return f"Index({self.name!r}, {self.index!r})"


class Neg(Node):
    __slots__ = ("a",)

    def __init__(self, a):
        self.a = a

    def ev(self, env):
        v = self.a.ev(env)
        if not is_number(v):
            raise ExpressionError(f"unary '-' needs a number, got {_what(v)}")
        return -v

    def children(self):
        return (self.a,)

    def is_const(self):
        return self.a.is_const()


class Not(Node):
    __slots__ = ("a",)

    def __init__(self, a):
        self.a = a

    def ev(self, env):
        v = self.a.ev(env)
        if isinstance(v, np.ndarray):
            return (v == 0).astype(float)
        return 1.0 if v == 0 else 0.0

    def children(self):
        return (self.a,)


class Bin(Node):
    __slots__ = ("op", "a", "b")

    def __init__(self, op, a, b):
        self.op = op
        self.a = a
        self.b = b

    def ev(self, env):
        if not isinstance(self.a, Bin):
            return self._apply(self.a.ev(env), self.b.ev(env))
        # a long flat chain (``1+2+...``, left-deep): its left spine is walked
        # in a loop, so 100,000 terms need no recursion (left to right, as
        # the nested calls would evaluate them)
        spine = []
        node = self
        while isinstance(node, Bin):
            spine.append(node)
            node = node.a
        v = node.ev(env)
        for node in reversed(spine):
            v = node._apply(v, node.b.ev(env))
        return v

    def _apply(self, a, b):
        if not (is_number(a) and is_number(b)):
            raise ExpressionError(f"operator '{self.op}' needs numbers, got "
                                  f"{_what(b if is_number(a) else a)}")
        with np.errstate(all="ignore"):
            if self.op == "/" and not isinstance(b, np.ndarray) and b == 0 \
                    and not isinstance(a, np.ndarray):
                raise ExpressionError("Division by zero.")     # REF's ERROR 1258
            if self.op == "*" and isinstance(a, ArrayValue) and isinstance(b, ArrayValue):
                if a.shape != b.shape:
                    raise ExpressionError(f"array product needs equal shapes, got "
                                          f"{list(a.shape)} and {list(b.shape)}")
                return float(np.sum(np.multiply(np.asarray(a), np.asarray(b))))  # dot product
            return _num(BINOPS[self.op](a, b))

    def children(self):
        return (self.a, self.b)

    def _spine(self):
        """The operands of the left-deep chain this node ends (iteratively)."""
        out = []
        node = self
        while isinstance(node, Bin):
            out.append(node.b)
            node = node.a
        out.append(node)
        return out

    def is_const(self):
        return all(c.is_const() for c in self._spine())

    def _names(self, out):
        for c in self._spine():
            c._names(out)

    def __repr__(self):
        return f"Bin({self.op!r}, {self.a!r}, {self.b!r})"


class Cmp(Node):
    __slots__ = ("op", "a", "b")

    def __init__(self, op, a, b):
        self.op = op
        self.a = a
        self.b = b

    def ev(self, env):
        a = self.a.ev(env)
        b = self.b.ev(env)
        if isinstance(a, str) and isinstance(b, str):
            return _bool(CMPOPS[self.op](a, b))
        if not (is_number(a) and is_number(b)):
            raise ExpressionError(f"'{self.op}' compares two numbers or two strings, got "
                                  f"{_what(a)} and {_what(b)}")
        return _bool(CMPOPS[self.op](a, b))

    def children(self):
        return (self.a, self.b)


class And(Node):
    __slots__ = ("a", "b")

    def __init__(self, a, b):
        self.a = a
        self.b = b

    def ev(self, env):
        a = self.a.ev(env)
        if isinstance(a, np.ndarray):
            return np.logical_and(a != 0, self.b.ev(env) != 0).astype(float)
        if not a:
            return 0.0
        return _bool(self.b.ev(env) != 0)

    def children(self):
        return (self.a, self.b)


class Or(Node):
    __slots__ = ("a", "b")

    def __init__(self, a, b):
        self.a = a
        self.b = b

    def ev(self, env):
        a = self.a.ev(env)
        if isinstance(a, np.ndarray):
            return np.logical_or(a != 0, self.b.ev(env) != 0).astype(float)
        if a:
            return 1.0
        return _bool(self.b.ev(env) != 0)

    def children(self):
        return (self.a, self.b)


#: > 0 while the branches of an element-wise ``?:`` are evaluated
_LENIENT = 0


class Cond(Node):
    __slots__ = ("c", "a", "b")

    def __init__(self, c, a, b):
        self.c = c
        self.a = a
        self.b = b

    def ev(self, env):
        c = self.c.ev(env)
        if isinstance(c, ArrayValue) or not (is_number(c) or isinstance(c, str)):
            raise ExpressionError(f"the condition of '?:' must be a number, got {_what(c)}")
        if isinstance(c, np.ndarray):
            # both branches are evaluated on every row: a domain error in the
            # rows the condition discards is not an error (REF evaluates per
            # element)
            global _LENIENT
            _LENIENT += 1
            try:
                a, b = self.a.ev(env), self.b.ev(env)
            finally:
                _LENIENT -= 1
            return np.where(c != 0, a, b)
        return self.a.ev(env) if c else self.b.ev(env)

    def children(self):
        return (self.c, self.a, self.b)


class Func(Node):
    __slots__ = ("name", "args")

    def __init__(self, name, args):
        self.name = name.lower()
        self.args = tuple(args)

    def ev(self, env):
        vals = [a.ev(env) for a in self.args]
        for v in vals:
            if not is_number(v):
                raise ExpressionError(f"{self.name}() needs a number, got {_what(v)}")
        if self.name in ("wrap_compose", "wrap_inverse"):
            group = _wrap_group(env)
            if group is not None:           # a group other than the torus (model.groups)
                return _num(group.function(self.name, *vals))
        with np.errstate(all="ignore"):
            if len(vals) == 1:
                v = vals[0]
                if self.name == "sqrt" and not isinstance(v, np.ndarray) and v < 0:
                    # REF's ERROR 1263
                    raise ExpressionError(f"Square root of negative number {v:g}.")
                if self.name == "log":
                    # REF: ERROR 1425 for a number, ERROR 1264 "Log of zero or
                    # negative number" inside element integrands (slidestr.fe's
                    # content integral under `U`); log(0) of a number is -inf
                    if isinstance(v, np.ndarray):
                        if not _LENIENT and np.any(v <= 0):
                            raise ExpressionError("Log of zero or negative number.")
                    elif v < 0:
                        raise ExpressionError("log of negative number.")
                return _num(FUNC1[self.name](v))
            return _num(FUNC2[self.name](vals[0], vals[1]))

    def children(self):
        return self.args

    def is_const(self):
        return all(a.is_const() for a in self.args)

    def __repr__(self):
        return f"Func({self.name!r}, {list(self.args)!r})"


# ---------------------------------------------------------------------------
# symbolic differentiation

ZERO = Num(0.0)
ONE = Num(1.0)


def _is(n, v):
    return isinstance(n, Num) and n.value == v


def add(a: Node, b: Node) -> Node:
    """``a + b``, folded when a side is 0 or both are numbers."""
    if _is(a, 0):
        return b
    if _is(b, 0):
        return a
    if isinstance(a, Num) and isinstance(b, Num):
        return Num(a.value + b.value)
    return Bin("+", a, b)


def sub(a: Node, b: Node) -> Node:
    """``a - b``, folded when a side is 0 or both are numbers."""
    if _is(b, 0):
        return a
    if _is(a, 0):
        return neg(b)
    if isinstance(a, Num) and isinstance(b, Num):
        return Num(a.value - b.value)
    return Bin("-", a, b)


def mul(a: Node, b: Node) -> Node:
    """``a * b``, folded when a side is 0 or 1 or both are numbers."""
    if _is(a, 0) or _is(b, 0):
        return ZERO
    if _is(a, 1):
        return b
    if _is(b, 1):
        return a
    if isinstance(a, Num) and isinstance(b, Num):
        return Num(a.value * b.value)
    return Bin("*", a, b)


def div(a: Node, b: Node) -> Node:
    """``a / b``, folded when ``a`` is 0 or ``b`` is 1."""
    if _is(a, 0):
        return ZERO
    if _is(b, 1):
        return a
    return Bin("/", a, b)


def neg(a: Node) -> Node:
    """``-a``, folded for a number and a negation."""
    if isinstance(a, Num):
        return Num(-a.value)
    if isinstance(a, Neg):
        return a.a
    return Neg(a)


def diff(node: Node, var: str) -> Node:
    """Symbolic derivative of ``node`` with respect to the variable ``var``.

    ``var`` is a lower-case name ("x", "y", "z", "p1", ...).  Coordinate
    aliases (``x1`` = ``x``) are resolved by the caller through
    :func:`canonical_coords`.  Piecewise constructs differentiate branchwise.
    """
    d = _DIFF.get(type(node))
    if d is None:
        if node.names().isdisjoint({var}):
            return ZERO
        raise ExpressionError(f"cannot differentiate {type(node).__name__}")
    return d(node, var)


def _d_func(n, var):
    args = n.args
    if len(args) == 2:
        a, b = args
        da, db = diff(a, var), diff(b, var)
        if n.name == "atan2":  # atan2(y, x): (x dy - y dx)/(x^2+y^2)
            den = add(mul(a, a), mul(b, b))
            return div(sub(mul(b, da), mul(a, db)), den)
        if n.name == "pow":
            return diff(Bin("^", a, b), var)
        if n.name in ("maximum", "minimum"):
            cmpop = ">=" if n.name == "maximum" else "<="
            return Cond(Cmp(cmpop, a, b), da, db)
        if n.name in ("incompleteellipticf", "incompleteelliptice"):
            # a = phi, b = m;  Delta = sqrt(1 - m sin^2 phi)  (A&S 17.2, DLMF 19.4)
            F = Func("incompleteellipticf", [a, b])
            E = Func("incompleteelliptice", [a, b])
            sn = Func("sin", [a])
            delta = Func("sqrt", [sub(ONE, mul(b, mul(sn, sn)))])
            if n.name == "incompleteellipticf":
                dphi = div(ONE, delta)
                dm = sub(sub(div(E, mul(Num(2.0), mul(b, sub(ONE, b)))), div(F, mul(Num(2.0), b))),
                         div(Func("sin", [mul(Num(2.0), a)]),
                             mul(Num(4.0), mul(sub(ONE, b), delta))))
            else:
                dphi = delta
                dm = div(sub(E, F), mul(Num(2.0), b))
            return add(mul(dphi, da), mul(dm, db))
        raise ExpressionError(f"cannot differentiate {n.name}")
    a = args[0]
    da = diff(a, var)
    if _is(da, 0):
        return ZERO
    nm = n.name
    if nm == "sqrt":
        g = div(Num(0.5), n)
    elif nm == "sin":
        g = Func("cos", [a])
    elif nm == "cos":
        g = neg(Func("sin", [a]))
    elif nm == "tan":
        c = Func("cos", [a])
        g = div(ONE, mul(c, c))
    elif nm == "exp":
        g = n
    elif nm == "log":
        g = div(ONE, a)
    elif nm == "abs":
        g = Cond(Cmp(">=", a, ZERO), ONE, Num(-1.0))
    elif nm == "sqr":
        g = mul(Num(2.0), a)
    elif nm == "sinh":
        g = Func("cosh", [a])
    elif nm == "cosh":
        g = Func("sinh", [a])
    elif nm == "tanh":
        c = Func("cosh", [a])
        g = div(ONE, mul(c, c))
    elif nm == "atan":
        g = div(ONE, add(ONE, mul(a, a)))
    elif nm == "asin":
        g = div(ONE, Func("sqrt", [sub(ONE, mul(a, a))]))
    elif nm == "acos":
        g = neg(div(ONE, Func("sqrt", [sub(ONE, mul(a, a))])))
    elif nm == "asinh":
        g = div(ONE, Func("sqrt", [add(mul(a, a), ONE)]))
    elif nm == "acosh":
        g = div(ONE, Func("sqrt", [sub(mul(a, a), ONE)]))
    elif nm == "atanh":
        g = div(ONE, sub(ONE, mul(a, a)))
    elif nm in ("ceil", "floor"):
        return ZERO
    elif nm == "elliptick":     # dK/dm = (E - (1-m) K) / (2m(1-m))  (DLMF 19.4.1)
        K, E = n, Func("elliptice", [a])
        g = div(sub(E, mul(sub(ONE, a), K)), mul(Num(2.0), mul(a, sub(ONE, a))))
    elif nm == "elliptice":     # dE/dm = (E - K) / (2m)
        g = div(sub(n, Func("elliptick", [a])), mul(Num(2.0), a))
    else:
        raise ExpressionError(f"cannot differentiate {nm}")
    return mul(g, da)


def _d_bin(n, var):
    a, b, op = n.a, n.b, n.op
    da, db = diff(a, var), diff(b, var)
    if op == "+":
        return add(da, db)
    if op == "-":
        return sub(da, db)
    if op == "*":
        return add(mul(da, b), mul(a, db))
    if op == "/":
        if _is(db, 0):
            return div(da, b)
        return div(sub(mul(da, b), mul(a, db)), mul(b, b))
    if op == "^":
        if _is(db, 0):
            if isinstance(b, Num):
                if b.value == 0:
                    return ZERO
                return mul(mul(Num(b.value), Bin("^", a, Num(b.value - 1.0))), da)
            return mul(mul(b, Bin("^", a, sub(b, ONE))), da)
        # general a^b = exp(b log a)
        return mul(n, add(mul(db, Func("log", [a])), div(mul(b, da), a)))
    if op in ("%", "mod", "imod", "idiv"):
        if op in ("%", "mod"):
            return da
        return ZERO
    raise ExpressionError(f"cannot differentiate operator {op}")


_DIFF = {
    Num: lambda n, v: ZERO,
    Str: lambda n, v: ZERO,
    Var: lambda n, v: ONE if n.name == v else ZERO,
    Neg: lambda n, v: neg(diff(n.a, v)),
    Bin: _d_bin,
    Func: _d_func,
    Cond: lambda n, v: Cond(n.c, diff(n.a, v), diff(n.b, v)),
    Cmp: lambda n, v: ZERO,
    Not: lambda n, v: ZERO,
    And: lambda n, v: ZERO,
    Or: lambda n, v: ZERO,
}

COORD_ALIASES = {"x1": "x", "x2": "y", "x3": "z", "x4": "w"}

# the canonical names of the coordinates x1 .. x9 (SPACE_DIMENSION up to 9)
COORD_NAMES = ("x", "y", "z", "w", "x5", "x6", "x7", "x8", "x9")


def coord_names(n: int) -> tuple[str, ...]:
    """The canonical names of the first ``n`` coordinates (``x y z w x5 ...``)."""
    return COORD_NAMES[:n]


def coord_dict(P: np.ndarray) -> dict:
    """``{name: column}`` of the points ``P (n, d)``, by :func:`coord_names`."""
    return {nm: P[:, k] for k, nm in enumerate(COORD_NAMES[:P.shape[1]])}



def canonical_coords(node: Node) -> Node:
    """Rewrite ``x1 x2 x3`` to ``x y z`` so derivatives see one name."""
    if isinstance(node, Var):
        if node.name in COORD_ALIASES:
            return Var(COORD_ALIASES[node.name])
        return node
    if isinstance(node, (Num, Str)):
        return node
    if isinstance(node, Neg):
        return Neg(canonical_coords(node.a))
    if isinstance(node, Not):
        return Not(canonical_coords(node.a))
    if isinstance(node, Bin):
        return Bin(node.op, canonical_coords(node.a), canonical_coords(node.b))
    if isinstance(node, Cmp):
        return Cmp(node.op, canonical_coords(node.a), canonical_coords(node.b))
    if isinstance(node, And):
        return And(canonical_coords(node.a), canonical_coords(node.b))
    if isinstance(node, Or):
        return Or(canonical_coords(node.a), canonical_coords(node.b))
    if isinstance(node, Cond):
        return Cond(canonical_coords(node.c), canonical_coords(node.a), canonical_coords(node.b))
    if isinstance(node, Func):
        return Func(node.name, [canonical_coords(a) for a in node.args])
    if isinstance(node, Index):
        return Index(node.name, canonical_coords(node.index), node.line, node.column)
    return node


# ---------------------------------------------------------------------------
# environments


def _wrap_group(env):
    """The symmetry group the environment offers as ``__symmetry_group__``
    (None: the torus group's codes)."""
    try:
        g = env.lookup("__symmetry_group__")
    except ExpressionError:
        return None
    return g if hasattr(g, "function") else None


class MapEnv:
    """Environment over a dict of names with a fallback environment.

    Parameters
    ----------
    values : dict
        Name -> number, string or (n,) array.
    parent : Env, optional
        Asked for the names not in ``values``; without one, the constants
        (``pi``, ``e``, colours) and then :class:`ExpressionError`.
    """

    def __init__(self, values: dict, parent: Env | None = None):
        self.values = values
        self.parent = parent

    def lookup(self, name: str) -> Any:
        """The value of ``name`` (see the class)."""
        v = self.values.get(name)
        if v is not None:
            return v
        if self.parent is not None:
            return self.parent.lookup(name)
        if name in CONSTANTS:
            return CONSTANTS[name]
        raise ExpressionError(f"undefined name '{name}'")


class Formula:
    """A formula of coordinates (and parameters), evaluated over arrays.

    Parameters
    ----------
    node : Node
        The expression tree.
    text : str
        Source text, for messages and ``print`` of formulas.
    """

    def __init__(self, node: Node, text: str = ""):
        self.node = canonical_coords(node)
        self.text = text
        self._grads = {}

    def __call__(self, env: Env) -> Any:
        return self.node.ev(env)

    def grad(self, var: str) -> Node:
        """The derivative along ``var`` (symbolic, cached)."""
        g = self._grads.get(var)
        if g is None:
            g = self._grads[var] = diff(self.node, var)
        return g

    def values(self, params: Env, coords: dict, n: int) -> np.ndarray:
        """Evaluate at ``n`` points; returns an (n,) array.

        ``coords`` maps ``x, y, z`` (and ``p1`` ...) to (n,) arrays;
        ``params`` is the parameter environment.
        """
        v = self.node.ev(MapEnv(coords, params))
        return np.broadcast_to(np.asarray(v, dtype=float), (n,))

    def hessian(self, params: Env, coords: dict, n: int,
                names: tuple[str, ...] = ("x", "y", "z")) -> np.ndarray:
        """(n, k, k) second derivatives (symbolic, cached)."""
        env = MapEnv(coords, params)
        k = len(names)
        out = np.empty((n, k, k))
        for i, a in enumerate(names):
            for j, b in enumerate(names):
                key = (a, b)
                h = self._grads.get(key)
                if h is None:
                    h = self._grads[key] = diff(self.grad(a), b)
                out[:, i, j] = np.broadcast_to(np.asarray(h.ev(env), dtype=float), (n,))
        return out

    def gradient(self, params: Env, coords: dict, n: int,
                 names: tuple[str, ...] = ("x", "y", "z")) -> np.ndarray:
        """(n, len(names)) array of partial derivatives."""
        env = MapEnv(coords, params)
        out = np.empty((n, len(names)))
        for k, nm in enumerate(names):
            out[:, k] = np.broadcast_to(np.asarray(self.grad(nm).ev(env), dtype=float), (n,))
        return out
