"""Parsing commands: ``commands.lark`` (with the expression grammar of
:mod:`pyevolver.expr`) into statement tuples and expression trees.
Scripts are data: nothing reaches Python ``eval``/``exec`` or a shell.
"""
from __future__ import annotations

import functools
import os
import re

from lark import v_args
from lark.exceptions import UnexpectedInput, VisitError

from ..errors import CommandError, PyEvolverError
from ..expr import nodes as N
from ..expr.lark_cache import cached_lark
from ..expr.transform import ExprTransformer, expr_grammar
from ..limits import MAX_NESTING, clip, nesting_depth
from .nodes import (Aggregate, ArrayLit, ArrayRef, Attr, ElemIndex, OnTest, Sprintf,
                    UserCall)
from .toggles import graphics_toggle
from .values import _KIND, Generator, Proc

_HERE = os.path.dirname(__file__)


@functools.lru_cache(maxsize=1)
def command_parser():
    with open(os.path.join(_HERE, "commands.lark")) as fh:
        grammar = expr_grammar() + "\n" + fh.read()
    return cached_lark(grammar, parser="lalr", lexer="contextual", start="start",
                       maybe_placeholders=False)


SETTABLE_ATTRS = {"x", "y", "z", "x1", "x2", "x3", "color", "colour", "frontcolor", "backcolor",
                  "tension", "density", "fixed", "no_refine", "target", "pressure", "volconst",
                  "constraint", "boundary", "opacity"}
UNSUPPORTED_REASONS = {
    "permload": "use replace_load, as the Evolver's manual advises; ::= permanent "
                "variables are not supported either",
    "system": "scripts never run programs", "shell": "scripts never run programs",
    "detorus": "the torus model cannot be unwrapped yet",
    "dissolve": "removing elements one by one is not implemented; delete merges edges",
}


# transformer


@v_args(inline=True)
class _CmdTransformer(ExprTransformer):
    def start(self, seq):
        return seq

    def seq(self, *stmts):
        return ("seq", [s for s in stmts if s is not None])

    def compound(self, seq):
        return seq

    def repeat(self, body, count):
        return ("repeat", body, count)

    def if_(self, _i, cond, _t, then):
        return ("if", cond, then, None)

    def if_else(self, _i, cond, _t, then, _e, other):
        return ("if", cond, then, other)

    def while_(self, _w, cond, _d, body):
        return ("while", cond, body)

    def do_while(self, _d, body, _w, cond):
        return ("dowhile", body, cond)

    def for_(self, _f, *parts):
        # FOR "(" seq_item ";" expr? ";" seq_item ")" stmt; the optional parts
        # are told apart by position
        items = list(parts)
        body = items.pop()
        init = cond = step = None
        rest = [x for x in items]
        # seq_item is a statement tuple or absent; expr is a Node
        stmts = [x for x in rest if isinstance(x, tuple)]
        exprs = [x for x in rest if isinstance(x, N.Node)]
        cond = exprs[0] if exprs else N.Num(1.0)
        if len(stmts) == 2:
            init, step = stmts
        elif len(stmts) == 1:
            # decide by position relative to the condition
            if exprs and rest.index(stmts[0]) < rest.index(exprs[0]):
                init = stmts[0]
            elif exprs:
                step = stmts[0]
            else:
                init = stmts[0]
        return ("for", init, cond, step, body)

    def foreach(self, _f, gen, _d, body):
        return ("foreach", gen, body)

    def redirect(self, body, op, target):
        return ("redirect", body, str(op), target)

    def pipe(self, body, _p, target):
        return ("pipe",)

    def params(self, *ps):
        return list(ps)

    def param(self, typ, name):
        return (str(typ).lower(), str(name).lower())

    def procedure(self, _p, name, *rest):
        params = rest[0] if len(rest) == 2 else []
        return ("procdef", Proc(str(name).lower(), params, rest[-1]))

    def prototype(self, _p, name, params=None):
        return ("procdef", Proc(str(name).lower(), params or [], None))

    def function(self, _f, typ, name, *rest):
        params = rest[0] if len(rest) == 2 else []
        return ("procdef", Proc(str(name).lower(), params, rest[-1], function=True))

    def fprototype(self, _f, typ, name, params=None):
        return ("procdef", Proc(str(name).lower(), params or [], None, function=True))

    def redefine(self, name, _r, body):
        return ("redefine", str(name), body)

    def redefine_restore(self, name, _r):
        return ("redefine", str(name), None)

    def builtin_letter(self, tok):
        return ("bare", str(tok)[1], None, True)

    def local_(self, _l, *names):
        return ("local", [str(n).lower() for n in names])

    def dims(self, *exprs):
        return list(exprs)

    def define_attr(self, _d, kind, _a, name, typ, dims=None):
        return ("define_attr", _KIND[str(kind).lower()], str(name).lower(), str(typ).lower(),
                dims or [])

    def define_fe_attr(self, _d, *rest):
        return ("unsupported", "facetedge attributes")

    def define_array(self, _d, name, typ, dims=None):
        return ("define_array", str(name).lower(), str(typ).lower(), dims or [])

    def exec_(self, _e, expr):
        return ("exec", expr)

    def read(self, _r, expr=None):
        return ("read", expr)

    def dump(self, _d, expr=None):
        return ("dump", expr)

    def load_(self, kw, expr):
        return ("load", str(kw).lower(), expr)

    def abort(self, _a):
        return ("abort",)

    def fix(self, _f, gen):
        return ("fix", gen, True)

    def unfix(self, _f, gen):
        return ("fix", gen, False)

    def fix_name(self, _f, name):
        return ("fix_name", str(name).lower(), True)

    def unfix_name(self, _f, name):
        return ("fix_name", str(name).lower(), False)

    def histogram(self, tok, gen, expr):
        return ("histogram", gen, expr, str(tok).lower() == "loghistogram")

    def call_stmt(self, name, *args):
        return ("call", str(name).lower(), [a for a in args if a is not None])

    def user_call(self, name, *args):
        return UserCall(str(name), [a for a in args if a is not None])

    def array_ref(self, name, *idx):
        return ArrayRef(str(name), list(idx))

    def string_concat(self, *parts):
        # "a" "b": adjacent literals are one string, as in C and the Evolver
        return N.Str("".join(p.value for p in parts))

    def sprintf_expr(self, _s, *args):
        return Sprintf(list(args))

    def array_lit(self, *items):
        return list(items)

    def assign_array(self, lv, _a, items):
        return ("assign_array", lv, items)

    def compare_eq1(self, a, _op, b):
        return N.Cmp("==", a, b)

    def array_arith(self, lv, op, items):
        # edge_tuber.cmd: evecs[inx] += { jeps*random, ... }
        return self.opassign(lv, op, ArrayLit(items))

    def define_constraint(self, tok):
        return ("define_constraint", str(tok))

    def define_other(self, _d, what, name):
        return ("unsupported", f"define {str(what).lower()}")

    def lv_array(self, name, *idx):
        return ("array", str(name).lower(), list(idx))

    def set_idx(self, _s, base, attr, idx, expr, *rest):
        _, where = self._split_where(rest)
        return ("set", Generator(base, None, where), str(attr).lower(), expr, idx)

    def set_dot(self, _s, var, attr, *rest):
        rest, where = self._split_where(rest)
        idx = rest[0] if len(rest) == 2 else None
        return ("set", Generator(("var", str(var).lower()), None, where), str(attr).lower(),
                rest[-1], idx)

    def define(self, lv, _a, body):
        if lv[0] != "name":
            raise CommandError("only a name can be defined as a command")
        return ("define", lv[1], body)

    def assign(self, lv, _a, expr):
        return ("assign", lv, expr)

    def opassign(self, lv, op, expr):
        return ("opassign", lv, str(op)[0], expr)

    def incr(self, lv, op):
        return ("opassign", lv, str(op)[0], N.Num(1.0))

    def lv_name(self, name):
        return ("name", str(name))

    def lv_attr(self, base, name):
        return ("attr", base, name, None)

    def lv_attr_index(self, base, name, *idx):
        return ("attr", base, name, idx[0] if len(idx) == 1 else list(idx))

    def attr_name(self, tok):
        return str(tok).lower()

    def print_(self, _p, expr):
        return ("print", expr)

    def printf(self, _p, *args):
        return ("printf", list(args), False)

    def errprintf(self, _p, *args):
        return ("printf", list(args), True)

    def list_(self, _l, gen):
        return ("list", gen)

    def where(self, _w, expr):
        return ("where", expr)

    @staticmethod
    def _split_where(rest):
        where = None
        out = []
        for r in rest:
            if isinstance(r, tuple) and r and r[0] == "where":
                where = r[1]
            else:
                out.append(r)
        return out, where

    def set_(self, _s, base, attr, *rest):
        rest, where = self._split_where(rest)
        return ("set", Generator(base, None, where), str(attr).lower(), rest[0] if rest else None)

    def set_var(self, _s, base, var, attr, *rest):
        rest, where = self._split_where(rest)
        return ("set", Generator(base, str(var).lower(), where), str(attr).lower(),
                rest[0] if rest else None)

    def unset(self, _s, base, attr, *rest):
        rest, where = self._split_where(rest)
        return ("unset", Generator(base, None, where), str(attr).lower(), rest[0] if rest else None)

    def refine(self, _r, gen):
        return ("refine", gen)

    def pop_gen(self, _p, gen):
        return ("pop", gen)

    def edgeswap(self, _r, gen):
        return ("edgeswap", gen)

    def equiangulate_gen(self, _e, gen):
        return ("equiangulate", gen)

    def equiangulate_bare(self, _e):
        return ("bare", "u", None)           # a whole sweep, like u

    def delete(self, _r, gen):
        return ("delete", gen)

    def break_(self, _b, n=None):
        return ("break", n)

    def continue_(self, _c, n=None):
        return ("continue", n)

    def return_(self, _r, e=None):
        return ("return", e)

    def bare(self, name):
        return ("bare", str(name), None)

    def bare_arg(self, name, expr):
        return ("bare", str(name), expr)

    def set_background(self, _s, _b, expr):
        # the graphics window's background colour: no effect without graphics
        return ("seq", [])

    def graphics(self, tok):
        return graphics_toggle(tok) or ("seq", [])

    def define_graphics(self, lv, _a, tok):
        if lv[0] != "name":
            raise CommandError("only a name can be defined as a command")
        return ("define", lv[1], graphics_toggle(tok) or ("seq", []))

    def unsupported(self, tok, body=None):
        words = str(tok).split()
        word = words[0].lower()
        if word == "define" and len(words) > 1:
            word = "define " + words[1].lower() + " (at run time)"
        reason = UNSUPPORTED_REASONS.get(word)
        return ("unsupported", word) if reason is None else ("unsupported", word, reason)

    def generator(self, base, *rest):
        var = None
        where = None
        for r in rest:
            if isinstance(r, tuple) and r and r[0] == "where":
                where = r[1]
            elif r is not None:
                var = str(r).lower()
        return Generator(base, var, where)

    def gen_index(self, kind, idx):
        return ("index", _KIND[str(kind).lower()], idx)

    def gen_all(self, kind):
        return ("all", _KIND[str(kind).lower()])

    def gen_sub(self, base, kind, idx=None):
        return ("sub", base, _KIND[str(kind).lower()], idx)

    def gen_var(self, name):
        return ("var", str(name).lower())

    def gen_var_sub(self, name, kind, idx=None):
        return ("varsub", str(name).lower(), _KIND[str(kind).lower()], idx)

    def attr(self, base, name):
        return Attr(base, name)

    def aggregate_juxt(self, op, gen, base, name):
        # `sum(vv.edge eee, eee ecutmark)` means eee.ecutmark (cut.cmd; REF
        # accepts a name and an attribute side by side)
        return Aggregate(str(op), gen, Attr(self.var(base), str(name).lower()))

    def attr_on(self, base, kw, arg):
        # vv.on_constraint 2, ee.on_boundary 1 (REF: no brackets)
        return Attr(base, str(kw).lower(), arg)

    def attr_index(self, base, name, *idx):
        return Attr(base, name, idx[0] if len(idx) == 1 else list(idx))

    def elem_ref(self, kind, idx):
        return ElemIndex(str(kind), idx)

    def aggregate(self, op, gen, expr):
        return Aggregate(str(op), gen, expr)

    def on_test(self, kw, arg):
        return OnTest(str(kw), arg)


_TRANSFORMER = _CmdTransformer()


# `set vertex y y+dy` could read as "set, with loop name y, attribute y to +dy"
# (the grammar's choice); the Evolver means "attribute y to y+dy".  Unless the
# second name is an attribute and the first is not, the value is made to start
# with a number (`0+y+dy`, the same value) so that only that reading parses.
_SET_AMBIG = re.compile(r"\bset(\s+)(vertices|vertex|edges|edge|facets|facet|faces|face|bodies|body)"
                        r"(\s*\[[^\[\]]*\])?(\s+)([a-z_]\w*)(\s+)([a-z_]\w*)(?=\s*[-+])", re.I)


def _disambiguate_set(text):
    def fix(m):
        first, second = m.group(5).lower(), m.group(7).lower()
        if second in SETTABLE_ATTRS and first not in SETTABLE_ATTRS:
            return m.group(0)
        return (m.group(0)[:m.start(7) - m.start(0)] + "0+" + m.group(7))
    return _SET_AMBIG.sub(fix, text)


def parse_command(text, where="<command>", line=1):
    """Parse one complete command; raises :class:`CommandError` with location."""
    if "set" in text.lower():
        text = _disambiguate_set(text)
    try:
        tree = command_parser().parse(text)
        ast = _TRANSFORMER.transform(tree)
    except UnexpectedInput as exc:
        ln = (exc.line if exc.line not in (None, -1) else 1) + line - 1
        col = exc.column if exc.column not in (None, -1) else 1
        snippet = text.split("\n")[(exc.line or 1) - 1] if text else ""
        caret = col
        if len(snippet) > 200:          # a very long line: the part around the column
            lo = max(0, col - 100)
            snippet = ("..." if lo else "") + snippet[lo:col + 100] + \
                ("..." if col + 100 < len(snippet) else "")
            caret = col - lo + (3 if lo else 0)
        tok = getattr(exc, "token", None)
        what = f"unexpected '{clip(tok)}'" if tok is not None and tok.type != "$END" else \
            "unexpected end of command" if tok is not None else "unexpected character"
        raise CommandError(f"{where}:{ln}:{col}: syntax error: {what}\n    {snippet}\n    "
                           + " " * (caret - 1) + "^") from None
    except VisitError as exc:
        if isinstance(exc.orig_exc, PyEvolverError):
            ln = getattr(exc.orig_exc, "line", None)
            col = getattr(exc.orig_exc, "column", None)
            at = f"{line + ln - 1}:{col}" if ln and col else f"{line}"
            raise CommandError(f"{where}:{at}: {exc.orig_exc}") from None
        raise
    if nesting_depth(ast, flat=N.Bin) > MAX_NESTING:
        raise CommandError(f"{where}:{line}: the command is nested more than {MAX_NESTING} "
                           f"levels deep (braces, control statements or expressions)")
    return ast
