"""Located errors of the datafile reader: the exceptions raised inside the
scanners and transformers, which the reader turns into a
:class:`~pyevolver.errors.DatafileError` with the source line and column, and
the wording of a parser's "expected ..." list."""
from __future__ import annotations

import functools
import os
import re

from lark.exceptions import UnexpectedCharacters, UnexpectedToken

from ..errors import did_you_mean
from ..limits import clip


class _Unsupported(Exception):
    """A keyword the grammar knows and pyevolver refuses (the token)."""


class _MatrixError(Exception):
    """A PERIODS / VIEW_* matrix with the wrong count: ``(line, message)``."""


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


_TERMINAL_LINE = re.compile(r"^([A-Z][A-Z0-9_]*)(?:\.\d+)?:\s*(.*)$", re.M)


@functools.lru_cache(maxsize=1)
def _keywords() -> dict:
    """``{terminal: keywords it matches}`` of the datafile grammars' keyword
    terminals (the words of their regular expressions; for "did you mean")."""
    out: dict = {}
    here = os.path.dirname(os.path.abspath(__file__))
    for name in ("fe_top.lark", "fe_elements.lark"):
        try:
            with open(os.path.join(here, name), encoding="utf-8") as fh:
                text = fh.read()
        except OSError:
            continue
        for term, pattern in _TERMINAL_LINE.findall(text):
            words = re.findall(r"(?<![\\\w])[a-z][a-z0-9_]{2,}", pattern.replace("\\b", " "))
            out.setdefault(term, set()).update(words)
    return out


def describe(exc: Exception, text: str) -> str:
    """The message for a parse error ``exc`` of ``text`` (without location)."""
    if isinstance(exc, UnexpectedCharacters):
        ch = text[exc.pos_in_stream] if exc.pos_in_stream < len(text) else ""
        word = re.match(r"[A-Za-z_]\w*", text[exc.pos_in_stream:])
        if word:
            return (f"unexpected '{clip(word.group(0))}': not a keyword, parameter or "
                    f"value allowed here")
        return f"unexpected character {ch!r}"
    if isinstance(exc, UnexpectedToken):
        tok = exc.token
        if tok.type == "$END":
            exp = _expected(exc.expected)
            return f"unexpected end of line: expected {exp}"
        exp = _expected(exc.expected)
        words = [w for e in exc.expected for w in _keywords().get(e, ())]
        hint = did_you_mean(str(tok), words) if re.fullmatch(r"[A-Za-z_]\w*", str(tok)) else ""
        return f"unexpected '{clip(tok)}': expected {exp}{hint}"
    return str(exc).split("\n")[0]
