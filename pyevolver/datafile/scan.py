"""Text scanning of datafiles around the grammars.

Regular expressions and small scanners shared by the top-section and
element-section readers: malformed numbers, lines of plain numbers (the fast
path), stand-alone procedures of the top section, the matrices after PERIODS /
VIEW_* keywords, and the rules for element keywords' values.
"""
from __future__ import annotations

import re

import numpy as np

from .table import floats_of

# numbers with two decimal points or an exponent without digits.  Every
# digit run is taken whole (``(?=(\d+))\1`` is an atomic group, which Python
# before 3.11 lacks), so a long digit run that fails cannot backtrack: the
# search is linear in the text (a 200,000-digit number is checked at once)
_BAD_NUMBER = re.compile(r"(?<![\w.])(?:(?=(\d*))\1\.(?=(\d*))\2\.[\d.]*"
                         r"|(?=(\d+))\3(?:\.(?=(\d*))\4)?[eEdD][+-]?(?![\d+-]))")

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

    def start(self):
        return self._end


_LETTER = np.zeros(256, bool)
_LETTER[np.frombuffer(b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_", np.uint8)] = True
_EXP = np.zeros(256, bool)
_EXP[np.frombuffer(b"DdEe", np.uint8)] = True
_DIGIT_DOT = np.zeros(256, bool)
_DIGIT_DOT[np.frombuffer(b"0123456789.", np.uint8)] = True


def _first_word(line):
    """``_FIRST_WORD.search(line)`` (its ``start()``), with array operations
    on a long ASCII line (a body's list of 81,920 facets: 1 ms, not 30)."""
    if not line.isascii():
        return _FIRST_WORD.search(line)
    b = np.frombuffer(line.encode("ascii"), np.uint8)
    idx = np.flatnonzero(_LETTER[b])
    if len(idx):
        after_number = np.zeros(len(idx), bool)
        inner = idx > 0
        after_number[inner] = _DIGIT_DOT[b[idx[inner] - 1]]
        word = ~_EXP[b[idx]] | ~after_number
        hit = np.flatnonzero(word)
        if len(hit):
            return _Head(int(idx[hit[0]]))      # (its start() and end(): the position)
    return None


def _long_numeric(line):
    """For a long line: ``("all", None)`` if it is plain numbers, ``("head",
    m)`` if plain numbers are followed by a word, else ``(None, None)``."""
    m = _first_word(line)
    end = m.start() if m else len(line)
    head = line[:end]
    if not _NUM_CHARS.fullmatch(head) or (m and end and not line[end - 1].isspace()):
        return None, None
    if "+" in head and re.search(r"(?:^|[ \t])\+", head):
        return None, None               # '+3' after a space: an addition
    if not head.split() or not head.split(None, 1)[0].isdigit():
        return None, None               # the element id: digits ('1e308' is not one)
    try:
        vals = floats_of(head)
    except ValueError:                  # '1-2', '--3': not plain numbers
        return None, None
    if (vals.size != len(head.split()) or not vals.size or not np.isfinite(vals[0])
            or vals[0] != int(vals[0])):        # (an id of 309 digits and more is inf)
        return None, None
    return ("all", None) if m is None else ("head", _Head(len(head.rstrip())))



_SPACE_DIM_RE = re.compile(r"^[ \t]*space_dimension[ \t:]+(\d+)", re.I | re.M)
_MATRIX_RE = re.compile(r"\b(torus_periods|periods|metric|view_matrix|view_transforms|"
                        r"view_transform_generators)\b", re.I)
_NUMTOK_RE = re.compile(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?)(?=\s|$)")


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
