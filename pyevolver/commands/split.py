"""Cutting input text into complete commands (the Evolver's ``more>``
prompt): braces and parentheses balanced, strings and comments closed, no
trailing operator or ``then``/``else``/``do``.
"""
from __future__ import annotations

import re

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
