"""Parser and interpreter of the Evolver command language (spec §9).

Scripts are data: commands are parsed by ``commands.lark`` into tuples and
expression trees and executed here; nothing reaches Python ``eval``/``exec``
or a shell.
"""
from __future__ import annotations

import contextlib
import functools
import math
import os
import re
import time

import numpy as np
from lark import Lark, v_args
from lark.exceptions import UnexpectedInput, VisitError

from ..atomic import atomic_write
from ..errors import CommandError, ExpressionError, PyEvolverError, UnsupportedError
from ..limits import MAX_ARRAY_ENTRIES, MAX_NESTING, nesting_depth
from ..expr import nodes as N
from ..expr.transform import ExprTransformer, expr_grammar
from .cformat import c_format, print_array, print_value
from .extensions import COMMANDS as EXTENSIONS, run_command

_HERE = os.path.dirname(__file__)


@functools.lru_cache(maxsize=1)
def command_parser():
    with open(os.path.join(_HERE, "commands.lark")) as fh:
        grammar = expr_grammar() + "\n" + fh.read()
    return Lark(grammar, parser="lalr", lexer="contextual", start="start",
                maybe_placeholders=False, cache=True)


# ---------------------------------------------------------------------------
# splitting input into complete commands

_CONT_END = ("+", "-", "*", "/", ",", "=", "&&", "||", "(", "{", "^", "?", ":")


def split_commands(text):
    """Cut text into complete commands: ``[(command_text, first_line), ...]``.

    A command continues on the next line while braces or parentheses are
    open, inside a string or block comment, or after a trailing binary
    operator, comma or ``then``/``else``/``do`` (the Evolver's ``more>``
    prompt).  An unfinished command at the end is returned as the last item.
    """
    chunks, pending = _scan(text)
    return chunks + ([pending] if pending else [])


def needs_more(text):
    """True when ``text`` ends inside an unfinished command."""
    return _scan(text)[1] is not None


def _scan(text):
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    out = []
    buf = []
    depth = 0
    in_str = False
    in_comment = False
    start = None
    opened = False          # the buffered command has had a '{'
    for lineno, line in enumerate(text.split("\n"), 1):
        i = 0
        n = len(line)
        code = []               # the line without its comments
        while i < n:
            c = line[i]
            if in_comment:
                if line.startswith("*/", i):
                    in_comment = False
                    code.append("  ")
                    i += 2
                    continue
                code.append(" ")
                i += 1
                continue
            if in_str:
                code.append(c)
                if c == "\\":
                    code.append(line[i + 1:i + 2])
                    i += 2
                    continue
                if c == '"':
                    in_str = False
                i += 1
                continue
            if c == '"':
                in_str = True
            elif line.startswith("//", i):
                break
            elif line.startswith("/*", i):
                in_comment = True
                code.append("  ")
                i += 2
                continue
            elif c in "{(":
                depth += 1
                if c == "{":
                    opened = True
            elif c in "})":
                depth -= 1
            code.append(c)
            i += 1
        # commands are kept without their comments (blanked, so columns stay)
        code = "".join(code)
        if not code.strip() and not in_str:
            if buf:
                buf.append(code)    # inside an unfinished command
            continue                # blank and comment lines neither start nor end one
        if start is None:
            start = lineno
        spliced = not in_str and code.rstrip().endswith("\\")
        if spliced:                 # backslash-newline: the line goes on (REF's dump writes it)
            k = code.rstrip().rfind("\\")
            code = code[:k] + " " + code[k + 1:]
        buf.append(code)
        tail = code.rstrip()
        if depth > 0 or in_str or in_comment or spliced or tail.endswith(_CONT_END) or \
                _ends_with_keyword(tail):
            continue
        if not opened and not tail.endswith(";") and _PROC_START.match("\n".join(buf)):
            continue        # a procedure/function header waits for its body (or ';')
        out.append(("\n".join(buf), start))
        buf = []
        start = None
        depth = 0
        opened = False
    pending = ("\n".join(buf), start) if buf else None
    # an 'else' at the start of a command belongs to the previous 'if'
    merged = []
    for chunk, ln in out:
        if merged and (_starts_with_else(chunk) or
                       (_WHILE_START.match(chunk) and _DO_OPEN.match(merged[-1][0]))):
            prev, pln = merged[-1]
            merged[-1] = (prev + "\n" + chunk, pln)
        else:
            merged.append((chunk, ln))
    return merged, pending


_KW_END = re.compile(r"(?:^|[^A-Za-z0-9_])(then|else|do)$", re.I)
_ELSE_START = re.compile(r"\s*else\b", re.I)
_WHILE_START = re.compile(r"\s*while\b", re.I)
_DO_OPEN = re.compile(r"\s*do\s*\{.*\}\s*$", re.I | re.S)      # `do { ... }` waiting for `while`
_PROC_START = re.compile(r"(?:\s|/\*.*?\*/|//[^\n]*)*(procedure|function)\b", re.I | re.S)


def _ends_with_keyword(tail):
    return bool(_KW_END.search(tail))


def _starts_with_else(chunk):
    return bool(_ELSE_START.match(chunk))


# ---------------------------------------------------------------------------
# values


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


# ---------------------------------------------------------------------------
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


class ElemIndex(N.Node):
    __slots__ = ("kind", "index")

    def __init__(self, kind, index):
        self.kind = _KIND[kind.lower()]
        self.index = index

    def ev(self, env):
        return env.session.element(self.kind, self.index.ev(env))

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
        return env.session.get_attr(base, self.name, idx)

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
        for el in env.session.generate(self.gen, env):
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
            return env.session.get_attr(el, self.what, _quantity_arg(self.arg, env))
        return env.session.get_attr(el, self.what, self.arg.ev(env))


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
            return env.session.get_attr(env.current(), self.name,
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


# ---------------------------------------------------------------------------
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

    def edgeswap(self, _r, gen):
        return ("edgeswap", gen)

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
        return _graphics_toggle(tok) or ("seq", [])

    def define_graphics(self, lv, _a, tok):
        if lv[0] != "name":
            raise CommandError("only a name can be defined as a command")
        return ("define", lv[1], _graphics_toggle(tok) or ("seq", []))

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
        tok = getattr(exc, "token", None)
        what = f"unexpected '{tok}'" if tok is not None and tok.type != "$END" else \
            "unexpected end of command" if tok is not None else "unexpected character"
        raise CommandError(f"{where}:{ln}:{col}: syntax error: {what}\n    {snippet}\n    "
                           + " " * (col - 1) + "^") from None
    except VisitError as exc:
        if isinstance(exc.orig_exc, PyEvolverError):
            ln = getattr(exc.orig_exc, "line", None)
            col = getattr(exc.orig_exc, "column", None)
            at = f"{line + ln - 1}:{col}" if ln and col else f"{line}"
            raise CommandError(f"{where}:{at}: {exc.orig_exc}") from None
        raise
    if nesting_depth(ast) > MAX_NESTING:
        raise CommandError(f"{where}:{line}: the command is nested more than {MAX_NESTING} "
                           f"levels deep (braces, control statements or expressions)")
    return ast


# ---------------------------------------------------------------------------
# control flow


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


class Env:
    """Name lookup for command expressions."""

    def __init__(self, session):
        self.session = session
        self.frames = []        # [(var name or None, ElemRef)]
        self.scopes = []        # local variables of the running commands: [dict]

    def current(self):
        return self.frames[-1][1] if self.frames else None

    def element(self, el, var):
        env = self

        class _Ctx:
            def __enter__(self_):
                env.frames.append((var, el))

            def __exit__(self_, *a):
                env.frames.pop()
        return _Ctx()

    def lookup(self, name):
        for var, el in reversed(self.frames):
            if var == name:
                return el
        s = self.session
        if self.scopes and name in self.scopes[-1]:
            return self.scopes[-1][name]
        if name in s.variables:
            return s.variables[name]
        if name in s.arrays:
            arr = s.arrays[name]
            if arr.dtype == object:
                raise ExpressionError(f"'{name}' is an array of strings; index it as {name}[i]")
            return N.array_value(arr)           # the whole array as a value
        if self.frames:
            el = self.frames[-1][1]
            try:
                return s.get_attr(el, name, None)
            except ExpressionError:
                pass
        return s.internal(name)


# ---------------------------------------------------------------------------
# the interpreter


def histogram_text(vals, log=False):
    """The ``histogram``/``loghistogram`` report: the Evolver's bins (21 equal
    bins from the least to the greatest value; 20 logarithmic bins over the
    positive values, with a ``<= 0.0`` line counting the others).  NaN
    values are counted on a last line ``NaN  n``, as REF does; with nothing
    else, REF's empty bins (from its initial bounds 1e38 and -1e38, which
    its logarithmic bins print as ``inf``).  Infinities are left out (REF
    stops on them)."""
    nan = sum(1 for v in vals if v != v)
    vals = [v for v in vals if math.isfinite(v)]
    if not vals and not nan:
        return "No qualifying values.\n"
    out = []
    tail = ["NaN          %d" % nan] if nan else []
    if log:
        nonpos = sum(1 for v in vals if v <= 0)
        vals = [v for v in vals if v > 0]
        if nonpos:
            out.append("          <= 0.0           %d" % nonpos)
        if not vals:
            if nan:
                out += ["%10.5g - %10.5g     0" % (math.inf, math.inf)] * 20
            return "\n".join(out + tail) + "\n"
    lo, hi = (min(vals), max(vals)) if vals else (1e38, -1e38)
    if vals and hi <= lo:
        out.append("%10.5g - %10.5g     %d" % (lo, hi, len(vals)))
        return "\n".join(out + tail) + "\n"
    nbins = 20 if log else 21
    if log:
        a, b = np.log(lo), np.log(hi)
        edges = [float(np.exp(a + (b - a) * k / nbins)) for k in range(nbins + 1)]
    else:
        edges = [lo + (hi - lo) * k / nbins for k in range(nbins + 1)]
    # a value on an edge counts in the bin below it (REF: 6 in 5.4286 - 6
    # when the values are 2..14)
    keys = np.searchsorted(np.array(edges[1:]), np.array(vals, dtype=float), side="left")
    counts = np.bincount(np.minimum(keys, nbins - 1), minlength=nbins).tolist()
    for k in range(nbins):
        out.append("%10.5g - %10.5g     %d" % (edges[k], edges[k + 1], counts[k]))
    return "\n".join(out + tail) + "\n"


LETTER_LATER = {
    "g": "g (iteration) comes with the evolve issue",
    "U": "U (conjugate gradient) comes with the evolve issue",
    "m": "m (fixed scale) comes with the evolve issue",
    "o": "o (vertex popping)",
    "G": "G (gravity) comes with the evolve issue",
    "e": "e (extrapolation)", "i": "i (information)", "Q": "Q (quantities)",
    "C": "C (consistency check)", "c": "c (counts)", "N": "N",
    "b": "b (interactive body targets)", "p": "p (ideal gas)", "y": "y (torus duplication)",
    "Z": "Z (zoom)", "M": "M (model order)", "J": "J (jiggle toggle)",
}
WORD_LATER = {
    "saddle", "ritz", "eigenprobe", "lanczos", "hessian_menu",
    "vertex_average", "raw_vertex_average", "rawest_vertex_average",
    "pop",
    "t1_edgeswap", "dissolve", "optimize", "optimise", "lagrange", "quadratic",
    "jiggle", "extrapolate", "counts", "check", "show_vol_later", "detorus", "runge_kutta",
    "conj_grad_later", "fix", "unfix", "burchard", "zoom",
}
TOGGLES = {
    "conj_grad", "check_increase", "autopop", "autochop", "quiet", "quietgo",
    "hessian_normal", "normal_motion", "area_normalization", "effective_area",
    "normal_curvature", "assume_oriented", "autorecalc", "estimate", "volgrads_every",
    "verbose", "ribiere", "approximate_curvature", "rgb_colors", "runge_kutta", "kraynikpopvertex",
    "kraynikpopedge", "hessian_diff", "linear_metric", "post_project", "gravity",
    "keep_macros", "brief", "itdebug", "memdebug", "visibility_test", "clipped",
    "connected", "thicken", "smooth_graph", "pscolorflag", "gridflag", "crossingflag",
    "labelflag", "self_similar", "pinning", "diffusion", "sqgauss", "interp_bdry_param",
    "h_inverse_metric", "jiggle", "break_after_warning", "full_bounding_box",
    "show_all_quantities", "show_inner", "show_outer", "colormap", "bezier_basis",
    "volgrads_every", "zener_drag", "backcull", "debug", "autodisplay",
}
GRAPHICS = {"s", "P", "show", "show_expr", "transform_expr", "geomview",
            "postscript", "showq", "view_transforms", "ps", "oogl", "gv", "screen"}
SETTABLE_ATTRS = {"x", "y", "z", "x1", "x2", "x3", "color", "colour", "frontcolor", "backcolor",
                  "tension", "density", "fixed", "no_refine", "target", "pressure", "volconst",
                  "constraint", "boundary", "opacity"}
UNSUPPORTED_REASONS = {
    "permload": "use replace_load, as the Evolver's manual advises; ::= permanent "
                "variables are not supported either",
    "system": "scripts never run programs", "shell": "scripts never run programs",
    "exec": "scripts never run programs",
    "detorus": "the torus model cannot be unwrapped yet",
    "dissolve": "removing elements one by one is not implemented; delete merges edges",
}
TOGGLE_DEFAULTS = {"hessian_normal": 1, "autorecalc": 1, "ribiere": 1}
# how REF names a toggle in "NAME ON. (was off)" (measured; the others use
# their own name)
TOGGLE_WORDS = {
    "check_increase": "Increase check", "conj_grad": "Conjugate gradient now",
    "ribiere": "Polak-Ribiere conjugate gradient", "gravity": "Gravity",
    "normal_motion": "Normal motion", "area_normalization": "Area normalization",
    "autorecalc": "Autorecalc", "estimate": "Estimation", "volgrads_every": "Volgrads_every",
    "verbose": "Verbose", "rgb_colors": "RGB colors", "runge_kutta": "Runge-Kutta",
    "kraynikpopvertex": "Kraynik pop vertex mode", "kraynikpopedge": "Kraynik pop edge mode",
    "post_project": "Post-projection", "visibility_test": "visibility test",
    "smooth_graph": "smooth graph", "self_similar": "Self similarity mode",
    "pinning": "Constraint pinning", "diffusion": "Diffusion",
    "sqgauss": "Squared Gaussian curvature", "jiggle": "jiggling",
    "break_after_warning": "Break after warning", "show_inner": "show inner",
    "show_outer": "show outer", "memdebug": "Memory debugging", "autodisplay": "Autodisplay",
}

# -- every toggle of the manual (toggle.htm) -------------------------------------
# The rest of the list; REF's synonyms share one state.
TOGGLES |= {
    "ambient_pressure", "approx_curv", "augmented_hessian", "autopop_quartic", "big_endian",
    "little_endian", "blas_flag", "boundary_curvature", "break_on_warning", "bunch_kaufman",
    "bunch_kauffman", "calculate_in_3d", "circular_arc_draw", "clip_view", "clipped_cells",
    "connected_cells", "raw_cells", "conf_edge", "detorus_sticky", "deturck", "dirichlet_mode",
    "sobolev_mode", "facet_colors", "force_deletion", "force_edgeswap",
    "function_quantity_sparse", "gv_binary", "hessian_double_normal", "hessian_normal_one",
    "hessian_normal_perp", "hessian_quiet", "hessian_special_normal", "homothety",
    "immediate_autopop", "interp_normals", "k_altitude_mode", "kusner", "metric_conversion",
    "metric_convert", "old_area", "pop_disjoin", "pop_enjoin", "pop_to_edge", "pop_to_face",
    "ps_cmykflag", "ps_colorflag", "ps_crossingflag", "ps_gridflag", "ps_labelflag",
    "quantities_only", "quietload", "rotate_lights", "septum_flag", "shading", "show_all_edges",
    "show_bounding_box", "slice_view", "sparse_constraints", "squared_gradient",
    "star_finagling", "torus_filled", "transforms", "view_4d",
    "view_transforms_use_unique_point", "ysmp",
}
# synonyms -> the name REF stores the state under
TOGGLE_ALIASES = {
    "approx_curv": "approximate_curvature", "metric_convert": "metric_conversion",
    "clipped_cells": "clipped", "connected_cells": "connected",
    "bunch_kauffman": "bunch_kaufman", "ps_crossingflag": "crossingflag",
    "gridflag": "ps_gridflag", "labelflag": "ps_labelflag", "pscolorflag": "ps_colorflag",
}
# initial states other than off (measured: print NAME after loading); -1 is "unset"
TOGGLE_DEFAULTS.update({
    "detorus_sticky": 1, "facet_colors": 1, "function_quantity_sparse": 1, "hessian_quiet": 1,
    "kraynikpopvertex": 1, "little_endian": 1, "shading": 1, "show_all_edges": 1,
    "show_inner": 1, "show_outer": 1, "sparse_constraints": 1, "transforms": 1, "raw_cells": 1,
    "augmented_hessian": -1, "crossingflag": -1, "ps_crossingflag": -1,
    "ps_colorflag": -1, "pscolorflag": -1, "ps_gridflag": -1, "gridflag": -1,
    "ps_labelflag": -1, "labelflag": -1, "septum_flag": -1,
})
TOGGLE_WORDS.update({
    "approximate_curvature": "approx_curvature", "augmented_hessian": "augmented Hessian",
    "boundary_curvature": "Boundary curvature", "break_on_warning": "Break on warning",
    "bunch_kaufman": "Bunch-Kaufman version of minimal degree",
    "circular_arc_draw": "Circular arc drawing", "conf_edge": "Conformal edge square curvature",
    "facet_colors": "Facet colors", "gv_binary": "Geomview binary mode",
    "k_altitude_mode": "K altitude mode", "kusner": "Edge square curvature",
    "metric_conversion": "Metric conversion", "quietload": "QuietLoad",
    "shading": "Facet shading", "sparse_constraints": "sparse constraints",
    "transforms": "Transform showing", "view_transforms_use_unique_point":
    "view_transforms_use_unique", "dirichlet_mode": "Dirichlet area mode",
    "sobolev_mode": "Sobolev area mode", "ps_gridflag": "ps_gridflag",
    "ps_labelflag": "ps_labelflag", "ps_colorflag": "ps_colorflag",
})
# REF's message when the generic "WORD ON. (was off)" does not fit: (on, off)
# formats with {was} ("on", "off" or "unset"), {WAS} (upper case), {WAS_}
# ("OFF." and a line break, or "ON."), {alg} (ysmp) and {zener} (zener_coeff)
TOGGLE_MESSAGES = {
    "autopop": ("Autopopping ON.\n (was {was})\n", "Autopopping OFF.\n (was {was})\n"),
    "autopop_quartic": ("Autopop quartic mode ON.\n (was {was})\n",
                        "Autopop quartic mode OFF.\n (was {was})\n"),
    "immediate_autopop": ("Immediate autopop mode ON.\n (was {was})\n",
                          "Immediate autopop mode OFF.\n (was {was})\n"),
    "debug": ("YACC debugging was {WAS_}Now ON.\n", "YACC debugging was {WAS_}Now OFF.\n"),
    "itdebug": ("Iteration debugging was {WAS_}Now ON.\n",
                "Iteration debugging was {WAS_}Now OFF.\n"),
    "ysmp": ("Using YSMP. (was {alg})\n", "Using alternate minimal degree. (was {alg})\n"),
    "interp_bdry_param": ("interpolation of boundary parameters  ON. (was {was})\n",
                          "interpolation of boundary parameters OFF (using extrapolation). "
                          "(was {was})\n"),
    "linear_metric": ("Linear interpolation metric with Hessian ON.(was {WAS})\n",
                      "Linear interpolation metric with Hessian OFF.(was {WAS})\n"),
    "quantities_only": ("Using quantities only ON.(was {WAS})\n",
                        "Using quantities only OFF.(was {WAS})\n"),
    "squared_gradient": ("Squared gradient minimization with Hessian ON.(was {WAS})\n",
                         "Squared gradient minimization with Hessian OFF.(was {WAS})\n"),
    "ambient_pressure": ("", "Ambient pressure OFF.\n"),
    "view_4d": ("4D graphics  ON. (was {was})\n", "4D graphics  OFF. (was {was})\n"),
    "zener_drag": ("", "Zener_drag OFF. (was {was})  ({zener})\n"),
}
for _name in ("bezier_basis", "hessian_normal", "hessian_normal_one", "hessian_normal_perp",
              "hessian_quiet", "hessian_double_normal"):      # two spaces before ON
    TOGGLE_MESSAGES[_name] = (_name + "  ON. (was {was})\n", _name + " OFF. (was {was})\n")
# toggles REF switches without a word
TOGGLE_SILENT = {"colormap", "connected", "thicken", "raw_cells", "interp_normals"}
# graphics display of the torus model: one of three modes
TOGGLE_CELLS = ("clipped", "connected", "raw_cells")
# toggles that change numbers in a model pyevolver supports but are not
# implemented: refused when turned on (off is their initial state)
TOGGLE_REFUSED = {
    "ambient_pressure": "the ideal gas model is not implemented",
    "boundary_curvature": "the boundary star rule of the curvature integrals is not "
                          "implemented",
    "conf_edge": "the conformal edge formula of squared curvature is not implemented",
    "kusner": "the edge formula of squared curvature is not implemented",
    "deturck": "unit normal motion is not implemented",
    "dirichlet_mode": "the Dirichlet area Hessian is not implemented",
    "sobolev_mode": "the Sobolev area Hessian is not implemented",
    "homothety": "homothety scaling is not implemented",
    "hessian_special_normal": "HESSIAN_SPECIAL_NORMAL_VECTOR is not supported",
    "hessian_double_normal": "the Hessian normal variants are not implemented",
    "hessian_normal_one": "the Hessian normal variants are not implemented",
    "hessian_normal_perp": "the Hessian normal variants are not implemented",
    "squared_gradient": "squared gradient minimization is not implemented",
    "quantities_only": "switching off the energies other than named quantities is not "
                       "implemented",
    "zener_drag": "Zener drag is not implemented",
    "force_deletion": "delete keeps its checks", "star_finagling": "delete keeps its checks",
    "force_edgeswap": "edgeswap keeps its checks",
    "pop_disjoin": "the pop variants are not implemented",
    "pop_enjoin": "the pop variants are not implemented",
    "pop_to_edge": "the pop variants are not implemented",
    "pop_to_face": "the pop variants are not implemented",
    "septum_flag": "the pop variants are not implemented",
    "k_altitude_mode": "K (skinny triangle refinement) uses the median",
}


def _graphics_toggle(tok):
    """A display word of the command grammar that is also a toggle
    (``transforms off``, ``clipped on``, ``ps_colorflag``): the toggle command,
    or None for a graphics command."""
    words = str(tok).split()
    if not words or words[0].lower() not in TOGGLES or len(words) > 2:
        return None
    if len(words) == 2 and words[1].lower() not in ("on", "off"):
        return None
    arg = N.Var(words[1].lower()) if len(words) == 2 else None
    return ("bare", words[0].lower(), arg)


class Interpreter:
    """Executes parsed commands against a :class:`pyevolver.session.core.Session`."""

    def __init__(self, session):
        self.session = session
        self.env = Env(session)
        self.deadline = None        # time.monotonic() after which the command stops

    def tick(self):
        """Stop the running command when its time limit (``Session.time_limit``,
        the CLI's ``--timeout``) has passed; called once per loop pass, call,
        repetition and iteration, wherever a script could run forever."""
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise TimeLimitExceeded(f"the command ran longer than "
                                    f"{self.session.time_limit:g} s (the time limit) "
                                    f"and was stopped")

    # -- statements -----------------------------------------------------------
    def execute(self, node):
        kind = node[0]
        getattr(self, "_x_" + kind)(node)

    def _x_seq(self, node):
        for st in node[1]:
            self.execute(st)

    def _x_repeat(self, node):
        n = self._count(node[2])
        for _ in range(n):
            self.tick()
            self.execute(node[1])

    def _count(self, expr):
        return max(0, as_int(self.value(expr), "a repetition count"))

    def _x_if(self, node):
        if self.truth(node[1]):
            self.execute(node[2])
        elif node[3] is not None:
            self.execute(node[3])

    def _loop(self, body):
        """Run one loop body; returns False to leave the loop."""
        self.tick()
        try:
            self.execute(body)
        except _Break as b:
            if b.n > 1:
                raise _Break(b.n - 1)
            return False
        except _Continue as c:
            if c.n > 1:
                raise _Continue(c.n - 1)
        return True

    def _x_while(self, node):
        while self.truth(node[1]):
            if not self._loop(node[2]):
                break

    def _x_dowhile(self, node):
        while True:
            if not self._loop(node[1]):
                break
            if not self.truth(node[2]):
                break

    def _x_for(self, node):
        _, init, cond, step, body = node
        if init is not None:
            self.execute(init)
        while self.truth(cond):
            if not self._loop(body):
                break
            if step is not None:
                self.execute(step)

    def _x_foreach(self, node):
        # the elements are listed first (ones created by the body are not
        # visited) but, as in the Evolver, `where` is tested when each element
        # is reached, on the surface the earlier passes left
        gen, body = node[1], node[2]
        sess = self.session
        els = list(sess._gen_base(gen.base, self.env))
        surf0 = sess.surface
        ids = {k: surf0.ids(k) for k in {el.kind for el in els} if k != "body"}
        for el in els:
            if sess.surface is not surf0 and el.kind in ids:
                # the body changed the topology (r, delete, ...): the element is
                # found again by its id; one that was deleted is skipped
                eid = ids[el.kind][el.i]
                hit = np.nonzero(sess.surface.ids(el.kind) == eid)[0]
                if not len(hit):
                    continue
                el = ElemRef(el.kind, int(hit[0]), el.sign)
            elif el.kind == "body" and el.i >= sess.count("body"):
                continue
            with self.env.element(el, gen.var):
                if gen.where is not None:
                    v = gen.where.ev(self.env)
                    if not is_true(v):
                        continue
                if not self._loop(body):
                    break

    def _x_define(self, node):
        name = node[1].lower()
        if len(node[1]) < 2:
            raise CommandError(f"'{node[1]}' is a single-letter command; redefine it with "
                               f"{node[1]} :::= {{ ... }}")
        self._check_free(name, "command")
        if name in self.session.variables:
            del self.session.variables[name]
        self.session.commands[name] = Proc(name, [], node[2])

    def _check_free(self, name, what):
        s = self.session
        from ..session.core import READ_ONLY
        if name in READ_ONLY or name in s.settings or name in TOGGLES or \
                (s.surface is not None and name in s.surface.quantities):
            raise CommandError(f"'{name}' is a built-in name; it cannot be a {what}")

    def _x_procdef(self, node):
        proc = node[1]
        if len(proc.name) < 2:
            raise CommandError(f"'{proc.name}' is a single-letter command, not a "
                               f"{'function' if proc.function else 'procedure'} name")
        self._check_free(proc.name, "function" if proc.function else "procedure")
        old = self.session.commands.get(proc.name)
        if proc.body is None and old is not None and old.body is not None:
            return                      # a prototype after the definition
        self.session.variables.pop(proc.name, None)
        self.session.commands[proc.name] = proc

    def _x_redefine(self, node):
        raw, body = node[1], node[2]
        if len(raw) != 1:
            raise CommandError(f":::= redefines single-letter commands; '{raw}' is not one "
                               f"(use {raw} := {{ ... }})")
        if body is None:
            self.session.letters.pop(raw, None)
        else:
            self.session.letters[raw] = Proc(raw, [], body)

    def _x_local(self, node):
        if not self.env.scopes:
            raise CommandError("'local' is only allowed inside a command body")
        scope = self.env.scopes[-1]
        for name in node[1]:
            if len(name) < 2:
                raise CommandError(f"'{name}' is a single-letter command, not a variable")
            scope.setdefault(name, 0.0)

    # -- procedures -------------------------------------------------------------
    def run_proc(self, proc, args):
        """Run a user command with argument values; returns the value of
        ``return expr`` (functions) or None."""
        if proc.body is None:
            raise CommandError(f"'{proc.name}' is declared but not defined yet")
        if len(args) != len(proc.params):
            raise CommandError(f"{'function' if proc.function else 'procedure'} "
                               f"'{proc.name}' needs {len(proc.params)} argument"
                               f"{'s' if len(proc.params) != 1 else ''}, the call has "
                               f"{len(args)}")
        self.tick()
        if len(self.env.scopes) > MAX_NESTING:
            raise CommandError(f"'{proc.name}': calls nested more than {MAX_NESTING} deep")
        scope = {name: v for (_, name), v in zip(proc.params, args)}
        self.env.scopes.append(scope)
        try:
            self.execute(proc.body)
        except _Return as r:
            return r.value
        except (_Break, _Continue):
            return None
        finally:
            self.env.scopes.pop()
        return None

    def call_in_expr(self, name, arg_nodes):
        s = self.session
        if name == "sizeof":
            if len(arg_nodes) != 1:
                raise ExpressionError("sizeof() takes one argument")
            a = arg_nodes[0]
            if isinstance(a, N.Var) and a.name in s.arrays:
                return float(s.arrays[a.name].size)
            v = self.value(a)
            if not isinstance(v, str):
                raise ExpressionError("sizeof() needs a string or an array")
            return float(len(v))
        if name == "is_defined":
            if len(arg_nodes) != 1:
                raise ExpressionError("is_defined() takes one argument")
            v = self.value(arg_nodes[0])
            if not isinstance(v, str):
                raise ExpressionError("is_defined() needs a name in a string")
            return float(self.is_defined(v.lower()))
        if name in ("valid_constraint", "valid_boundary"):
            # 1 if the constraint / boundary (a number, or a name) is defined
            if len(arg_nodes) != 1:
                raise ExpressionError(f"{name}() takes one argument")
            v = self.value(arg_nodes[0])
            if isinstance(v, str) or not math.isfinite(float(v)):
                raise ExpressionError(f"{name}() needs a number or a name")
            table = (s.surface.constraints if name == "valid_constraint"
                     else s.surface.boundaries) if s.surface is not None else {}
            return float(float(v) == int(v) and int(v) in table)
        if name in ("new_vertex", "new_edge", "new_facet", "new_body"):
            raise UnsupportedError(f"{name}() (creating elements from a script)")
        if name == "valid_element":
            # 1 if the element exists (simply_connected.cmd: vertex[sc_startv])
            if len(arg_nodes) != 1 or not isinstance(arg_nodes[0], ElemIndex):
                raise ExpressionError("valid_element() takes one element, e.g. vertex[3]")
            try:
                arg_nodes[0].ev(self.env)
            except ExpressionError:
                return 0.0
            return 1.0
        proc = s.commands.get(name)
        if proc is None:
            raise ExpressionError(f"unknown function '{name}'")
        args = [self.value(a) for a in arg_nodes]
        v = self.run_proc(proc, args)
        if not proc.function:
            raise ExpressionError(f"'{name}' is a procedure; it has no value")
        if v is None:
            raise ExpressionError(f"function '{name}' ended without 'return value'")
        return v

    def is_defined(self, name):
        s = self.session
        if name in s.commands or name in s.variables or name in s.arrays or \
                (self.env.scopes and name in self.env.scopes[-1]):
            return True
        try:
            s.internal(name)
            return True
        except PyEvolverError:
            return False

    def _x_call(self, node):
        name, args = node[1], node[2]
        proc = self.session.commands.get(name)
        if proc is None:
            if len(args) == 1 and name in ("g", "r", "u"):
                return self._x_bare(("bare", name, args[0]))
            if name.lower() in EXTENSIONS:
                return run_command(self.session, name, [self.value(a) for a in args])
            raise CommandError(f"unknown procedure '{name}'")
        self.run_proc(proc, [self.value(a) for a in args])

    # -- arrays ----------------------------------------------------------------
    def _x_define_array(self, node):
        _, name, typ, dims = node
        s = self.session
        if len(name) < 2:
            raise CommandError(f"'{name}' is a single-letter command, not a variable")
        shape = self._sizes(dims, f"define {name}")
        if not shape:                       # `define name real`: a plain variable
            if name not in s.variables:
                s.set_variable(name, "" if typ == "string" else 0.0)
            return
        if self.env.scopes and name in self.env.scopes[-1]:
            # `local vn; define vn real[3]`: the name is the array from here on
            # (pyevolver keeps arrays in one namespace)
            del self.env.scopes[-1][name]
        old = s.arrays.get(name)
        new = np.zeros(shape, dtype=object if typ == "string" else float)
        if typ == "string":
            new[...] = ""
        if old is not None and old.ndim == new.ndim and old.dtype == new.dtype:
            # redefining keeps the values (of the same type)
            sl = tuple(slice(0, min(a, b)) for a, b in zip(old.shape, new.shape))
            new[sl] = old[sl]
        s.arrays[name] = new
        s.array_types[name] = typ

    def array_slot(self, name, idx, partial=False):
        """``(array, position)`` of ``name[idx...]``; with ``partial`` fewer
        indices than dimensions name a sub-array (``evecs[2]`` of a
        ``real[20][3]``)."""
        s = self.session
        arr = s.arrays.get(name)
        if arr is None:
            raise ExpressionError(f"'{name}' is not an array (define it first: "
                                  f"define {name} real[n])")
        if len(idx) != arr.ndim and not (partial and 0 < len(idx) < arr.ndim):
            raise ExpressionError(f"array '{name}' has {arr.ndim} dimension"
                                  f"{'s' if arr.ndim != 1 else ''}, got {len(idx)} indices")
        pos = []
        for k, n in zip(idx, arr.shape):
            k = as_int(k, f"an index of array '{name}'")
            if k < 1 or k > n:
                raise ExpressionError(f"array '{name}': index {k} is outside 1..{n}")
            pos.append(k - 1)
        return arr, tuple(pos)

    def _sizes(self, dims, what, per=1):
        """Array sizes from ``dims`` expressions: integers >= 0 whose product
        (times ``per`` elements) stays within :data:`~pyevolver.limits.MAX_ARRAY_ENTRIES`."""
        shape = []
        total = per
        for d in dims:
            v = self.value(d)
            if isinstance(v, str) or not (0 <= v < float("inf")):
                raise CommandError(f"{what}: array sizes must be numbers >= 0")
            shape.append(int(v))
            total *= int(v)
        # (real[0][huge] and real[huge][0] have no entries, but numpy
        # cannot make the huge dimension)
        total = max([total] + shape)
        if total > MAX_ARRAY_ENTRIES:
            raise CommandError(f"{what}: {total} entries is more than the "
                               f"{MAX_ARRAY_ENTRIES} allowed")
        return shape

    def _x_define_attr(self, node):
        _, kind, name, typ, dims = node
        n = self.session.count(kind) if kind != "facetedge" else 1
        shape = self._sizes(dims, f"define {kind} attribute {name}", per=max(n, 1))
        self.session.define_attribute(kind, name, typ, shape)

    def _x_assign(self, node):
        self._store(node[1], self.value(node[2]))

    def _x_opassign(self, node):
        lv, op, expr = node[1], node[2], node[3]
        old = self._load(lv)
        v = self.value(expr)
        if isinstance(old, str) or isinstance(v, str):
            raise CommandError(f"'{op}=' needs numbers")
        if op == "/" and not isinstance(v, np.ndarray) and v == 0:
            raise ExpressionError("Division by zero.")
        if op == "*" and isinstance(old, N.ArrayValue) and isinstance(v, N.ArrayValue):
            raise CommandError("'*=' of two arrays: use a := a * b for the dot product")
        new = {"+": lambda: old + v, "-": lambda: old - v, "*": lambda: old * v,
               "/": lambda: old / v}[op]()
        self._store(lv, new)

    def _load(self, lv):
        if lv[0] == "name":
            return self.env.lookup(lv[1].lower())
        if lv[0] == "array":
            arr, pos = self.array_slot(lv[1], [self.value(i) for i in lv[2]], partial=True)
            v = arr[pos]
            return N.array_value(v) if np.ndim(v) else v
        base = lv[1].ev(self.env)
        return self.session.get_attr(base, lv[2], self._index(lv[3]))

    def _store(self, lv, value):
        s = self.session
        if lv[0] == "name":
            name = lv[1].lower()
            if len(lv[1]) < 2:
                raise CommandError(f"'{lv[1]}' is a single-letter command, not a variable "
                                   f"(variable names need two or more characters)")
            for var, el in self.env.frames:
                if var == name:
                    raise CommandError(f"cannot assign to loop variable '{name}'")
            if self.env.scopes and name in self.env.scopes[-1]:
                self.env.scopes[-1][name] = value
                return
            if name in s.commands:
                del s.commands[name]
            if name in s.arrays:
                self._fill(name, s.arrays[name], (), value)
                return
            if isinstance(value, N.ArrayValue):
                raise CommandError(f"'{name}' is not an array; define it first "
                                   f"(define {name} real" +
                                   "".join(f"[{n}]" for n in value.shape) + ")")
            s.set_variable(name, value)
            return
        if lv[0] == "array":
            arr, pos = self.array_slot(lv[1], [self.value(i) for i in lv[2]], partial=True)
            if len(pos) < arr.ndim:
                self._fill(lv[1], arr, pos, value)
            elif isinstance(value, N.ArrayValue):
                raise CommandError(f"{lv[1]}[...]: an array does not fit in one entry")
            elif arr.dtype == object:
                arr[pos] = value if isinstance(value, str) else print_value(value).strip()
            elif isinstance(value, str):
                raise CommandError(f"array '{lv[1]}' holds numbers, not strings")
            else:
                arr[pos] = value
            return
        base = lv[1].ev(self.env)
        s.set_attr(base, lv[2], self._index(lv[3]), value)

    @staticmethod
    def _fill(name, arr, pos, value):
        """Assign a number (to every entry) or an array of the same shape to
        the (sub-)array ``arr[pos]``."""
        if isinstance(value, str) or arr.dtype == object:
            raise CommandError(f"array '{name}': whole-array assignment needs numbers")
        target = arr[pos] if pos else arr
        if isinstance(value, N.ArrayValue) and value.shape != target.shape:
            raise CommandError(f"array '{name}': cannot assign shape {list(value.shape)} "
                               f"to shape {list(target.shape)}")
        if pos:
            arr[pos] = np.asarray(value)
        else:
            arr[...] = np.asarray(value)

    def _index(self, idx):
        if idx is None:
            return None
        if isinstance(idx, list):
            return tuple(self.value(i) for i in idx)
        return self.value(idx)

    def _x_assign_array(self, node):
        lv, items = node[1], node[2]
        if lv[0] != "name":
            raise CommandError("a {...} list can only be assigned to an array name")
        name = lv[1].lower()

        def shape(x):
            return [len(x)] + shape(x[0]) if isinstance(x, list) else []

        def flat(x):
            if isinstance(x, list):
                return [v for it in x for v in flat(it)]
            return [as_float(self.value(x), f"a value of array {name}")]
        vals = flat(items)
        s = self.session
        arr = s.arrays.get(name)
        if arr is None:
            dims = "".join(f"[{n}]" for n in shape(items))
            raise CommandError(f"'{name}' is not an array; define it first "
                               f"(define {name} real{dims})")
        if arr.dtype == object:
            raise CommandError(f"array '{name}' holds strings")
        flat_arr = arr.reshape(-1)
        if len(vals) > flat_arr.size:
            raise CommandError(f"array '{name}' has {flat_arr.size} entries; the list has "
                               f"{len(vals)}")
        flat_arr[:len(vals)] = vals

    def _x_print(self, node):
        e = node[1]
        if isinstance(e, N.Var) and e.name in self.session.arrays and \
                not (self.env.scopes and e.name in self.env.scopes[-1]):
            self.session.write(print_array(self.session.arrays[e.name]) + "\n")
            return
        v = self.value(e)
        if isinstance(v, N.ArrayValue):
            self.session.write(print_array(np.asarray(v)) + "\n")
            return
        self.session.write(print_value(v) + "\n")

    def _x_printf(self, node):
        args = [self.value(a) for a in node[1]]
        if not args or not isinstance(args[0], str):
            raise CommandError("printf needs a format string first")
        # REF prints a lone format string as it is ("%%" stays "%%": xray.cmd)
        if len(args) == 1 and "%" in args[0].replace("%%", ""):
            raise CommandError(f"{'ERR' if node[2] else ''}PRINTF string has formats, but "
                               "there are no arguments.")          # REF's ERROR 1928
        text = c_format(args[0], args[1:]) if len(args) > 1 else args[0]
        if node[2]:
            self.session.write_err(text)
        else:
            self.session.write(text)

    def _var_elem(self, name):
        for var, el in reversed(self.env.frames):
            if var == name:
                return el
        return None

    def _x_list(self, node):
        gen = node[1]
        if gen.base[0] == "var" and self._var_elem(gen.base[1]) is None:
            what = gen.base[1]
            if what in ("topinfo", "bottominfo", "procedures", "attributes", "quantities",
                        "method_instances", "constraints", "boundaries"):
                raise UnsupportedError(f"list {what}")
            raise CommandError(f"list: '{what}' is not an element (expected for example "
                               f"list vertex[3] or list facets where area > 0.1)")
        self.session.list_elements(node[1], self.env)

    def _quantity_gen(self, gen):
        """The quantity or method instance a ``set``/``unset`` names, if any."""
        s = self.session.surface
        if gen.base[0] == "var" and s is not None and gen.base[1] in s.quantities \
                and self._var_elem(gen.base[1]) is None:
            return gen.base[1]
        return None

    def _x_set(self, node):
        idx = node[4] if len(node) > 4 else None
        if node[1].base == ("var", "quantity") and self._var_elem("quantity") is None:
            raise CommandError("set quantity NAME ...: write set NAME target value (the "
                               "Evolver reads 'set quantity' as a syntax error)")
        qname = self._quantity_gen(node[1])
        if qname is not None:
            from .attributes import set_quantity
            if node[1].where is not None or node[1].var is not None or idx is not None:
                raise CommandError(f"set {qname}: expected set {qname} attribute [value]")
            value = None if node[3] is None else self.value(node[3])
            set_quantity(self.session, qname, node[2], value)
            return
        self.session.set_elements(node[1], node[2], node[3], self.env, unset=False, idx=idx)

    def _x_fix(self, node):
        gen, on = node[1], node[2]
        s = self.session
        if gen.base[0] == "var" and gen.where is None and \
                not isinstance(self._var_elem(gen.base[1]), ElemRef):
            s.fix_name(gen.base[1], on)
            return
        els = s.generate(gen, self.env)
        n = s.fix_elements(els, on)
        # REF reports the elements fixed and unfixed by a whole command at
        # its end ("Fixed: N" then "Unfixed: M", nonzero counts only)
        s.report("Fixed" if on else "Unfixed", n)

    def _x_fix_name(self, node):
        self.session.fix_name(node[1], node[2])

    def _x_histogram(self, node):
        gen, expr, log = node[1], node[2], node[3]
        vals = []
        for el in self.session.generate(gen, self.env):
            with self.env.element(el, gen.var):
                v = self.value(expr)
            vals.append(as_float(v, "a histogram value"))
        self.session.write(histogram_text(vals, log))

    # -- files --------------------------------------------------------------------
    def _x_redirect(self, node):
        _, body, op, target = node
        name = self.value(target)
        if not isinstance(name, str) or not name:
            raise CommandError(f"'{op}' needs a file name in quotes (for example: "
                               f"do_off {op} \"out.off\")")
        s = self.session
        # the file changes only when the command completes (atomic_write): a
        # failing or interrupted command leaves it as it was
        with contextlib.ExitStack() as stack:
            try:
                fh = stack.enter_context(atomic_write(name, "w" if op == ">>>" else "a",
                                                      durable=False, encoding="latin-1",
                                                      newline=""))
            except OSError as exc:
                raise CommandError(f"cannot open '{name}' for output: "
                                   f"{exc.strerror or exc}") from None
            old = s.out
            s.out = fh
            flow = None
            try:
                self.execute(body)
            except (_Break, _Continue, _Return, Loaded, Quit) as exc:
                flow = exc              # normal control flow: the output is kept
            finally:
                s.out = old
        if flow is not None:
            raise flow

    def _x_pipe(self, node):
        raise UnsupportedError("piping output to a command ('|')",
                               "scripts never reach a shell; use >> or >>> to write a file")

    def _x_read(self, node):
        if node[1] is None:
            raise UnsupportedError("read without a file name", "use read \"file\"")
        name = self.value(node[1])
        if not isinstance(name, str):
            raise CommandError("read needs a file name in quotes (for example: read \"off.cmd\")")
        self.session.read_file(name)

    def _x_dump(self, node):
        name = None
        if node[1] is not None:
            name = self.value(node[1])
            if not isinstance(name, str):
                raise CommandError("dump needs a file name in quotes (for example: "
                                   "dump \"out.fe\")")
        self.session.dump(name)

    def _x_load(self, node):
        kw = node[1]
        name = self.value(node[2])
        if not isinstance(name, str):
            raise CommandError(f"{kw} needs a datafile name in quotes (for example: "
                               f"{kw} \"cube.fe\")")
        if kw == "load":
            self.session.load_command(name)
            raise Loaded()              # the Evolver: the current command ends
        elif kw == "addload":
            self.session.addload(name)
        else:
            self.session.replace_load(name)

    def _x_abort(self, node):
        raise CommandError("Command aborted (abort).")

    def _x_unset(self, node):
        qname = self._quantity_gen(node[1])
        if qname is not None:
            raise CommandError(f"unset {qname}: a quantity is not an element (REF: syntax "
                               f"error); use unfix {qname} or set {qname} info_only")
        self.session.set_elements(node[1], node[2], node[3], self.env, unset=True)

    def _x_refine(self, node):
        s = self.session
        els = s.generate(node[1], self.env)
        kinds = {el.kind for el in els}
        if kinds - {"edge", "facet"}:
            raise UnsupportedError("refine of " + ", ".join(sorted(kinds - {"edge", "facet"}))
                                   + "s", "'refine edges' and 'refine facets' are supported")
        if kinds == {"facet"}:
            s.refine_facets([el.i for el in els])
        else:
            s.refine_edges([el.i for el in els])

    def _x_edgeswap(self, node):
        s = self.session
        els = s.generate(node[1], self.env)
        if {el.kind for el in els} - {"edge"}:
            raise CommandError("edgeswap needs edges (for example: edgeswap edge[3])")
        s.edgeswap([el.i for el in els])

    def _x_delete(self, node):
        s = self.session
        gen = node[1]
        if gen.kind not in ("edge", "facet"):
            raise CommandError("delete needs edges or facets (for example: "
                               "delete edges where length < 0.01)")
        n = 0
        if gen.where is None or gen.base[0] != "all":
            n = s.delete_elements(gen.kind, [el.i for el in s.generate(gen, self.env)])
        else:
            # `delete edges where cond`: like the Evolver, visit the elements
            # in id order and test cond when each is reached, on the surface
            # the earlier deletions left (a merge can make a later edge short)
            for eid in s.surface.ids(gen.kind).tolist():
                hit = np.nonzero(s.surface.ids(gen.kind) == eid)[0]
                if not len(hit):
                    continue
                el = ElemRef(gen.kind, int(hit[0]))
                with self.env.element(el, gen.var):
                    v = gen.where.ev(self.env)
                if is_true(v):
                    n += s.delete_elements(gen.kind, [el.i])
        s.report(f"{'Edges' if gen.kind == 'edge' else 'Facets'} deleted", n)

    def _x_break(self, node):
        raise _Break(1 if node[1] is None else as_int(self.value(node[1]), "break's count"))

    def _x_continue(self, node):
        raise _Continue(1 if node[1] is None else as_int(self.value(node[1]),
                                                         "continue's count"))

    def _x_return(self, node):
        raise _Return(None if node[1] is None else self.value(node[1]))

    def _x_define_constraint(self, node):
        self.session.define_constraint(node[1])

    def _x_unsupported(self, node):
        raise UnsupportedError(*node[1:])

    def _x_bare(self, node):
        raw, arg = node[1], node[2]
        name = raw.lower()
        s = self.session
        builtin = len(node) > 3
        if name in s.commands and len(raw) > 1:
            proc = s.commands[name]
            if proc.params:
                if arg is None:
                    raise CommandError(f"'{raw}' needs {len(proc.params)} argument"
                                       f"{'s' if len(proc.params) != 1 else ''}: "
                                       f"{raw}(...)")
                self.run_proc(proc, [self.value(arg)])
                return
            n = 1 if arg is None else self._count(arg)
            for _ in range(n):
                self.tick()
                self.run_proc(proc, [])
            return
        if not builtin and raw in s.letters:
            n = 1 if arg is None else self._count(arg)
            for _ in range(n):
                self.tick()
                self.run_proc(s.letters[raw], [])
            return
        if name in EXTENSIONS and len(raw) > 1:
            return run_command(s, name, [] if arg is None else [self.value(arg)])
        if raw in ("q",) or name in ("quit", "bye", "exit"):
            raise Quit(0 if arg is None else as_int(self.value(arg), "the exit status") & 255)
        if raw == "v" or name == "show_vol":
            s.note(s.show_vol())
            return
        if name == "recalc":
            s.recalc(reposition=True)
            return
        if name == "history" and arg is None:
            s.show_history()
            return
        if raw in GRAPHICS or name in GRAPHICS:
            return
        if name in TOGGLES:
            self._toggle(name, arg)
            return
        if name == "linear":
            return        # a no-op on a linear surface, as in REF
        if name == "convert_to_quantities" and arg is None:
            # REF's dump writes it in the read section of files that used
            # named-quantity energies; pyevolver computes the same numbers
            # either way, so only the message is kept
            # REF converts at load a surface whose boundaries carry integrals
            bnd = getattr(s.surface, "boundaries", None) or {}
            if s.toggles.get("_all_quantities") or any(
                    b.energy or b.content for b in bnd.values()):
                s.note("Everything already quantities.\n")
            else:
                s.toggles["_all_quantities"] = 1
                s.note("Converting to all named quantities...Done.\n")
            return
        if raw == "g" or re.fullmatch(r"g\d+", raw):
            n = int(raw[1:]) if len(raw) > 1 else (1 if arg is None else self._count(arg))
            s.go(n)
            return
        if raw == "m":
            if arg is None:
                raise CommandError("m needs a scale value (for example: m 0.1)")
            v = as_float(self.value(arg), f"the argument of {raw}")
            s.settings["scale"] = v
            s.toggles["_fixed_scale"] = 1
            s.note("Scale fixed at %g.\n" % v)
            return
        if name in ("optimize", "optimise"):
            if arg is not None:
                s.settings["scale_limit"] = as_float(self.value(arg), f"the argument of {raw}")
            s.toggles["_fixed_scale"] = 0
            s.note("Scale optimizing with bound %g.\n" % s.settings["scale_limit"])
            return
        if raw == "r":
            for _ in range(1 if arg is None else self._count(arg)):
                self.tick()
                s.refine()
            return
        if raw == "j":
            s.jiggle(None if arg is None else as_float(self.value(arg), f"the argument of {raw}"))
            return
        if raw in ("t", "w") or name in ("edgeweed", "areaweed"):
            if arg is None:
                raise CommandError(f"{raw} needs a value (for example: {raw} 0.01)")
            v = as_float(self.value(arg), f"the argument of {raw}")
            if raw == "t" or name == "edgeweed":
                s.delete_short_edges(v)
            else:
                s.weed(v)
            return
        if raw in ("l", "K", "n") or name in ("edge_divide", "notch"):
            if arg is None:
                raise CommandError(f"{raw} needs a value (for example: {raw} 0.3)")
            v = as_float(self.value(arg), f"the argument of {raw}")
            if raw == "l" or name == "edge_divide":
                s.edge_divide_long(v)
            elif raw == "K":
                s.skinny(v)
            else:
                s.notch(v)
            return
        if raw == "V" or name in ("rawv", "rawestv"):
            s.vertex_average({"V": "V", "rawv": "raw", "rawestv": "rawest"}[raw])
            return
        if raw == "O":
            s.pop_edges()
            return
        if raw == "u" or name == "equiangulate":
            s.equiangulate()
            return
        if name == "bfgs":
            s.bfgs(1 if arg is None else self._count(arg))
            return
        if name == "newton":
            s.newton(1 if arg is None else self._count(arg))
            return
        if name in ("hessian", "hessian_seek"):
            if name == "hessian_seek" and arg is not None:
                s.hessian(seek=True, max_scale=as_float(self.value(arg), f"the argument of {raw}"))
            else:
                s.hessian(seek=name == "hessian_seek")
            return
        if raw == "U":
            old = s.toggles.get("conj_grad", 0)
            s.toggles["conj_grad"] = 0 if old else 1
            s.reset_cg()
            s.note(f"Conjugate gradient now {'OFF' if old else 'ON'}. (was {'on' if old else 'off'})\n")
            return
        if raw == "G":
            old_on = s.toggles.get("gravity", 0)
            if arg is not None:
                s.surface.gravity_constant = as_float(self.value(arg), f"the argument of {raw}")
            g = s.surface.gravity_constant
            s.toggles["gravity"] = int(g != 0)
            was = "on" if old_on else "off"
            if g != 0:
                s.note(f"Gravity is now ON with gravitational constant {g:g}. (was {was})\n")
            else:
                s.note(f"Gravity is now OFF. (was {was})\n")
            s.recalc()
            return
        if len(raw) == 1 and raw in LETTER_LATER:
            raise UnsupportedError(f"command {LETTER_LATER[raw]}")
        if name in WORD_LATER:
            raise UnsupportedError(f"command {name}")
        if name in s.variables and arg is None:
            raise CommandError(f"'{raw}' is a variable, not a command (use print {raw})")
        raise CommandError(f"unknown command '{raw}'")

    def _toggle(self, name, arg):
        s = self.session
        if name in ("conj_grad", "ribiere"):      # both erase the CG history (REF)
            s.reset_cg()
        if arg is None:
            new = 1
        elif isinstance(arg, N.Var) and arg.name in ("on", "off"):
            new = 1 if arg.name == "on" else 0
        else:
            v = self.value(arg)
            new = (1 if v else 0) if isinstance(v, str) else int(is_true(v, "a toggle value"))
        key = TOGGLE_ALIASES.get(name, name)
        names = [key] + [a for a, k in TOGGLE_ALIASES.items() if k == key]
        default = TOGGLE_DEFAULTS.get(key, 0)
        if key == "show_all_edges" and s.surface is not None and s.surface.string:
            default = 0                         # REF: off in the string model
        old = s.toggles.get(key, default)
        if name == "autopop" and new:
            raise UnsupportedError("autopop", "vertex and edge popping (o, O) is not implemented")
        if key in TOGGLE_REFUSED and new:
            raise UnsupportedError(f"{name} on", TOGGLE_REFUSED[key])
        surf = s.surface
        torus = surf is not None and surf.periods is not None
        if key == "blas_flag":                   # REF's build has no BLAS either
            s.write_err("WARNING 2472: This Evolver not compiled with BLAS.\n")
            return
        if key == "torus_filled":
            if not torus:
                s.write_err("WARNING 2042: torus_filled is invalid toggle because not in "
                            "torus model.\n")
                return
            if new != old:
                raise UnsupportedError(f"torus_filled {'on' if new else 'off'} at run time",
                                       "the torus_filled model is fixed by the datafile")
        if key == "calculate_in_3d" and new and surf is not None and surf.sdim > 3:
            raise UnsupportedError("calculate_in_3d on", "curvature in the first three "
                                   "coordinates is not implemented")
        for n in names:
            s.toggles[n] = new
        if key == "effective_area":          # the command also changes REF's motion
            s.toggles["_effective_area_motion"] = new
        if key in TOGGLE_CELLS:                  # one display mode of three
            for other in TOGGLE_CELLS:
                if other != key:
                    for n in [other] + [a for a, k in TOGGLE_ALIASES.items() if k == other]:
                        s.toggles[n] = 0
            if key == "clipped" and not torus:
                s.write_err("WARNING 1254: CLIPPED mode has no effect since torus model not "
                            "used.\n")
            return
        if key == "big_endian" and new:
            s.toggles["little_endian"] = 0
        elif key == "little_endian" and new:
            s.toggles["big_endian"] = 0
        was = {1: "on", 0: "off"}.get(old, "unset")
        now = "ON" if new else "OFF"
        if key in TOGGLE_SILENT:
            pass
        elif key == "quietgo":               # REF prints this one even when quiet
            s.write(f"QuietGo {now}. (was {was})\n")
        elif key == "quiet":
            if not new:                     # turning it on is silent
                s.write(f"Quiet OFF. (was {was})\n")
        elif key == "autochop":
            if new:
                s.note(f"Autochopping ON. Chop length {s.settings.get('autochop_length', 0.0):g}"
                       f"  (was {was})\n"
                       "Set autochop length with  AUTOCHOP_LENGTH := value\n")
            else:
                s.note(f"Autochopping OFF. (was {was})\n")
        elif key in TOGGLE_MESSAGES:
            fmt = TOGGLE_MESSAGES[key][0 if new else 1]
            zc = s.variables.get("zener_coeff")
            if key == "ysmp" and new == old:      # REF says nothing then
                fmt = ""
            s.note(fmt.format(was=was, WAS=was.upper(),
                              WAS_="OFF.\n" if old == 0 else was.upper() + ".",
                              alg="YSMP" if old else "alt min deg",
                              zener="zener_coeff not set" if zc is None else
                              f"zener_coeff: {zc:g}" if isinstance(zc, (int, float))
                              else "zener_coeff"))
        else:
            word = TOGGLE_WORDS.get(key, key)
            s.note(f"{word} {now}. (was {was})\n")
        if key == "sparse_constraints" and not new:     # REF settles an unset one too
            old_aug = s.toggles.get("augmented_hessian", TOGGLE_DEFAULTS["augmented_hessian"])
            if old_aug == -1:
                s.toggles["augmented_hessian"] = 0
                s.note("augmented Hessian OFF. (was unset)\n")
        if key == "gravity":
            s.recalc()

    # -- expressions ------------------------------------------------------------
    def value(self, expr):
        v = expr.ev(self.env)
        if isinstance(v, N.ArrayValue):
            return v
        if isinstance(v, np.ndarray):
            if v.size != 1:
                raise CommandError(f"expected a number here, got an array of shape "
                                   f"{list(v.shape)}")
            v = float(v.reshape(()))
        if isinstance(v, (ElemRef, QRef)):
            raise CommandError("an element or quantity is not a value here")
        return v

    def truth(self, expr):
        v = self.value(expr)
        if isinstance(v, str):
            return bool(v)
        if isinstance(v, np.ndarray):
            raise ExpressionError(f"a condition must be a number, got {N._what(v)}")
        return v != 0
