"""Lexical preprocessing of a datafile (spec §1).

Line endings (LF, CRLF, CR) are normalised, comments are blanked (keeping
line and column positions), spliced lines are joined, ``#define`` macros are
expanded on whole tokens (rescanned) and ``#include`` files are inserted.
The result is split into the top section, the element sections and the
``read`` section, each with the source line number of its first line.
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field

from ..errors import DatafileError
from ..limits import MAX_EXPANDED_LINE

_COMMENT_RE = re.compile(r'"(?:\\.|[^"\\\n])*"|/\*.*?\*/|//[^\n]*', re.S)
_SECTION_RE = re.compile(
    r"^[ \t]*(vertices|edges|faces|facets|bodies|read"
    r"|vertex|edge|face|facet|body)\b[ \t]*:?", re.I | re.M)
# singular section keywords (REF accepts vertex/edge/face/facet/body too)
_SECTION_KIND = {"vertex": "vertices", "edge": "edges", "face": "faces", "facet": "faces",
                 "facets": "faces", "body": "bodies"}
_IDENT_RE = re.compile(r'"(?:\\.|[^"\\\n])*"|[A-Za-z_][A-Za-z0-9_]*')
_DIRECTIVE_RE = re.compile(r"^[ \t]*#[ \t]*(define|include)\b(.*)$", re.I | re.M)
# lines after the first that start with a letter: the candidates for a
# section keyword (a literal first character, "\n", which re searches fast;
# a large file's 7 MB of numbers in about 15 ms instead of a tenth of a second)
_LETTER_LINE_RE = re.compile(r"\n[ \t]*[A-Za-z]")


class _SectionMatch:
    """What _SECTION_RE's match gives: start, end and the keyword."""

    __slots__ = ("_start", "_end", "_kw")

    def __init__(self, start, end, kw):
        self._start, self._end, self._kw = start, end, kw

    def start(self):
        return self._start

    def end(self):
        return self._end

    def group(self, k):
        return self._kw


def _section_matches(text):
    """The matches of ``_SECTION_RE.finditer(text)``, found faster."""
    m = _SECTION_RE.match(text)
    pos = 0
    if m:
        yield _SectionMatch(m.start(), m.end(), m.group(1))
        pos = m.end()
    while True:
        c = _LETTER_LINE_RE.search(text, pos)
        if c is None:
            return
        m = _SECTION_RE.match(text, c.start() + 1)
        if m:
            yield _SectionMatch(m.start(), m.end(), m.group(1))
            pos = m.end()
        else:
            pos = c.end()


@dataclass
class Section:
    """A part of the datafile: its kind, text and first source line."""

    kind: str
    text: str
    line: int
    lines: list = field(default_factory=list)  # source line of each text line
    warnings: list = field(default_factory=list)  # (source line, message)


def normalise_newlines(text: str) -> str:
    """LF line endings (CRLF and CR become LF) and no DOS end-of-file
    character (``\\x1a`` becomes a space)."""
    if "\r" in text:
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    if "\x1a" in text:
        text = text.replace("\x1a", " ")
    return text


def blank_comments(text: str, filename: str) -> str:
    """Replace ``//`` and ``/* */`` comments by spaces, keeping newlines
    (lines and columns are kept); strings are left alone.

    Raises
    ------
    DatafileError
        At an unterminated ``/*``.
    """
    if "/" not in text:
        return text

    def repl(m):
        s = m.group(0)
        if s[0] == '"':
            return s
        return re.sub(r"[^\n]", " ", s)

    # no comment starts before the first '/' or '"' nor after the line of
    # the last '/' (strings and // comments end at their line's end, a
    # closed /* */ at a '/'): the scan runs between (a large file's tables)
    lo = min(k for k in (text.find("/"), text.find('"'), len(text)) if k >= 0)
    lo = text.rfind("\n", 0, lo) + 1
    hi = text.find("\n", text.rfind("/"))
    hi = len(text) if hi < 0 else hi
    out = text[:lo] + _COMMENT_RE.sub(repl, text[lo:hi]) + text[hi:] \
        if lo or hi < len(text) else _COMMENT_RE.sub(repl, text)
    k = out.find("/*")
    if k >= 0:
        # check it is not inside a string
        for m in re.finditer(r'"(?:\\.|[^"\\\n])*"|/\*', out):
            if m.group(0) == "/*":
                line = out.count("\n", 0, m.start()) + 1
                col = m.start() - (out.rfind("\n", 0, m.start()) + 1) + 1
                raise DatafileError("unterminated comment: '/*' has no closing '*/'",
                                    filename, line, col, text.split("\n")[line - 1])
    return out


def read_source(path: str) -> str:
    """The text of the file ``path``, decoded as Latin-1 (any byte reads)."""
    with open(path, "rb") as fh:
        data = fh.read()
    return data.decode("latin-1")


def preprocess(text: str, filename: str = "<datafile>",
               include_depth: int = 0) -> tuple[list[Section], dict[str, str]]:
    """Split a datafile's text into sections, macros expanded.

    Parameters
    ----------
    text : str
        The datafile's text.
    filename : str
        Its name, for messages and to find ``#include`` files beside it.
    include_depth : int
        How deep in ``#include`` files this text is.

    Returns
    -------
    sections : list of Section
        The first is always the top section (kind ``"top"``); element
        sections follow in file order, and ``read`` (raw command text, its
        ``#include`` and ``#define`` lines handled) comes last if present.
    macros : dict
        The ``#define`` macros, name -> replacement text.

    Raises
    ------
    DatafileError
        An unterminated comment, a bad directive or a missing include file.
    """
    text = normalise_newlines(text)
    clean = blank_comments(text, filename)
    # find the read section first: macros do not apply after it
    read_text = None
    read_line = None
    m_read = None
    for m in _section_matches(clean):
        if m.group(1).lower() == "read":
            m_read = m
            break
    if m_read is not None:
        read_line = clean.count("\n", 0, m_read.start()) + 1
        read_text = text[m_read.end():]      # raw: the command lexer handles comments
        clean = clean[:m_read.start()]
    src_lines = None
    if "\\\n" in clean:
        clean, src_lines = _splice(clean)
    macros = {}
    if "#" in clean:
        clean, src_lines = _directives(clean, filename, macros, src_lines, include_depth)
    sections = _split(clean, src_lines)
    if read_text is not None:
        keep = _KEEP_MACROS_RE.search(clean) is not None
        read_text, warnings = _read_directives(read_text, read_line, filename, macros,
                                               keep)
        sections.append(Section("read", read_text, read_line, warnings=warnings))
    return sections, macros


_KEEP_MACROS_RE = re.compile(r"^[ \t]*keep_macros\b", re.I | re.M)


def _read_directives(text, first_line, filename, macros, keep_macros):
    """``#include`` and ``#define`` lines of the read section.

    ``#include "f"`` becomes ``read "path"`` (the file found as for the top
    section: the current directory, the datafile's directory, EVOLVERPATH),
    so its commands run in place.  ``#define`` draws the Evolver's warning
    2853 ("valid only in top of datafile"); with ``keep_macros`` it still
    defines the macro, and the top section's macros are expanded in the
    read section, as in the Evolver.  Lines keep their numbers.
    """
    if "#" not in text and not (keep_macros and macros):
        return text, []
    warnings = []
    lines = text.split("\n")
    for k, line in enumerate(lines):
        m = _DIRECTIVE_RE.match(line)
        if m and m.group(1).lower() == "include":
            mm = re.match(r'\s*"([^"]*)"', m.group(2))
            if mm:
                inc = _find_include(mm.group(1), filename)
                path = os.path.abspath(inc) if inc else mm.group(1)
                lines[k] = 'read "' + path.replace("\\", "\\\\").replace('"', '\\"') + '"'
            continue
        if m:
            warnings.append((first_line + k,
                             "WARNING 2853: #define valid only in top of datafile."))
            mm = re.match(r"\s*([A-Za-z_][A-Za-z0-9_]*)(.*)$", m.group(2))
            if keep_macros and mm:
                macros[mm.group(1)] = mm.group(2).strip()[:500]
            lines[k] = ""
            continue
        if keep_macros and macros:
            try:
                lines[k] = expand_macros(line, macros)
            except _TooLong:
                raise DatafileError(f"#define macros expand this line beyond "
                                    f"{MAX_EXPANDED_LINE} characters", filename,
                                    first_line + k, 1, line) from None
    return "\n".join(lines), warnings


def _splice(text):
    """Join lines ending in a backslash; returns text and source line map."""
    lines = text.split("\n")
    out, src = [], []
    i = 0
    while i < len(lines):
        start = i + 1
        cur = lines[i]
        while cur.endswith("\\") and i + 1 < len(lines):
            i += 1
            cur = cur[:-1] + " " + lines[i]
        out.append(cur)
        src.append(start)
        i += 1
    return "\n".join(out), src


def _directives(text, filename, macros, src_lines, depth):
    lines = text.split("\n")
    if src_lines is None:
        src_lines = list(range(1, len(lines) + 1))
    out, src = [], []
    for ln, line in zip(src_lines, lines):
        m = _DIRECTIVE_RE.match(line)
        if m:
            kind = m.group(1).lower()
            rest = m.group(2).strip()
            if kind == "define":
                mm = re.match(r"([A-Za-z_][A-Za-z0-9_]*)(.*)$", rest)
                if not mm:
                    raise DatafileError("expected a macro name after #define",
                                        filename, ln, line.find("define") + 7, line)
                macros[mm.group(1)] = mm.group(2).strip()[:500]
                out.append("")
                src.append(ln)
                continue
            # include
            mm = re.match(r'"([^"]*)"', rest)
            if not mm:
                raise DatafileError('expected a quoted file name after #include',
                                    filename, ln, line.find("include") + 8, line)
            if depth >= 10:
                raise DatafileError("#include nested more than 10 deep", filename, ln, 1, line)
            inc = _find_include(mm.group(1), filename)
            if inc is None:
                raise DatafileError(f"cannot open include file '{mm.group(1)}'",
                                    filename, ln, line.find('"') + 1, line)
            inc_text = blank_comments(normalise_newlines(read_source(inc)), inc)
            inc_text, _ = _directives(inc_text, inc, macros, None, depth + 1)
            for l2 in inc_text.split("\n"):
                out.append(l2)
                src.append(ln)
            continue
        if macros:
            try:
                line = expand_macros(line, macros)
            except _TooLong:
                raise DatafileError(f"#define macros expand this line beyond "
                                    f"{MAX_EXPANDED_LINE} characters", filename, ln, 1,
                                    line) from None
        out.append(line)
        src.append(ln)
    return "\n".join(out), src


def _find_include(name, filename):
    cands = [name, os.path.join(os.path.dirname(filename or "."), name)]
    for d in os.environ.get("EVOLVERPATH", "").split(os.pathsep):
        if d:
            cands.append(os.path.join(d, name))
    for c in cands:
        if os.path.isfile(c):
            return c
    return None


class _TooLong(Exception):
    """A line grew beyond :data:`~pyevolver.limits.MAX_EXPANDED_LINE` by macro expansion."""


def expand_macros(line: str, macros: dict[str, str]) -> str:
    """Replace whole tokens that are macro names, rescanning the result.

    Parameters
    ----------
    line : str
        One line (strings in it are left alone).
    macros : dict
        Name -> replacement text.

    Returns
    -------
    str
        The line after at most 100 passes.

    Raises
    ------
    _TooLong
        When the line grows beyond :data:`~pyevolver.limits.MAX_EXPANDED_LINE`
        (macros that double at each level would exhaust memory).
    """
    for _ in range(100):
        if len(line) > MAX_EXPANDED_LINE:
            raise _TooLong()
        changed = False

        def repl(m):
            nonlocal changed
            s = m.group(0)
            if s[0] != '"' and s in macros:
                changed = True
                return macros[s]
            return s

        new = _IDENT_RE.sub(repl, line)
        if not changed:
            return new
        line = new
    return line


def _split(text, src_lines):
    sections = []
    matches = list(_section_matches(text))
    starts = [0] + [m.start() for m in matches]
    kinds = ["top"] + [m.group(1).lower() for m in matches]
    ends = [m.start() for m in matches] + [len(text)]
    bodies = [0] + [m.end() for m in matches]
    for kind, s, b, e in zip(kinds, starts, bodies, ends):
        kind = _SECTION_KIND.get(kind, kind)
        line0 = text.count("\n", 0, s) + 1 if s else 1
        body = text[b:e]
        # the header line's remainder belongs to the section; keep its line
        if src_lines is not None:
            n = body.count("\n") + 1
            lines = src_lines[line0 - 1: line0 - 1 + n]
            sections.append(Section(kind, body, lines[0] if lines else line0, lines))
        else:
            sections.append(Section(kind, body, line0))
    return sections
