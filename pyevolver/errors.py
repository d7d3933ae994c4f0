"""One exception hierarchy for pyevolver.

Library code raises these; only the CLI/REPL turns them into messages and
exit codes.
"""
from __future__ import annotations

import difflib
import os
import sys
import traceback


#: The page that lists what is supported and what is refused (every refusal names it).
DOCS_PAGE = "docs/supported.md"
_REFUSAL = "not supported in pyevolver"


def _with_docs(message):
    """A refusal's message with the docs page named (once)."""
    if isinstance(message, str) and _REFUSAL in message and DOCS_PAGE not in message:
        return f"{message}; see {DOCS_PAGE}"
    return message


class PyEvolverError(Exception):
    """Base class of every pyevolver error (a refusal's message names
    :data:`DOCS_PAGE`)."""

    def __init__(self, *args):
        if args:
            args = (_with_docs(args[0]),) + args[1:]
        super().__init__(*args)


class DatafileError(PyEvolverError):
    """A datafile could not be read.

    The message has the form ``FILE:LINE:COL: what was expected``, followed by
    the offending source line when it is known.
    """

    def __init__(self, message, filename=None, line=None, column=None, excerpt=None):
        self.message = message = _with_docs(message)
        self.filename = filename
        self.line = line
        self.column = column
        self.excerpt = excerpt
        super().__init__(self.format())

    def format(self):
        where = self.filename or "<datafile>"
        if self.line is not None:
            where += f":{self.line}"
            if self.column is not None:
                where += f":{self.column}"
        text = f"{where}: {self.message}"
        if self.excerpt:
            line, col = excerpt_window(self.excerpt.rstrip("\n"), self.column)
            text += "\n    " + line
            if col is not None and col >= 1:
                text += "\n    " + " " * (col - 1) + "^"
        return text


def excerpt_window(line: str, column: int | None = None,
                   width: int = 120) -> tuple[str, int | None]:
    """A source line cut to at most ``width`` characters around ``column``
    (1-based; None: the start), control characters shown as ``?``; returns
    ``(text, column in text)``."""
    line = "".join(c if c >= " " or c == "\t" else "?" for c in line)
    if len(line) <= width:
        return line, column
    c = 1 if column is None or column < 1 else min(column, len(line))
    start = max(0, min(c - 1 - width // 2, len(line) - width))
    cut = line[start:start + width]
    pre = "..." if start > 0 else ""
    post = "..." if start + width < len(line) else ""
    return pre + cut + post, (None if column is None else c - start + len(pre))


def did_you_mean(word: str, names) -> str:
    """``"; did you mean 'x'?"`` (or two or three names) for the names
    closest to ``word`` (difflib, case-insensitive), or ``""``."""
    pool = {str(n).lower(): str(n) for n in names if n and str(n) != word}
    close = difflib.get_close_matches(str(word).lower(), list(pool), n=3, cutoff=0.75)
    if not close:
        return ""
    quoted = [f"'{pool[c]}'" for c in close]
    text = quoted[0] if len(quoted) == 1 else ", ".join(quoted[:-1]) + " or " + quoted[-1]
    return f"; did you mean {text}?"


class UnsupportedError(PyEvolverError):
    """An Evolver feature that pyevolver recognises but refuses by name:
    ``not supported in pyevolver: FEATURE (why); see docs/supported.md``."""

    def __init__(self, feature, detail=""):
        self.feature = feature
        msg = f"not supported in pyevolver: {feature}"
        if detail:
            msg += f" ({detail})"
        super().__init__(msg)


def dimension_error(sdim: int, what: str, verb: str = "needs") -> UnsupportedError:
    """The refusal of ``what`` in ``SPACE_DIMENSION sdim`` > 3:
    ``"not supported in pyevolver: SPACE_DIMENSION 5: the Hessian needs 3 dimensions"``."""
    return UnsupportedError(f"SPACE_DIMENSION {sdim}: {what} {verb} 3 dimensions")


class CommandError(PyEvolverError):
    """A command could not be parsed or executed; the surface is unchanged."""


class InternalError(CommandError):
    """A Python exception inside pyevolver (a bug): reported as a message,
    never a traceback, and the surface is left as it was.  With the
    environment variable ``PYEVOLVER_TRACEBACK=1`` the traceback is printed
    to standard error as well."""

    @classmethod
    def from_exception(cls, exc, where):
        if os.environ.get("PYEVOLVER_TRACEBACK"):
            traceback.print_exception(type(exc), exc, exc.__traceback__, file=sys.stderr)
        err = cls(f"{where}: internal error ({type(exc).__name__}: {exc}); the surface "
                  f"is as it was")
        err.original = exc
        return err


class ExpressionError(PyEvolverError):
    """An expression could not be evaluated (unknown name, bad argument)."""


class ConstraintError(PyEvolverError):
    """A constraint projection failed to converge."""


class ConvergenceWarning(UserWarning):
    """An iteration did not converge (e.g. volume restoration)."""
