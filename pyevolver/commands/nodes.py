"""Expression nodes of the command language beyond :mod:`pyevolver.expr`:
``vertex[3]``, ``x.attr``, ``sum(edges, length)``, ``on_constraint 1``,
``{1, 2}``, ``f(x)``, ``arr[i]``, ``sprintf``.  They evaluate against an
:class:`~pyevolver.commands.interpreter.Env` (``env.session``).
"""
from __future__ import annotations

import numpy as np

from ..errors import ExpressionError
from ..expr import nodes as N
from . import element_attrs, elements
from .cformat import c_format
from .values import _KIND, QRef, as_float

class ElemIndex(N.Node):
    __slots__ = ("kind", "index")

    def __init__(self, kind, index):
        self.kind = _KIND[kind.lower()]
        self.index = index

    def ev(self, env):
        return elements.element(env.session, self.kind, self.index.ev(env))

    def children(self):
        return (self.index,)


class Attr(N.Node):
    __slots__ = ("base", "name", "index")

    def __init__(self, base, name, index=None):
        self.base = base
        self.name = name.lower()
        self.index = index

    def ev(self, env):
        if isinstance(self.base, ArrayRef) and self.base.name == "is_constraint":
            return _is_constraint(env, self.base, self.name)
        base = self.base.ev(env)
        if self.index is None:
            idx = None
        elif self.name in ("on_quantity", "on_method_instance"):
            idx = _quantity_arg(self.index, env)
        elif isinstance(self.index, list):
            idx = tuple(i.ev(env) for i in self.index)
        else:
            idx = self.index.ev(env)
        return element_attrs.get_attr(env.session, base, self.name, idx)

    def children(self):
        if isinstance(self.index, list):
            return (self.base,) + tuple(self.index)
        return (self.base,) + ((self.index,) if self.index is not None else ())


def _is_constraint(env, ref, what):
    """``is_constraint[n].fixed`` / ``.nonnegative`` / ``.nonpositive``: the
    kind of level-set constraint n (a number or a name; manual, constrnt.htm)."""
    if len(ref.index) != 1 or what not in ("fixed", "nonnegative", "nonpositive"):
        raise ExpressionError("is_constraint[n] has .fixed, .nonnegative and .nonpositive")
    s = env.session
    v = s.interp.value(ref.index[0])
    cons = s.surface.constraints if s.surface is not None else {}
    if isinstance(v, str) or float(v) != int(v) or int(v) not in cons:
        raise ExpressionError(f"is_constraint[{v}]: no such constraint")
    flags = cons[int(v)].flags
    if what == "fixed":
        return float(not flags & {"nonnegative", "nonpositive"})
    return float(what in flags)


class Aggregate(N.Node):
    __slots__ = ("op", "gen", "expr")

    def __init__(self, op, gen, expr):
        self.op = op.lower()
        self.gen = gen
        self.expr = expr

    def ev(self, env):
        vals = []
        tick = env.session.interp.tick
        for el in elements.generate(env.session, self.gen, env):
            tick()
            with env.element(el, self.gen.var):
                vals.append(as_float(self.expr.ev(env), f"the value of {self.op}()"))
        if self.op == "count":
            return float(len(vals))
        if not vals:                # REF: max -1e38, min 1e38 over no elements
            return {"max": -1e38, "min": 1e38}.get(self.op, 0.0)
        if self.op == "sum":
            return float(sum(vals))
        if self.op == "avg":
            return float(sum(vals) / len(vals))
        if self.op == "max":
            return float(max(vals))
        return float(min(vals))


class OnTest(N.Node):
    __slots__ = ("what", "arg")

    def __init__(self, what, arg):
        self.what = what.lower()
        self.arg = arg

    def ev(self, env):
        el = env.current()
        if el is None:
            raise ExpressionError(f"{self.what} needs an element (use it in a where clause)")
        if self.what in ("on_quantity", "on_method_instance"):
            return element_attrs.get_attr(env.session, el, self.what, _quantity_arg(self.arg, env))
        return element_attrs.get_attr(env.session, el, self.what, self.arg.ev(env))


def _quantity_arg(node, env):
    """The quantity named after ``on_quantity`` (a name that inside an
    element loop would otherwise read the element's own quantity value)."""
    s = env.session.surface
    if isinstance(node, N.Var) and s is not None and node.name.lower() in s.quantities:
        return QRef(node.name.lower())
    return node.ev(env)


class ArrayLit(N.Node):
    """``{a, b, c}`` (nested: ``{{..},{..}}``) as a whole-array value."""

    __slots__ = ("items",)

    def __init__(self, items):
        self.items = items

    def ev(self, env):
        def val(x):
            if isinstance(x, list):
                return [val(y) for y in x]
            v = env.session.interp.value(x)
            if isinstance(v, str):
                raise ExpressionError("array values must be numbers")
            return float(v)
        try:
            return N.array_value(val(self.items))
        except ValueError:
            raise ExpressionError("the rows of an array list differ in length") from None

    def children(self):
        def walk(x):
            return [n for y in x for n in walk(y)] if isinstance(x, list) else [x]
        return tuple(walk(self.items))


class UserCall(N.Node):
    """``name(args)`` in an expression: a user function or a string builtin."""

    __slots__ = ("name", "args")

    def __init__(self, name, args):
        self.name = name.lower()
        self.args = args

    def ev(self, env):
        return env.session.interp.call_in_expr(self.name, self.args)

    def children(self):
        return tuple(self.args)


class ArrayRef(N.Node):
    """``arr[i][j]`` of an array variable (1-based, as in the Evolver)."""

    __slots__ = ("name", "index")

    def __init__(self, name, index):
        self.name = name.lower()
        self.index = index

    def ev(self, env):
        interp = env.session.interp
        idx = [interp.value(i) for i in self.index]
        if self.name not in env.session.arrays and env.current() is not None:
            # a bare indexed attribute inside a generator: form_factors[2]
            return element_attrs.get_attr(env.session, env.current(), self.name,
                                          idx[0] if len(idx) == 1 else tuple(idx))
        arr, pos = interp.array_slot(self.name, idx, partial=True)
        v = arr[pos]
        if np.ndim(v):
            return N.array_value(v)
        return v if isinstance(v, str) else float(v)

    def children(self):
        return tuple(self.index)


class Sprintf(N.Node):
    __slots__ = ("args",)

    def __init__(self, args):
        self.args = args

    def ev(self, env):
        interp = env.session.interp
        vals = [interp.value(a) for a in self.args]
        if not vals or not isinstance(vals[0], str):
            raise ExpressionError("sprintf needs a format string first")
        return c_format(vals[0], vals[1:])

    def children(self):
        return tuple(self.args)

