"""Lark transformer from parse trees to expression nodes (shared rules)."""
from __future__ import annotations

import os

from lark import v_args
from lark.visitors import Transformer_NonRecursive

from ..errors import UnsupportedError, ExpressionError
from . import nodes as N

GRAMMAR_DIR = os.path.dirname(__file__)


def expr_grammar() -> str:
    """The text of ``expr.lark``, the expression rules shared by the grammars."""
    with open(os.path.join(GRAMMAR_DIR, "expr.lark")) as fh:
        return fh.read()


def parse_number(text: str) -> float:
    """A number token's value: decimal (``d`` exponents too), ``0x`` hex or
    ``...b`` binary."""
    t = text.lower()
    if t.startswith("0x"):
        return float(int(t[2:], 16))
    if t.endswith("b") and set(t[:-1]) <= {"0", "1"}:
        return float(int(t[:-1], 2))
    return float(t.replace("d", "e"))


@v_args(inline=True)
class ExprTransformer(Transformer_NonRecursive):
    """Builds :mod:`pyevolver.expr.nodes` trees (iteratively: a deeply nested
    expression cannot exhaust Python's recursion; its depth is checked after,
    see :data:`pyevolver.limits.MAX_NESTING`)."""

    def number(self, tok):
        return N.Num(parse_number(str(tok)))

    def var(self, tok):
        return N.Var(str(tok), tok.line, tok.column)

    def STRING(self, tok):
        return N.Str(unescape(str(tok)[1:-1]))

    def call(self, name, *args):
        nm = str(name).lower()
        args = [a for a in args if a is not None]
        if nm in N.UNSUPPORTED_FUNCS:
            raise _at(UnsupportedError(f"function {nm}()"), name)
        if nm in N.FUNC1:
            if len(args) != 1:
                raise _at(ExpressionError(f"{nm}() takes one argument, got {len(args)}"), name)
        elif nm in N.FUNC2:
            if len(args) != 2:
                raise _at(ExpressionError(f"{nm}() takes two arguments, got {len(args)}"),
                          name)
        else:
            return self.user_call(name, args)
        return N.Func(nm, args)

    def user_call(self, name, args):
        raise ExpressionError(f"unknown function '{name}'")

    def binop(self, a, op, b):
        o = str(op).lower()
        if o == "**":
            o = "^"
        return N.Bin(o, a, b)

    def neg(self, _op, a):
        return N.neg(a) if isinstance(a, N.Num) else N.Neg(a)

    def pos(self, _op, a):
        return a

    def cond(self, c, a, b):
        return N.Cond(c, a, b)

    def or_(self, a, _op, b):
        return N.Or(a, b)

    def and_(self, a, _op, b):
        return N.And(a, b)

    def not_(self, _op, a):
        return N.Not(a)

    def compare(self, a, op, b):
        return N.Cmp(str(op), a, b)


def _at(exc, tok):
    """``exc`` with the position of the token ``tok`` (``line``, ``column``
    attributes, read by the datafile reader and the command parser)."""
    exc.line = getattr(tok, "line", None)
    exc.column = getattr(tok, "column", None)
    return exc


_ESCAPES = {"n": "\n", "r": "\r", "t": "\t", "b": "\b", "q": '"'}


def unescape(s: str) -> str:
    """A string literal's backslash escapes (``\\n``, ``\\t``, ...) replaced."""
    if "\\" not in s:
        return s
    out = []
    i = 0
    while i < len(s):
        c = s[i]
        if c == "\\" and i + 1 < len(s):
            d = s[i + 1]
            out.append(_ESCAPES.get(d, d))
            i += 2
        else:
            out.append(c)
            i += 1
    return "".join(out)
