"""Datafile reader: text -> :class:`pyevolver.model.scene.Scene`.

The top section and non-trivial element lines are parsed by the LALR
grammar ``fe.lark`` (with the shared expression grammar); element lines made
only of plain numbers take a fast path that gives the same result.
"""
from __future__ import annotations

import functools
import math
import os
import re

import numpy as np
from lark import Lark, Token, v_args
from lark.exceptions import UnexpectedInput, UnexpectedCharacters, UnexpectedToken, VisitError

from ..errors import DatafileError, ExpressionError, PyEvolverError
from ..expr import nodes as N
from ..expr.transform import ExprTransformer, expr_grammar
from ..limits import MAX_ARRAY_ENTRIES, MAX_FACE_EDGES, MAX_ID, MAX_NESTING, nesting_depth
from ..model.scene import (Scene, ConstraintDecl, BoundaryDecl, QuantityDecl, MethodDecl)
from .preprocess import preprocess, read_source

_HERE = os.path.dirname(__file__)

# numbers with two decimal points or an exponent without digits
_BAD_NUMBER = re.compile(r"(?<![\w.])(\d*\.\d*\.[\d.]*|\d+\.?\d*[eEdD][+-]?(?![\d+-]))")

# an element line made of plain numbers (no alternative can match a digit
# run in two ways, so a failing match cannot backtrack exponentially)
# (a '+' after a space continues the value before it: REF reads "1 2 +3" as
# the two values 1 and 5; only a '-' after a space starts a new value)
_NUMBER = r"-?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?"
_NUMERIC_LINE = re.compile(r"[ \t]*\d+(?:[ \t]+" + _NUMBER + r")*[ \t]*\Z")
# the numeric head of a line followed by attributes that start with a letter
_NUMERIC_HEAD = re.compile(r"[ \t]*\d+(?:[ \t]+" + _NUMBER + r")*(?=[ \t]+[A-Za-z_])")
# long lines (a body's facet list) avoid regexes with repeated groups, whose
# backtracking state grows with the number of repetitions
_LONG = 2000
_FIRST_WORD = re.compile(r"[A-CF-Za-cf-z_]|(?<![\d.])[DdEe]")
_NUM_CHARS = re.compile(r"[ \t\d.eE+-]*")


_ELEM_KWS = frozenset(
    "fixed bare no_refine nodisplay no_display constraint constraints boundary tension "
    "density volume volconst actual_volume pressure color colour frontcolor frontcolour "
    "backcolor backcolour wrap orientation original opacity tag phase no_hessian_normal "
    "hessian_normal_one axial_point triple_point tetra_point lagrange_multiplier "
    "centerofmass".split())
_WORD = re.compile(r"\S+")
_PLAIN = re.compile(_NUMBER + r"\Z")


def _plain_tail(tail, offset):
    """The attributes after an element's numbers when they are only keywords
    of ``fe_elements.lark`` (ELEM_KW) and plain numbers: the items the grammar
    would give, without parsing (most element lines); else None."""
    items = []
    for m in _WORD.finditer(tail):
        w = m.group(0)
        lw = w.lower()
        if lw in _ELEM_KWS:
            items.append(("kw", lw, offset + m.start() + 1))
        elif _PLAIN.match(w):
            items.append(float(w))
        else:
            return None
    return items


class _Head:
    def __init__(self, end):
        self._end = end

    def end(self):
        return self._end


def _long_numeric(line):
    """For a long line: ``("all", None)`` if it is plain numbers, ``("head",
    m)`` if plain numbers are followed by a word, else ``(None, None)``."""
    m = _FIRST_WORD.search(line)
    end = m.start() if m else len(line)
    head = line[:end]
    if not _NUM_CHARS.fullmatch(head) or (m and end and not line[end - 1].isspace()):
        return None, None
    if "+" in head and re.search(r"(?:^|[ \t])\+", head):
        return None, None               # '+3' after a space: an addition
    if not head.split() or not head.split(None, 1)[0].isdigit():
        return None, None               # the element id: digits ('1e308' is not one)
    try:
        vals = np.fromstring(head, dtype=float, sep=" ")
    except ValueError:                  # '1-2', '--3': not plain numbers
        return None, None
    if vals.size != len(head.split()) or not vals.size or vals[0] != int(vals[0]):
        return None, None
    return ("all", None) if m is None else ("head", _Head(len(head.rstrip())))


class _Unsupported(Exception):
    pass


def _refuse(tok):
    raise _Unsupported(tok)


@functools.lru_cache(maxsize=1)
def top_parser():
    """LALR parser of the top section (``fe_top.lark`` + ``expr.lark``)."""
    with open(os.path.join(_HERE, "fe_top.lark")) as fh:
        grammar = expr_grammar() + "\n" + fh.read()
    return Lark(grammar, parser="lalr", lexer="contextual", start="start",
                maybe_placeholders=False, lexer_callbacks={"UNSUPPORTED_KW": _refuse,
                                                    "UNSUPPORTED2_KW": _refuse},
                cache=True)


@functools.lru_cache(maxsize=1)
def line_parser():
    """LALR parser of one element line (``fe_elements.lark`` + ``expr.lark``)."""
    with open(os.path.join(_HERE, "fe_elements.lark")) as fh:
        grammar = expr_grammar() + "\n" + fh.read()
    return Lark(grammar, parser="lalr", lexer="contextual",
                start=["vertex_line", "edge_line", "face_line", "body_line"],
                maybe_placeholders=False, cache=True)


_SPACE_DIM_RE = re.compile(r"^[ \t]*space_dimension[ \t:]+(\d+)", re.I | re.M)
# ``define edge attribute bbb real function { ... }``: refused by name
_ATTR_FUNCTION = re.compile(r"\bdefine\s+\w+\s+attribute\s+\w+\s+\w+(?:\s*\[[^\]\n]*\])*"
                            r"\s+(function)\b", re.I)
_MATRIX_RE = re.compile(r"\b(torus_periods|periods|view_matrix|view_transforms|"
                        r"view_transform_generators)\b", re.I)
_NUMTOK_RE = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?)(?=\s|$)")


def _cid(tok):
    """A constraint's or boundary's number, or its name (lower case)."""
    s = str(tok)
    return int(s) if s.isdigit() else s.lower()


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
            return ("content_rank", int(n), tok.line, tok.column)
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
        return ("boundary", _cid(bid), int(nparams), opts, comps, blocks, kw.line)

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
        return (int(idtok), flat)

    def braced(self, *exprs):
        return list(exprs)

    vertex_line = edge_line = face_line = body_line = _line

    def kw(self, tok):
        return ("kw", str(tok).lower(), tok.column)

    def name_neg(self, tok):
        return ("name_neg", str(tok)[:-1].lower(), tok.column)


_TOP = _TopTransformer()
_LINE = _LineTransformer()

VALUE_NAMES = {
    "square_curvature": "squared_curvature",
    "spring_constant": "gap_constant",
    "integral_order": "integral_order",
}


class Reader:
    """Reads one datafile into a :class:`Scene`."""

    def __init__(self, filename, text=None):
        self.filename = filename
        self.text = read_source(filename) if text is None else text
        self.scene = Scene(filename=filename)
        self._src_lines = None
        self._named_forward = set()     # names declared ahead ("constraint pinned;")

    @property
    def src_lines(self):
        if self._src_lines is None:
            self._src_lines = self.text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
        return self._src_lines

    # -- errors -----------------------------------------------------------
    def error(self, msg, line, col=None):
        excerpt = self.src_lines[line - 1] if line and 0 < line <= len(self.src_lines) else None
        return DatafileError(msg, self.filename, line, col, excerpt)

    def read(self):
        self.scene.source_lines = self.src_lines
        sections, self.macros = preprocess(self.text, self.filename)
        top = sections[0]
        self._top(top)
        if "keep_macros" in self.scene.flags:
            self.scene.macros = self.macros     # active at run time too (manual)
        seen = []
        for k in range(1, len(sections)):
            sec = sections[k]
            sections[k] = None           # let each section's text go once read
            if sec.kind == "read":
                self.scene.read_text = sec.text
                self.scene.read_line = sec.line
                self.scene.read_warnings = sec.warnings
                continue
            if sec.kind in seen:
                raise self.error(f"section '{sec.kind}' appears twice", sec.line, 1)
            seen.append(sec.kind)
            self._elements(sec)
        if "vertices" not in seen:
            last = len(self.src_lines)
            raise self.error("unexpected end of file: expected a 'vertices' section",
                             last, 1)
        if self.scene.unsupported:
            feature, line, col = self.scene.unsupported[0]
            raise self.error(f"not supported in pyevolver: {feature}", line, col)
        if "keep_originals" in self.scene.flags:
            self._keep_originals()
        return self.scene

    def _keep_originals(self):
        """KEEP_ORIGINALS: the elements keep their datafile ids (the Evolver
        otherwise numbers them in reading order).  pyevolver numbers elements
        1..n by position, so a section whose ids are 1..n in another order
        (the Evolver's dump after refining) is put in id order; ids with gaps
        cannot be kept and are refused."""
        sc = self.scene
        for kind, what in (("vertices", "vertex"), ("edges", "edge"), ("faces", "face"),
                           ("bodies", "body")):
            blk = getattr(sc, kind)
            ids = np.asarray(blk.ids, dtype=np.int64)
            n = len(ids)
            if not n or np.array_equal(ids, np.arange(1, n + 1)):
                continue
            order = np.argsort(ids, kind="stable")
            if not np.array_equal(ids[order], np.arange(1, n + 1)):
                missing = int(np.setdiff1d(np.arange(1, n + 1), ids)[0])
                line = sc.decl_lines.get("keep_originals")
                raise self.error(f"not supported in pyevolver: KEEP_ORIGINALS with {what} ids "
                                 f"that are not 1 to {n} ({what} {missing} is missing); "
                                 f"elements are numbered 1..n", line)
            inv = np.empty(n, np.int64)
            inv[order] = np.arange(n)
            blk.ids = ids[order] if isinstance(blk.ids, np.ndarray) else ids[order].tolist()
            if isinstance(blk.data, np.ndarray):
                blk.data = blk.data[order]
            else:
                blk.data = [blk.data[k] for k in order.tolist()]
            blk.lines = type(blk.lines)("l", [blk.lines[k] for k in order.tolist()])
            blk.attrs = {int(inv[pos]): a for pos, a in blk.attrs.items()}
            if kind == "edges" and sc.wraps:
                sc.wraps = {int(inv[pos]): w for pos, w in sc.wraps.items()}

    # -- top section --------------------------------------------------------
    def _describe(self, exc, text):
        if isinstance(exc, UnexpectedCharacters):
            ch = text[exc.pos_in_stream] if exc.pos_in_stream < len(text) else ""
            word = re.match(r"[A-Za-z_]\w*", text[exc.pos_in_stream:])
            if word:
                return (f"unexpected '{word.group(0)}': not a keyword, parameter or "
                        f"value allowed here")
            return f"unexpected character {ch!r}"
        if isinstance(exc, UnexpectedToken):
            tok = exc.token
            if tok.type == "$END":
                exp = _expected(exc.expected)
                return f"unexpected end of line: expected {exp}"
            exp = _expected(exc.expected)
            return f"unexpected '{tok}': expected {exp}"
        return str(exc).split("\n")[0]

    def _matrix_exprs(self, text, m, count):
        """The ``count`` values after the PERIODS or VIEW_MATRIX keyword ``m``:
        expressions separated by white space as on an element line (manual:
        "PERIODS followed by expressions"; ``1 -2`` is two values, ``1 - 2``
        one), whole lines at a time.  Returns ``(exprs, end)``."""
        pos = m.end()
        vals = []
        while len(vals) < count and pos < len(text):
            nl = text.find("\n", pos)
            nl = len(text) if nl < 0 else nl
            seg = text[pos:nl]
            if seg.strip():
                try:
                    tree = line_parser().parse("0 " + seg, start="vertex_line")
                    _, items = _LINE.transform(tree)
                except (UnexpectedInput, VisitError):
                    break
                if any(isinstance(it, tuple) for it in items):
                    break
                vals.extend(items)
            pos = nl + 1 if nl < len(text) else nl
        return vals, min(pos, len(text))

    def _extract_matrices(self, text):
        """Take the numbers of PERIODS / VIEW_* matrices out of the text."""
        out = text
        for m in _MATRIX_RE.finditer(text):
            key = m.group(1).lower()
            if key.endswith("periods") or key == "view_matrix":
                # rows given by expressions (parameters, arithmetic) or numbers
                sd = self._peek_space_dimension(text[:m.start()])
                count = sd * sd if key.endswith("periods") else (sd + 1) ** 2
                vals, pos = self._matrix_exprs(text, m, count)
                line = text.count("\n", 0, m.start()) + 1
                if len(vals) != count:
                    raise _MatrixError(line, f"{key.upper()} needs {count} numbers, "
                                             f"found {len(vals)}")
                out = out[:m.end()] + re.sub(r"[^\n]", " ", out[m.end():pos]) + out[pos:]
                if key.endswith("periods"):
                    self._period_exprs = vals
                continue
            pos = m.end()
            if key.startswith("view_transform"):
                # n, then n matrices, each after an optional COLOR c or SWAP_COLORS
                pos = _skip_transforms(text, pos, self._peek_space_dimension(text[:m.start()]))
                out = out[:m.end()] + re.sub(r"[^\n]", " ", out[m.end():pos]) + out[pos:]
                continue
            vals = []
            limit = None
            if m.group(1).lower().endswith("periods"):
                sd = self._peek_space_dimension(text[:m.start()])
                limit = sd * sd
            while limit is None or len(vals) < limit:
                mm = _NUMTOK_RE.match(text, pos)
                if not mm:
                    break
                vals.append(float(mm.group(1).replace("d", "e").replace("D", "e")))
                pos = mm.end()
            out = out[:m.end()] + re.sub(r"[^\n]", " ", out[m.end():pos]) + out[pos:]
            if limit is not None:
                if len(vals) != limit:
                    line = text.count("\n", 0, m.start()) + 1
                    raise _MatrixError(line, f"PERIODS needs {limit} numbers, found {len(vals)}")
                if not all(math.isfinite(v) for v in vals):
                    line = text.count("\n", 0, m.start()) + 1
                    raise _MatrixError(line, "PERIODS: the numbers must be finite")
                self.scene.values["_periods"] = vals
        return out

    def _peek_space_dimension(self, text):
        m = re.search(r"\bspace_dimension\s+(\d+)", text, re.I)
        return int(m.group(1)) if m else 3

    def _cut_procedures(self, sec):
        """Take the stand-alone ``procedure`` and ``function`` declarations and
        definitions out of the top section (manual, "Functions and
        procedures": the read-section syntax, allowed in the top section).

        They are kept, with their source lines, in ``scene.top_commands`` (run
        as commands before the read section) and blanked in the text, so the
        line and column of everything else are kept.
        """
        text = sec.text
        self._functions = set()
        self._procedures = set()
        af = _ATTR_FUNCTION.search(text)
        if af:
            line = text.count("\n", 0, af.start(1)) + 1
            raise self.error("not supported in pyevolver: attribute FUNCTION (an extra "
                             "attribute computed by a procedure)", self._src(sec, line),
                             af.start(1) - text.rfind("\n", 0, af.start(1)))
        if not _PROC_START.search(text):
            return text
        out = []
        pos = 0
        for m in _PROC_START.finditer(text):
            if m.start() < pos:
                continue
            end = _proc_end(text, m.end() - 1)
            line = text.count("\n", 0, m.start()) + 1
            if end is None:
                raise self.error(f"unbalanced parentheses or braces in this "
                                 f"{m.group(1).lower()} declaration", self._src(sec, line),
                                 m.start() - text.rfind("\n", 0, m.start()))
            body = text[m.start():end]
            self.scene.top_commands.append((body.rstrip().rstrip(";"), self._src(sec, line)))
            if m.group(1).lower() == "procedure":
                self._procedures.add(re.match(r"\w+\s+(\w+)", body).group(1).lower())
            if m.group(1).lower() == "function":
                self._functions.add(re.match(r"\w+\s+(?:\w+\s+)?(\w+)", body).group(1).lower())
            out.append(text[pos:m.start()])
            out.append(re.sub(r"[^\n]", " ", body))
            pos = end
        out.append(text[pos:])
        text = "".join(out)
        if self._functions:
            # a user function called in a top-section expression (REF evaluates
            # it with its command interpreter; pyevolver's datafile reader has none)
            call = re.search(r"\b(" + "|".join(map(re.escape, sorted(self._functions))) +
                             r")\s*\(", text, re.I)
            if call:
                line = text.count("\n", 0, call.start()) + 1
                raise self.error(f"not supported in pyevolver: calling the user function "
                                 f"{call.group(1)} in the top section of a datafile",
                                 self._src(sec, line),
                                 call.start() - text.rfind("\n", 0, call.start()))
        return text

    def _top(self, sec):
        if _PROC_START.search(sec.text) or _ATTR_FUNCTION.search(sec.text):
            sec.text = self._cut_procedures(sec)
        text = sec.text.replace(",", " ")
        bad = _BAD_NUMBER.search(text)
        if bad:
            line = text.count("\n", 0, bad.start()) + 1
            col = bad.start() - (text.rfind("\n", 0, bad.start()) + 1) + 1
            raise self.error(f"malformed number '{bad.group(0)}'", self._src(sec, line), col)
        sdm = _SPACE_DIM_RE.search(text)
        if sdm and int(sdm.group(1)) > 3:
            # the model is refused whatever else the file says: say so before
            # parsing what only that model allows (relaxed.fe's ref_coord[1])
            line = text.count("\n", 0, sdm.start()) + 1
            raise self.error(f"not supported in pyevolver: SPACE_DIMENSION {sdm.group(1)} "
                             f"(3, or 2 in the string model)", self._src(sec, line),
                             sdm.start() - (text.rfind("\n", 0, sdm.start()) + 1) + 1)
        fdef = _ATTR_FUNCTION.search(text)
        if fdef:
            line = text.count("\n", 0, fdef.start(1)) + 1
            col = fdef.start(1) - (text.rfind("\n", 0, fdef.start(1)) + 1) + 1
            raise self.error("not supported in pyevolver: DEFINE ... ATTRIBUTE ... FUNCTION "
                             "(attributes computed when read)", self._src(sec, line), col)
        try:
            if _MATRIX_RE.search(text):
                text = self._extract_matrices(text)
            tree = top_parser().parse(text, start="start")
            decls = _TOP.transform(tree)
        except _MatrixError as exc:
            raise self.error(exc.args[1], self._src(sec, exc.args[0]), 1) from None
        except _Unsupported as exc:
            kw = exc.args[0]
            raise self.error(f"not supported in pyevolver: {str(kw).upper()}",
                             self._src(sec, kw.line), kw.column) from None
        except UnexpectedInput as exc:
            line = exc.line if exc.line not in (None, -1) else 1
            srcline = sec.lines[line - 1] if sec.lines else line
            raise self.error(self._describe(exc, text), srcline,
                             exc.column if exc.column not in (None, -1) else None) from None
        except VisitError as exc:
            orig = exc.orig_exc
            if isinstance(orig, _Unsupported):
                kw = orig.args[0]
                srcline = sec.lines[kw.line - 1] if sec.lines else kw.line
                raise self.error(f"not supported in pyevolver: {str(kw).upper()}",
                                 srcline, kw.column) from None
            if isinstance(orig, PyEvolverError):
                line = getattr(orig, "line", None)
                raise self.error(str(orig), self._src(sec, line) if line else sec.line,
                                 getattr(orig, "column", None)) from None
            raise
        for d in decls:
            if nesting_depth(d) > MAX_NESTING:
                line = d[-1] if isinstance(d[-1], int) else 1
                raise self.error(f"expression nested more than {MAX_NESTING} levels deep",
                                 self._src(sec, line))
        self._fill_scene(decls, sec)

    def _src(self, sec, line):
        return sec.lines[line - 1] if sec.lines else line

    def _const(self, expr, line, what):
        try:
            v = expr.ev(self.param_env)
        except ExpressionError as exc:
            raise self.error(f"{exc} in {what}", line, getattr(expr, "column", None)) from None
        if isinstance(v, str):
            raise self.error(f"expected a number for {what}, got a string", line)
        return float(v)

    @property
    def param_env(self):
        named = self._named_ids()
        if named:
            return N.MapEnv({**named, **self.scene.parameters})
        return N.MapEnv(self.scene.parameters)

    def _named_ids(self):
        """Named constraints and boundaries as values (REF: ``print pinned``
        prints its number; ``constraint 2,pinned`` on an element)."""
        sc = self.scene
        if not (sc.constraint_names or sc.boundary_names):
            return {}
        key = (tuple(sc.constraint_names.items()), tuple(sc.boundary_names.items()))
        if getattr(self, "_named_key", None) != key:
            self._named_key = key
            self._named = {**{n: float(c) for c, n in sc.boundary_names.items()},
                           **{n: float(c) for c, n in sc.constraint_names.items()}}
        return self._named

    def _formula(self, expr, text="", allowed=None):
        if allowed is None:
            self._check_names(expr)
        else:
            self._check_names(expr, allowed)
        return N.Formula(expr, text)

    def _check_names(self, expr, allowed=("x", "y", "z", "w", "x1", "x2", "x3", "x4", "g")):
        # (boundary parametrizations name p1, p2, ... instead: see _decl)
        for name in expr.names():
            if (name in allowed or name in self.scene.parameters or name in N.CONSTANTS
                    or any(name == a[1] for a in self.scene.attributes)):
                continue
            line = None
            for node in _walk(expr):
                if isinstance(node, N.Var) and node.name == name:
                    line = node.line
                    col = node.column
                    break
            raise _LocatedName(name, line, col)

    def _fill_scene(self, decls, sec):
        sc = self.scene
        self._forward = {}
        for d in decls:
            kind = d[0]
            try:
                self._decl(d, sc, sec)
            except _LocatedName as exc:
                raise self.error(f"undefined parameter '{exc.name}'",
                                 self._src(sec, exc.line) if exc.line else None,
                                 exc.col) from None
        for name, (kind, line) in self._forward.items():
            known = sc.quantities if kind == "quantity_forward" else sc.method_instances
            if name not in known:
                what = "quantity" if kind == "quantity_forward" else "method_instance"
                raise self.error(f"{what} {name} is declared but never defined", line)

    def _decl(self, d, sc, sec):
        kind = d[0]
        if kind == "parameter":
            _, name, expr, line = d[:4]
            if len(d) > 4:
                self._parameter_options(name, d[4], self._src(sec, line))
            if isinstance(expr, N.Str):         # a string-valued parameter
                sc.parameters[name] = expr.value
                return
            sc.parameters[name] = self._const(expr, self._src(sec, line), f"parameter {name}")
        elif kind == "flag":
            sc.flags.add(d[1])
            sc.decl_lines[d[1]] = self._src(sec, d[2])
        elif kind == "value":
            _, name, expr, fixed, line = d
            name = VALUE_NAMES.get(name, name)
            sc.values[name] = self._const(expr, self._src(sec, line), name)
            sc.decl_lines[name] = self._src(sec, line)
            if name in ("space_dimension", "surface_dimension") and \
                    sc.values[name] not in (1, 2, 3, 4):
                raise self.error(f"not supported in pyevolver: {name.upper()} "
                                 f"{sc.values[name]:g}", self._src(sec, line))
            if fixed:
                sc.values[name + "_fixed"] = 1.0
            # the quadrature orders: pyevolver has REF's default rules only
            default = {"integral_order_1d": 3.0, "integral_order_2d": 6.0}.get(name)
            if name == "integral_order" or (default is not None and
                                            sc.values[name] != default):
                raise self.error(f"not supported in pyevolver: {name.upper()} "
                                 f"{sc.values[name]:g} (edge integrals use order 3 and facet "
                                 f"integrals order 6, the Evolver's defaults)",
                                 self._src(sec, line))
        elif kind == "constraint":
            _, cid, opts, formula, blocks, line = d
            cid = self._number_named(cid, sc.constraints, sc.constraint_names, "constraint",
                                     self._src(sec, line))
            if cid in sc.constraints:
                raise self.error(f"constraint {cid} defined twice", self._src(sec, line))
            for o in [o for o in opts if isinstance(o, tuple)]:
                # the content integral's side with several content constraints
                self._defer("CONTENT_RANK", self._src(sec, o[2]), o[3])
                opts.remove(o)
            c = ConstraintDecl(cid, self._formula(formula), set(opts), line=self._src(sec, line))
            for bname, comps in blocks:
                setattr(c, bname, self._components(comps, "ec"[bname == "content"], sec, line))
            sc.constraints[cid] = c
        elif kind == "boundary":
            _, bid, npar, opts, comps, blocks, line = d
            bid = self._number_named(bid, sc.boundaries, sc.boundary_names, "boundary",
                                     self._src(sec, line))
            if bid in sc.boundaries:
                raise self.error(f"boundary {bid} defined twice", self._src(sec, line))
            if not 1 <= npar <= 3:
                raise self.error(f"boundary {bid}: PARAMETERS must be 1, 2 or 3, got {npar}",
                                 self._src(sec, line))
            # a boundary's coordinates are functions of its parameters only
            coords = self._components(comps, "x", sec, line,
                                      allowed=tuple(f"p{k + 1}" for k in range(npar)))
            b = BoundaryDecl(bid, npar, coords, set(opts), line=self._src(sec, line))
            for bname, bcomps in blocks:
                setattr(b, bname, self._components(bcomps, "ec"[bname == "content"], sec, line))
            sc.boundaries[bid] = b
        elif kind == "quantity":
            _, name, kindt, rest, line = d
            q = QuantityDecl(name, kindt[1], line=self._src(sec, line))
            if kindt[2] is not None:
                q.target = self._const(kindt[2], q.line, f"quantity {name} target")
            for r in rest:
                if r[0] in ("modulus", "tolerance", "lagrange_multiplier"):
                    setattr(q, r[0], self._const(r[1], q.line, f"quantity {name} {r[0]}"))
                elif r[0] == "method":
                    q.methods.append(self._method(r[1], r[2], r[3], sec, line, name))
                elif r[0] == "function":
                    q.function = r[1]
            sc.quantities[name] = q
        elif kind == "method_instance":
            _, name, mname, opts, line = d
            m = self._method(mname, False, opts, sec, line, name)
            m.line = self._src(sec, line)
            sc.method_instances[name] = m
        elif kind == "attribute":
            _, etype, name, atype, dims, line = d
            dims = [self._dim(e, self._src(sec, line), name) for e in dims]
            if atype in _INT_ATTR_TYPES:
                atype = "integer"        # the Evolver's integer types; stored as numbers
            elif atype != "real":
                raise self.error(f"not supported in pyevolver: {atype.upper()} element "
                                 f"attributes (attribute {name})", self._src(sec, line))
            size = math.prod(dims) if dims else 1
            if size > MAX_ARRAY_ENTRIES:
                raise self.error(f"attribute {name}: {size} entries per {etype}; at most "
                                 f"{MAX_ARRAY_ENTRIES} are allowed", self._src(sec, line))
            sc.attributes[(etype, name)] = (atype, size, dims)
        elif kind == "forward":          # constraint NAME;  boundary NAME;
            _, what, name, line = d
            table, names = ((sc.constraints, sc.constraint_names) if what == "constraint"
                            else (sc.boundaries, sc.boundary_names))
            if name not in names.values():
                self._number_named(name, table, names, what, self._src(sec, line))
                self._named_forward.add((what, name))
        elif kind == "global_array":
            self._global_array(d, sc, sec)
        elif kind in ("quantity_forward", "instance_forward"):
            # ``quantity name;``, ``method_instance name;``: declared now, defined
            # later in the top section
            self._forward.setdefault(d[1], (kind, self._src(sec, d[2])))
        elif kind == "periods":
            exprs = getattr(self, "_period_exprs", None)
            if exprs is not None:       # expressions: evaluated here, in order
                line = self._src(sec, d[2])
                vals = [self._value(e, line, "PERIODS") for e in exprs]
                if not all(math.isfinite(v) for v in vals):
                    raise self.error("PERIODS: the values must be finite", line)
                sc.values["_periods"] = vals
                if any(not isinstance(e, (float, N.Num)) for e in exprs):
                    sc.values["_period_exprs"] = exprs
            # (plain numbers were taken by _extract_matrices)
        elif kind == "ignored":
            pass

    def _defer(self, feature, line, col=None):
        """An unsupported feature met while reading: the file is read to the
        end, then refused by name at the first such feature (located)."""
        self.scene.unsupported.append((feature, line, col))

    def _parameter_options(self, name, opts, line):
        """OPTIMIZING_PARAMETER (refused: the Evolver varies it during
        iteration), PDELTA / PSCALE (used by optimizing parameters only: no
        number of a plain parameter changes), ON_ASSIGN_CALL (refused)."""
        if opts.get("optimizing"):
            self._defer(f"OPTIMIZING_PARAMETER ({name})", line, opts.get("column"))
        for key in ("pdelta", "pscale"):
            if key in opts:
                self._const(opts[key][0], line, f"{key} of parameter {name}")
        if "on_assign_call" in opts:
            # the procedure runs whenever the variable is assigned (manual); it
            # must have been declared before, in the top section
            proc, col = opts["on_assign_call"]
            if proc not in getattr(self, "_procedures", ()):
                raise self.error(f"ON_ASSIGN_CALL: '{proc}' is not a procedure declared "
                                 f"above (e.g. procedure {proc}();)", line, col)
            self.scene.on_assign[name] = proc

    def _dim(self, expr, line, name):
        """An attribute's array dimension: a constant expression (REF:
        ``real[nn+1]``), a positive integer."""
        v = self._const(expr, line, f"the dimension of attribute {name}")
        if not (math.isfinite(v) and v == int(v) and v >= 0):
            raise self.error(f"attribute {name}: the dimension must be a non-negative "
                             f"integer, got {v:g}", line)
        return int(v)

    def _number_named(self, key, table, names, what, line):
        """The number of a constraint or boundary declared by number or by name.

        A name takes the lowest number not in use; a later declaration by a
        number a name holds moves the name to the lowest free number (REF:
        ``constraint aa``, ``constraint bb``, ``constraint 1`` give aa 3, bb 2).
        """
        if isinstance(key, int):
            if key in names:
                name = names.pop(key)
                decl = table.pop(key, None)     # (None: only declared ahead so far)
                new = _lowest_free(table, names, also=key)
                if decl is not None:
                    decl.id = new
                    table[new] = decl
                names[new] = name
            return key
        if key in names.values():
            if (what, key) in self._named_forward:     # declared ahead, defined now
                self._named_forward.discard((what, key))
                return next(c for c, n in names.items() if n == key)
            raise self.error(f"{what} '{key}' defined twice", line)
        if key in self.scene.parameters:
            raise self.error(f"{what} name '{key}' is already a parameter", line)
        new = _lowest_free(table, names)
        names[new] = key
        return new

    def _global_array(self, d, sc, sec):
        _, name, atype, dims, init, line, iline = d
        where = self._src(sec, line)
        dims = [self._dim(e, where, name) for e in dims]
        if atype not in ("real", "string") and atype not in _INT_ATTR_TYPES:
            raise self.error(f"not supported in pyevolver: {atype.upper()} arrays "
                             f"(array {name})", where)
        size = math.prod(dims) if dims else 1
        if size > MAX_ARRAY_ENTRIES:
            raise self.error(f"array {name}: {size} entries; at most {MAX_ARRAY_ENTRIES} are "
                             f"allowed", where)
        # the values in braces, row by row: numbers or strings
        depth, shape_ok, vals = 0, True, []
        for m in _ARRAY_TOKEN.finditer(init):
            tok = m.group(0)
            if tok == "{":
                depth += 1
                shape_ok = shape_ok and depth <= len(dims)
            elif tok == "}":
                depth -= 1
            elif tok.startswith('"'):
                vals.append(tok[1:-1].encode("latin-1").decode("unicode_escape"))
            else:
                vals.append(float(tok.replace("d", "e").replace("D", "e")))
        strings = atype == "string"
        if not shape_ok or len(vals) != size or any(isinstance(v, str) != strings
                                                     for v in vals):
            raise self.error(f"array {name}: expected {size} "
                             f"{'strings' if strings else 'numbers'} in "
                             f"{len(dims)} levels of braces for {atype}"
                             + "".join(f"[{k}]" for k in dims), self._src(sec, iline))
        arr = np.array(vals, dtype=object if strings else float).reshape(dims)
        sc.arrays[name] = ("integer" if atype in _INT_ATTR_TYPES else atype, arr)

    def _method(self, mname, is_global, opts, sec, line, qname):
        m = MethodDecl(mname, is_global, name=qname)
        for o in opts:
            if o[0] == "global":
                m.is_global = True
            elif o[0] == "scalar":
                m.scalar = self._formula(o[1])
            elif o[0] == "vector":
                m.vector = self._components(o[1], "q", sec, line)
            elif o[0] == "modulus":
                m.modulus = self._const(o[1], self._src(sec, line), "modulus")
            elif o[0] == "ignore_fixed":
                m.ignore_fixed = True
            elif o[0] == "ignore_constraints":
                m.ignore_constraints = True
        return m

    def _components(self, comps, letter, sec, line, allowed=None):
        out = {}
        for key, expr in comps:
            if key[0] != letter:
                raise self.error(f"unexpected component '{key.upper()}': expected "
                                 f"{letter.upper()}1, {letter.upper()}2, ...",
                                 self._src(sec, line))
            out[int(key[1:])] = self._formula(expr, allowed=allowed)
        n = max(out) if out else 0
        return [out.get(i + 1, N.Formula(N.Num(0.0))) for i in range(n)]

    # -- element sections ----------------------------------------------------
    def _elements(self, sec):
        """Parse one element section.

        Lines of plain numbers are converted in bulk with numpy; a line whose
        numbers are followed by attributes sends only the attributes to the
        grammar; anything else is parsed whole by ``fe_elements.lark``.
        """
        kind = sec.kind
        block = getattr(self.scene, kind)
        start = {"vertices": "vertex_line", "edges": "edge_line", "faces": "face_line",
                 "bodies": "body_line"}[kind]
        lines = sec.text.split("\n")
        torus = self.scene.torus
        sdim = self.scene.space_dimension
        nums = _NUMERIC_LINE.match
        head_re = _NUMERIC_HEAD.match
        numeric_pos = []       # positions in the block of pure numeric lines
        numeric_txt = []
        entries = 0
        for k, raw in enumerate(lines):
            if not raw or raw.isspace():
                continue
            srcline = sec.lines[k] if sec.lines else sec.line + k
            long_kind = long_head = None
            if len(raw) > _LONG:
                long_kind, long_head = _long_numeric(raw.replace(",", " ").replace(":", " "))
            if long_kind == "all" or (long_kind is None and len(raw) <= _LONG and nums(raw)):
                block.ids.append(None)
                block.data.append(None)
                block.lines.append(srcline)
                numeric_pos.append(entries)
                numeric_txt.append(raw)
                entries += 1
                continue
            if "(" in raw and "-" in raw:
                raw = _binary_minus_in_parens(raw)
            line = raw.replace(",", " ").replace(":", " ")
            if "{" in line:             # array attribute values: ref_coord { 1 0 0 }
                line = line.replace("{", " ").replace("}", " ")
            bad = _BAD_NUMBER.search(line)
            if bad:
                raise self.error(f"malformed number '{bad.group(0)}'", srcline, bad.start() + 1)
            if kind == "edges" and torus:
                line = self._strip_wraps(line, entries, sdim, srcline)
            if ";" in line:
                raise self.error("unexpected ';': one element per line", srcline,
                                 line.index(";") + 1)
            head = long_head if long_kind == "head" else (
                head_re(line) if len(line) <= _LONG else None)
            try:
                if head is not None and kind != "edges" or (head is not None and not torus):
                    nums_ = np.fromstring(line[:head.end()], dtype=float, sep=" ")
                    tail = line[head.end():]
                    items = _plain_tail(tail, head.end())
                    if items is None:
                        tree = line_parser().parse("0" + " " * (head.end() - 1) + tail,
                                                   start=start)
                        _, items = _LINE.transform(tree)
                    eid = int(line[:head.end()].split()[0])
                    items = nums_[1:].tolist() + items
                else:
                    tree = line_parser().parse(line, start=start)
                    eid, items = _LINE.transform(tree)
            except UnexpectedInput as exc:
                col = exc.column if exc.column not in (None, -1) else None
                what = {"vertices": "vertex", "edges": "edge", "faces": "face",
                        "bodies": "body"}[kind]
                for fn in getattr(self, "_functions", ()):
                    call = re.search(r"\b" + re.escape(fn) + r"\s*\(", line, re.I)
                    if call:
                        raise self.error(f"not supported in pyevolver: calling the user "
                                         f"function {fn} in a datafile element line",
                                         srcline, call.start() + 1) from None
                raise self.error(self._describe(exc, line) + f" in {what} line", srcline,
                                 col) from None
            except VisitError as exc:
                if isinstance(exc.orig_exc, PyEvolverError):
                    raise self.error(str(exc.orig_exc), srcline,
                                     getattr(exc.orig_exc, "column", None)) from None
                raise
            if nesting_depth(items) > MAX_NESTING:
                raise self.error(f"expression nested more than {MAX_NESTING} levels deep",
                                 srcline)
            self._cur_line = line
            self._element(kind, block, eid, items, srcline)
            entries += 1
        if numeric_txt:
            self._bulk(kind, block, numeric_pos, numeric_txt)

    def _bulk(self, kind, block, positions, texts):
        """Convert pure-numeric lines with one numpy call (no token list)."""
        lens = np.fromiter((len(t.split()) for t in texts), np.int64, len(texts))
        vals = np.fromstring(" ".join(texts), dtype=float, sep=" ")
        if vals.size != int(lens.sum()):       # cannot happen for lines that matched
            raise self.error("could not read the numbers of this section", block.lines[positions[0]])
        starts = np.concatenate([[0], np.cumsum(lens)[:-1]])
        what = {"vertices": "vertex", "edges": "edge", "faces": "face", "bodies": "body"}[kind]

        def line_of(k):                 # source line of the k-th number
            return block.lines[positions[int(np.searchsorted(starts, k, side="right")) - 1]]
        idv = vals[starts]
        bad = np.nonzero(~((idv >= 1) & (idv <= MAX_ID)))[0]
        if len(bad):
            raise self.error(f"{what} id {idv[bad[0]]:.0f} is out of range (ids are 1 to "
                             f"{MAX_ID})", line_of(starts[bad[0]]), 1)
        if kind == "vertices":
            bad = np.nonzero(~np.isfinite(vals))[0]
            if len(bad):
                raise self.error(f"vertex coordinate {vals[bad[0]]:g} is not a finite number",
                                 line_of(bad[0]))
        else:
            frac = np.nonzero(vals != np.round(vals))[0]
            if len(frac):
                raise self.error(f"expected an integer id, got {vals[frac[0]]:g}",
                                 line_of(frac[0]))
            big = np.nonzero(np.abs(vals) > MAX_ID)[0]
            if len(big):
                raise self.error(f"{what}: id {vals[big[0]]:.0f} is out of range (ids are 1 to "
                                 f"{MAX_ID})", line_of(big[0]))
            if kind == "faces" and lens.max() - 1 > MAX_FACE_EDGES:
                k = int(np.argmax(lens))
                raise self.error(f"face {vals[starts[k]]:.0f} has {lens[k] - 1} edges; at most "
                                 f"{MAX_FACE_EDGES} are allowed", block.lines[positions[k]])
            vals = vals.astype(np.int64)
        ids = vals[starts].astype(np.int64)
        uniform = bool(np.all(lens == lens[0]))
        if uniform and len(positions) == len(block.ids):
            # the whole section is one table: keep it as arrays
            block.ids = ids
            block.data = vals.reshape(len(texts), int(lens[0]))[:, 1:]
            if kind == "vertices" and 1 <= block.data.shape[1] < self.scene.space_dimension:
                block.data = self._pad_coordinates(block.data, ids, block.lines)
            return
        sd = self.scene.space_dimension
        for p, i, st, n in zip(positions, ids.tolist(), starts.tolist(), lens.tolist()):
            block.ids[p] = i
            block.data[p] = vals[st + 1: st + n]
            if kind == "vertices" and 2 <= n <= sd:
                block.data[p] = self._pad_coordinates(block.data[p][None, :], [i],
                                                      [block.lines[p]])[0]

    def _pad_coordinates(self, data, ids, lines):
        """Vertices with fewer coordinates than the space dimension: a warning
        each, the missing ones 0 (REF: WARNING 1127 "Wrong number of
        coordinates for vertex")."""
        sd = self.scene.space_dimension
        for k, vid in enumerate(ids):
            self.warn(f"wrong number of coordinates for vertex {int(vid)}: "
                      f"{data.shape[1]} instead of {sd} (the rest are 0)", lines[k])
        out = np.zeros((data.shape[0], sd))
        out[:, :data.shape[1]] = data
        return out

    def _strip_wraps(self, line, pos, sdim, srcline):
        toks = line.split()
        if len(toks) >= 3 + sdim and all(t in ("*", "+", "-") for t in toks[3:3 + sdim]):
            self.scene.wraps[pos] = [{"*": 0, "+": 1, "-": -1}[t] for t in toks[3:3 + sdim]]
            return " ".join(toks[:3] + toks[3 + sdim:])
        return line

    def _undefined(self, exc, srcline):
        if exc.name in getattr(self, "_functions", ()):
            return self.error(f"not supported in pyevolver: calling the user function "
                              f"{exc.name} in a datafile element line", srcline, exc.col)
        return self.error(f"undefined parameter '{exc.name}'", srcline, exc.col)

    def warn(self, msg, line, col=None):
        """Record a warning about a line (the Evolver warns and goes on)."""
        self.scene.warnings.append((msg, line, col))

    def _unknown_words(self, etype, eid, items, qnames, srcline):
        """Edge, face and body lines: an unknown word is skipped with a warning
        (REF: WARNING 2110 / 2115 / 2119 "Unexpected token", the rest of the
        line is read); on a vertex line it is an error (REF: DATAFILE ERROR)."""
        sc = self.scene
        named = self._named_ids()
        keep = []
        text = getattr(self, "_cur_line", "")
        for it in items:
            col = getattr(it, "column", None)
            if isinstance(it, N.Var) and col and col >= 2 and col - 2 < len(text) and \
                    text[col - 2] in " \t" and not (
                    it.name in sc.parameters or it.name in N.CONSTANTS or it.name in named
                    or it.name in qnames or (etype, it.name) in sc.attributes):
                self.warn(f"{etype} {eid}: unexpected word '{it.name}' (ignored)",
                          srcline, it.column)
                continue
            keep.append(it)
        return keep

    def _element(self, kind, block, eid, items, srcline):
        sc = self.scene
        etype = {"vertices": "vertex", "edges": "edge", "faces": "facet", "bodies": "body"}[kind]
        qnames = set(sc.quantities) | set(sc.method_instances)
        if etype != "vertex" and any(isinstance(it, N.Var) for it in items):
            items = self._unknown_words(etype, eid, items, qnames, srcline)
        attrs = []
        i = 0
        n = len(items)
        # leading data expressions
        while i < n:
            it = items[i]
            if isinstance(it, float):
                i += 1
                continue
            if isinstance(it, tuple):
                break
            if isinstance(it, N.Var) and (it.name in qnames or (etype, it.name) in sc.attributes):
                break
            i += 1
        data = items[:i]
        while i < n:
            it = items[i]
            i += 1
            if isinstance(it, tuple) and it[0] == "kw":
                kw = it[1]
                args = []
                while i < n and not isinstance(items[i], tuple) and not (
                        isinstance(items[i], N.Var) and (items[i].name in qnames or
                                                         (etype, items[i].name) in sc.attributes)):
                    args.append(items[i])
                    i += 1
                attrs.append((kw, args, it[2]))
            elif isinstance(it, tuple) and it[0] == "name_neg":
                if it[1] not in qnames:
                    raise self.error(f"'{it[1]}-' is not a quantity or method instance",
                                     srcline, it[2])
                attrs.append(("quantity", [it[1], -1], it[2]))
            elif isinstance(it, N.Var) and it.name in qnames:
                attrs.append(("quantity", [it.name, 1], it.column))
            elif isinstance(it, N.Var) and (etype, it.name) in sc.attributes:
                size = sc.attributes[(etype, it.name)][1]
                vals = items[i:i + size]
                i += size
                attrs.append(("attribute", [it.name] + vals, it.column))
            else:
                col = getattr(it, "column", None)
                raise self.error(f"unexpected value after the attributes of {etype} {eid}",
                                 srcline, col)
        # evaluate
        try:
            values = [self._value(e, srcline, f"{etype} {eid}") for e in data]
        except _LocatedName as exc:
            raise self._undefined(exc, srcline) from None
        if not 1 <= eid <= MAX_ID:
            raise self.error(f"{etype} id {eid} is out of range (ids are 1 to {MAX_ID})",
                             srcline, 1)
        if kind == "vertices" and len(values) < sc.space_dimension and values and \
                not any(kw == "boundary" for kw, _, _ in attrs):
            # REF: WARNING 1127 "Wrong number of coordinates", the rest are 0
            self.warn(f"wrong number of coordinates for vertex {eid}: "
                      f"{len(values)} instead of {sc.space_dimension} (the rest are 0)", srcline)
            values = values + [0.0] * (sc.space_dimension - len(values))
        if kind == "vertices":
            for v in values:
                if not math.isfinite(v):
                    raise self.error(f"vertex {eid}: coordinate {v:g} is not a finite number",
                                     srcline)
        else:
            for v in values:
                if not (math.isfinite(v) and v == int(v)):
                    raise self.error(f"expected an integer id in {etype} {eid}, got {v:g}", srcline)
                if abs(v) > MAX_ID:
                    raise self.error(f"{etype} {eid}: id {v:.0f} is out of range (ids are 1 to "
                                     f"{MAX_ID})", srcline)
            if kind == "faces" and len(values) > MAX_FACE_EDGES:
                raise self.error(f"face {eid} has {len(values)} edges; at most "
                                 f"{MAX_FACE_EDGES} are allowed", srcline)
            values = [int(v) for v in values]
        cooked = []
        for kw, args, col in attrs:
            if kw == "quantity":
                cooked.append((kw, args))
                continue
            vals = []
            for a in (args[1:] if kw == "attribute" else args):
                what = args[0] if kw == "attribute" else f"{kw} of {etype} {eid}"
                try:
                    vals.append(self._value(a, srcline, what))
                except _LocatedName as exc:
                    raise self._undefined(exc, srcline) from None
            if kw == "attribute":
                cooked.append((kw, [args[0]] + vals))
            else:
                self._check_kw_args(kw, vals, etype, eid, srcline, col)
                cooked.append((kw, vals))
        block.ids.append(eid)
        block.data.append(values)
        block.lines.append(srcline)
        if cooked:
            block.attrs[len(block.ids) - 1] = cooked

    def _check_kw_args(self, kw, vals, etype, eid, srcline, col):
        """An attribute keyword's values: present, finite, integers where ids."""
        if kw in _KW_NEEDS_VALUE and not vals:
            raise self.error(f"{etype} {eid}: '{kw}' needs a value", srcline, col)
        for v in vals:
            if not math.isfinite(v):
                raise self.error(f"{etype} {eid}: the value of '{kw}' is not a finite number",
                                 srcline, col)
            if kw in _KW_INTEGER and (v != int(v) or abs(v) > MAX_ID):
                raise self.error(f"{etype} {eid}: '{kw}' needs an integer, got {v:g}",
                                 srcline, col)

    def _value(self, expr, line, what):
        if isinstance(expr, float):
            return expr
        if isinstance(expr, N.Num):
            return expr.value
        for name in expr.names():
            if name not in self.scene.parameters and name not in N.CONSTANTS and \
                    name not in self._named_ids():
                col = None
                for node in _walk(expr):
                    if isinstance(node, N.Var) and node.name == name:
                        col = node.column
                raise _LocatedName(name, line, col)
        return self._const(expr, line, what)


# element keywords that take a value, and those whose values are integers
_KW_NEEDS_VALUE = {"constraint", "constraints", "boundary", "tension", "density", "volume",
                   "volconst", "pressure", "color", "colour", "frontcolor", "frontcolour",
                   "backcolor", "backcolour", "original", "opacity", "phase", "tag",
                   "orientation", "lagrange_multiplier", "actual_volume"}
_KW_INTEGER = {"constraint", "constraints", "boundary", "color", "colour", "frontcolor",
               "frontcolour", "backcolor", "backcolour", "original", "phase", "tag"}


# a stand-alone procedure or function of the top section: its keyword, (type),
# name and opening parenthesis
# (a stand-alone function has a return type: "function qwerty^3" and
# "function sin(x)" are quantity FUNCTION expressions)
_PROC_START = re.compile(
    r"\b(procedure(?=\s+[A-Za-z_]\w*\s*\()|function(?=\s+(?:real|integer|string|"
    r"vertex_type|edge_type|facet_type|body_type|facetedge_type|element_id)\s+"
    r"[A-Za-z_]\w*\s*\())\s+(?:\w+\s+)?[A-Za-z_]\w*\s*\(", re.I)


# define ... attribute name type [dims] FUNCTION { ... }
_ATTR_FUNCTION = re.compile(r"\battribute\s+\w+\s+\w+(?:\s*\[[^\]\n]*\])*\s+(function)\s*\{",
                            re.I)


def _balanced_end(text, i, open_, close):
    """The index after the ``close`` that balances the ``open_`` at
    ``text[i]`` (strings skipped), or None when it never balances."""
    depth = 0
    n = len(text)
    while i < n:
        c = text[i]
        if c == open_:
            depth += 1
        elif c == close:
            depth -= 1
            if depth == 0:
                return i + 1
        elif c == '"':
            i = _skip_string(text, i)
        i += 1
    return None


def _proc_end(text, k):
    """The end of a declaration whose parameter list opens at ``text[k]``:
    after ``)`` and a ``;``, or after the ``{...}`` body (strings skipped);
    None when the parentheses or braces do not balance."""
    i = _balanced_end(text, k, "(", ")")
    if i is None:
        return None
    n = len(text)
    while i < n and text[i] in " \t\n":
        i += 1
    if i < n and text[i] == ";":
        return i + 1
    if i >= n or text[i] != "{":
        return i                    # a declaration without ';'
    return _balanced_end(text, i, "{", "}")


def _skip_string(text, i):
    j = i + 1
    while j < len(text) and text[j] != '"':
        if text[j] == "\\":
            j += 1
        j += 1
    return j


_COLOR_TOK = re.compile(r"\s*(?:colou?r\s+[A-Za-z_]\w*|colou?r\s+[-+]?\d+|swap_colors)\b", re.I)


def _skip_transforms(text, pos, sd):
    """The end of VIEW_TRANSFORMS / VIEW_TRANSFORM_GENERATORS data from
    ``pos``: the count, then that many matrices of numbers, each after an
    optional ``COLOR c`` or ``SWAP_COLORS`` (graphics only)."""
    mm = _NUMTOK_RE.match(text, pos)
    if not mm:
        return pos
    n = int(float(mm.group(1)))
    pos = mm.end()
    for _ in range(max(n, 0)):
        cm = _COLOR_TOK.match(text, pos)
        if cm:
            pos = cm.end()
        for _ in range((sd + 1) ** 2):
            mm = _NUMTOK_RE.match(text, pos)
            if not mm:
                return pos
            pos = mm.end()
    return pos


_ETYPE = {"vertices": "vertex", "edges": "edge", "facets": "facet", "face": "facet",
          "faces": "facet", "bodies": "body"}


def _binary_minus_in_parens(line):
    """Inside parentheses a '-' after a space is a subtraction (REF reads
    ``1 (2 -3) 4`` as 1, -1, 4), unless a comma or an operator comes before it
    (``atan2(y, -x)``): the space before such a '-' becomes \\x1a, which the
    element grammar ignores, so that the '-' is not a new value's sign."""
    out = list(line)
    depth = 0
    for i, c in enumerate(line):
        if c == "(":
            depth += 1
        elif c == ")":
            depth = max(depth - 1, 0)
        elif c == "-" and depth and i and line[i - 1] in " \t":
            j = i - 1
            while j >= 0 and line[j] in " \t":
                j -= 1
            if j >= 0 and (line[j].isalnum() or line[j] in "_.)"):
                out[i - 1] = "\x1a"
    return "".join(out)


def _lowest_free(table, names, also=None):
    k = 1
    while k in table or k in names or k == also:
        k += 1
    return k
# the integer types of ``define ... attribute`` (the Evolver's dump writes them)
_INT_ATTR_TYPES = {"integer", "uchar", "char", "uint", "ulong_int", "short_int", "ushort_int",
                   "long_int"}


_ARRAY_TOKEN = re.compile(r'[{}]|"(?:\\.|[^"\\\n])*"|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?')


class _MatrixError(Exception):
    pass


class _LocatedName(Exception):
    def __init__(self, name, line, col):
        super().__init__(name)
        self.name = name
        self.line = line
        self.col = col


def _walk(node):
    yield node
    for c in node.children():
        yield from _walk(c)


_TERMINAL_NAMES = {
    "NUMBER": "a number", "NAME": "a name", "INT": "an integer", "MINUS": "'-'",
    "PLUS": "'+'", "LPAR": "'('", "RPAR": "')'", "FORMULA_KW": "FORMULA",
    "COMPKW": "a component such as E1: or X1:", "EQUAL": "'='",
    "BRACED_NUMBERS": "numbers in braces { ... }", "ARRAY_INIT": "values in braces { ... }",
    "DUMP_FLAG_KW": "RUNGE_KUTTA", "SLICE_COEFF_KW": "slice_coeff",
}


def _expected(exp):
    names = []
    for e in sorted(exp):
        if e.startswith("__") or e in ("LIST_NEG", "LIST_PLUS", "ON_NEVER", "NAME_NEG"):
            continue
        names.append(_TERMINAL_NAMES.get(e, e.replace("_KW", "").lower()))
    if not names:
        return "something else"
    if len(names) > 6:
        names = names[:6] + ["..."]
    return ", ".join(names)


def read_datafile(filename, text=None):
    """Read a datafile into a :class:`Scene` (raises :class:`DatafileError`)."""
    try:
        return Reader(filename, text).read()
    except OSError as exc:
        raise DatafileError(f"cannot read datafile: {exc.strerror}", filename) from None
