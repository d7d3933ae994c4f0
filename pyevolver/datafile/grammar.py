"""The datafile grammars and their transformers.

``fe_top.lark`` (the top section) and ``fe_elements.lark`` (one element line),
each with the shared expression grammar ``expr.lark``, parsed LALR; the
transformers turn the trees into declaration tuples and element items.
"""
from __future__ import annotations

import functools
import os

from lark import Lark, Token, v_args

from ..expr import nodes as N
from ..errors import ExpressionError
from ..expr.lark_cache import cached_lark
from ..expr.transform import ExprTransformer, _at, expr_grammar
from ..limits import clip
from .located import _Unsupported

_HERE = os.path.dirname(__file__)


def _refuse(tok):
    raise _Unsupported(tok)


@functools.lru_cache(maxsize=1)
def top_parser() -> Lark:
    """LALR parser of the top section (``fe_top.lark`` + ``expr.lark``)."""
    with open(os.path.join(_HERE, "fe_top.lark")) as fh:
        grammar = expr_grammar() + "\n" + fh.read()
    return cached_lark(grammar, parser="lalr", lexer="contextual", start="start",
                       maybe_placeholders=False, lexer_callbacks={"UNSUPPORTED_KW": _refuse,
                                                           "UNSUPPORTED2_KW": _refuse})


@functools.lru_cache(maxsize=1)
def line_parser() -> Lark:
    """LALR parser of one element line (``fe_elements.lark`` + ``expr.lark``)."""
    with open(os.path.join(_HERE, "fe_elements.lark")) as fh:
        grammar = expr_grammar() + "\n" + fh.read()
    return cached_lark(grammar, parser="lalr", lexer="contextual",
                       start=["vertex_line", "edge_line", "face_line", "body_line"],
                       maybe_placeholders=False)



_ETYPE = {"vertices": "vertex", "edges": "edge", "facets": "facet", "face": "facet",
          "faces": "facet", "bodies": "body"}


def _int(tok):
    """An integer token (an id, a count): a located error when it has more
    digits than any id may (Python refuses to convert past 4,300 digits)."""
    s = str(tok)
    if len(s.lstrip("+-0")) > 18:
        raise _at(ExpressionError(f"the number {clip(s, 30)} is too large here "
                                  f"(ids and counts are below 2^31)"), tok)
    return int(s)


def _cid(tok):
    """A constraint's or boundary's number, or its name (lower case)."""
    s = str(tok)
    return _int(tok) if s.isdigit() else s.lower()


@v_args(inline=True)
class _TopTransformer(ExprTransformer):
    """Top-section declarations -> tuples consumed by :func:`_fill_scene`."""

    def start(self, *decls):
        return list(decls)

    def parameter(self, kw, name, value, *tail):
        d = ("parameter", str(name).lower(), value, kw.line)
        if not tail and not str(kw).lower().startswith("optimi"):
            return d
        return d + ({"optimizing": str(kw).lower().startswith("optimi"),
                     "column": kw.column, **dict(tail)},)

    def p_delta(self, kw, e):
        return ("pdelta", (e, kw.column))

    def p_scale(self, kw, e):
        return ("pscale", (e, kw.column))

    def p_on_assign(self, kw, name):
        return ("on_assign_call", (str(name).lower(), kw.column))

    def constraint_forward(self, kw, name):
        return ("forward", "constraint", str(name).lower(), kw.line)

    def boundary_forward(self, kw, name):
        return ("forward", "boundary", str(name).lower(), kw.line)

    def value_decl2(self, kw, e):
        return ("ignored", str(kw).lower().rstrip(":"))

    def merit_factor(self, kw, e=None):
        return ("ignored", "merit_factor")

    def level_expr(self, a, b=None):
        return a if b is None else N.Bin("-", a, b)

    def constraint_opt(self, tok, n=None):
        if n is not None:                  # CONTENT_RANK n
            return ("content_rank", _int(n), tok.line, tok.column)
        return str(tok).lower()

    def comp(self, kw, e):
        return (str(kw).rstrip(":").lower(), e)

    def energy_block(self, _kw, *comps):
        return ("energy", list(comps))

    def content_block(self, _kw, *comps):
        return ("content", list(comps))

    def constraint(self, kw, cid, *rest):
        opts = []
        formula = None
        blocks = []
        for r in rest:
            if isinstance(r, str):
                opts.append(r)
            elif isinstance(r, Token):
                continue
            elif isinstance(r, tuple) and r[0] == "content_rank":
                opts.append(r)
            elif isinstance(r, tuple):
                blocks.append(r)
            else:
                formula = r
        return ("constraint", _cid(cid), opts, formula, blocks, kw.line)

    def boundary_opt(self, tok):
        return str(tok).lower()

    def boundary(self, kw, bid, _pk, nparams, *rest):
        opts, comps, blocks = [], [], []
        for r in rest:
            if isinstance(r, str):
                opts.append(r)
            elif isinstance(r, tuple) and r[0] in ("energy", "content"):
                blocks.append(r)
            elif isinstance(r, tuple):
                comps.append(r)
        return ("boundary", _cid(bid), _int(nparams), opts, comps, blocks, kw.line)

    def q_energy(self, _t):
        return ("kind", "energy", None)

    def q_fixed(self, _t, e):
        return ("kind", "fixed", e)

    def q_conserved(self, _t):
        return ("kind", "conserved", None)

    def q_info(self, _t):
        return ("kind", "info_only", None)

    def q_modulus(self, _t, e):
        return ("modulus", e)

    def q_lagrange(self, _t, e):
        return ("lagrange_multiplier", e)

    def q_tolerance(self, _t, e):
        return ("tolerance", e)

    def m_global(self, _t):
        return ("global", None)

    def m_scalar(self, _t, e):
        return ("scalar", e)

    def m_vector(self, _t, *comps):
        return ("vector", list(comps))

    def m_modulus(self, _t, e):
        return ("modulus", e)

    def m_parameter_1(self, _t, e):
        return ("parameter_1", e)

    def m_ignore_fixed(self, _t):
        return ("ignore_fixed", None)

    def m_ignore_constraints(self, _t):
        return ("ignore_constraints", None)

    def q_method(self, _t, name, *opts):
        return ("method", str(name).lower(), False, list(opts))

    def q_global_method(self, _t, name, *opts):
        return ("method", str(name).lower(), True, list(opts))

    def q_function(self, _t, e):
        return ("function", e)

    def index(self, name, idx):
        # ``ref_coord[1]``: an entry of an array attribute in a formula
        return N.Index(str(name), idx, name.line, name.column)

    def qvalue(self, tok):
        # ``inst.value``: the global value of a method instance (quantity FUNCTION)
        return N.Var(str(tok), tok.line, tok.column)

    def quantity(self, kw, name, kind, *rest):
        return ("quantity", str(name).lower(), kind, list(rest), kw.line)

    def method_instance(self, kw, name, _m, mname, *opts):
        return ("method_instance", str(name).lower(), str(mname).lower(), list(opts), kw.line)

    def dims(self, *exprs):
        return list(exprs)          # (expressions: evaluated in order, _decl)

    def define_attr(self, kw, etype, _a, name, atype, dims=None):
        # (REF also takes the plural and 'face' forms: define faces attribute ...)
        etype = _ETYPE.get(str(etype).lower(), str(etype).lower())
        return ("attribute", etype, str(name).lower(), str(atype).lower(),
                dims or [], kw.line)

    def flag_decl(self, kw):
        return ("flag", str(kw).lower(), kw.line)

    def value_decl(self, kw, e, fixed=None):
        return ("value", str(kw).lower().rstrip(":"), e, fixed is not None, kw.line)

    def periods(self, kw):
        return ("periods", [], kw.line)

    def view_matrix(self, kw):
        return ("ignored", str(kw).lower())

    def evolver_version(self, kw, s):
        return ("ignored", "evolver_version")

    def unsupported(self, kw):
        raise _Unsupported(kw)

    def metric_matrix(self, kw):
        return ("metric", "matrix", [], kw.line)

    def metric_conformal(self, kw, e):
        return ("metric", "conformal", [e], kw.line)

    def metric_klein(self, kw):
        return ("metric", "klein", [], kw.line)

    # -- what the Evolver's dump writes --
    def slice_coeff(self, kw, _nums):
        return ("ignored", "slice_coeff")       # the slicing plane of the graphics

    def quantity_forward(self, kw, name):
        return ("quantity_forward", str(name).lower(), kw.line)

    def dump_flag(self, kw):
        return ("flag", str(kw).lower(), kw.line)

    def instance_forward(self, kw, name):
        return ("instance_forward", str(name).lower(), kw.line)

    def global_array(self, kw, name, atype, dims, init):
        # ``define arr real[2][3] = {{...},{...}}``: a global array with its values
        return ("global_array", str(name).lower(), str(atype).lower(), dims, str(init),
                kw.line, init.line)


@v_args(inline=True)
class _LineTransformer(ExprTransformer):
    def _line(self, idtok, *items):
        flat = []
        for it in items:
            if isinstance(it, list):        # braced array values
                flat.extend(it)
            else:
                flat.append(it)
        return (_int(idtok), flat)

    def braced(self, *exprs):
        return list(exprs)

    vertex_line = edge_line = face_line = body_line = _line

    def kw(self, tok):
        return ("kw", str(tok).lower(), tok.column)

    def name_neg(self, tok):
        return ("name_neg", str(tok)[:-1].lower(), tok.column)


_TOP = _TopTransformer()
_LINE = _LineTransformer()
