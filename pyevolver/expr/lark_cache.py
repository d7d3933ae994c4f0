"""Start-up: the grammars' LALR parsers kept whole on disk, lexers included.

lark's own cache (``Lark(..., cache=True)``) stores the parse tables, and
loading them rebuilds every state object (about 25 ms for the command
grammar); its contextual lexer then compiles one regular expression per
parser state the input reaches, each an alternation of the terminals that
state accepts (the command grammar has about a hundred distinct sets, 3 ms
each: most of the time of loading ``cube.fe``, whose read section defines
two procedures).

:func:`cached_lark` builds the parser once, compiles every state's scanner,
and pickles the whole :class:`lark.Lark` object into the user's cache folder
(``$PYEVOLVER_CACHE_DIR``, else ``$XDG_CACHE_HOME/pyevolver``, else
``~/.cache/pyevolver``; ``PYEVOLVER_CACHE_DIR=""`` turns the cache off).
A compiled pattern is stored as the program the ``re`` module made of it
and restored by ``_sre.compile``, as ``re.compile`` ends: no parsing of the
pattern again.  Before a pattern is stored in this form, the restored
pattern must compare equal to the original (CPython compares the pattern,
the flags and the compiled code), else it is stored as its text and
compiled again on loading.  The file name is a hash of the grammar, the
options and the versions of Python, ``re`` and lark, so a changed grammar
or an upgrade builds a new file; a file that does not load (truncated,
another format) is ignored and replaced.  Any failure falls back to
``Lark(grammar, **options, cache=True)``, the parser as it was built before.
"""
from __future__ import annotations

import array
import copyreg
import gc
import hashlib
import importlib
import io
import os
import pickle
import re
import sys
import types
from typing import Any, Optional

import _sre
import lark
from lark import Lark
from lark.lexer import Scanner
from lark.parsers import lalr_analysis

try:                                            # Python 3.11 and later
    from re import _compiler as _re_compiler, _parser as _re_parser
except ImportError:                             # pragma: no cover  (3.9, 3.10)
    import sre_compile as _re_compiler          # type: ignore[no-redef]
    import sre_parse as _re_parser              # type: ignore[no-redef]

from ..atomic import atomic_write

#: bump when the stored form changes
FORMAT = 1

_ENV = "PYEVOLVER_CACHE_DIR"


def cache_dir() -> Optional[str]:
    """The folder of the stored parsers, or None when the cache is off."""
    d = os.environ.get(_ENV)
    if d is not None:
        return d or None
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "pyevolver")


def _describe(value: Any) -> str:
    """A stable text of an option's value (functions by qualified name)."""
    if callable(value) and hasattr(value, "__qualname__"):
        return f"{getattr(value, '__module__', '')}.{value.__qualname__}"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k!r}: {_describe(v)}" for k, v in sorted(value.items())) + "}"
    return repr(value)


def cache_key(grammar: str, options: dict) -> str:
    """The hash naming a parser's file."""
    h = hashlib.sha256()
    for part in (str(FORMAT), sys.version, sys.implementation.cache_tag or "",
                 str(getattr(_sre, "MAGIC", "")), lark.__version__, grammar,
                 _describe(options)):
        h.update(part.encode("utf-8", "surrogatepass"))
        h.update(b"\0")
    return h.hexdigest()[:32]


# -- compiled patterns -------------------------------------------------------------------

def _restore_pattern(pattern, flags, code, groups, groupindex, indexgroup):
    """A compiled pattern from the program ``re`` made of it (unpickling)."""
    return _sre.compile(pattern, flags, code.tolist(), groups, groupindex, indexgroup)


def _program(p: re.Pattern):
    """``(pattern, flags, code, groups, groupindex, indexgroup)`` as
    ``re.compile`` hands them to ``_sre.compile``, or None when the restored
    pattern would not equal ``p``."""
    try:
        tree = _re_parser.parse(p.pattern, p.flags)
        code = array.array("I", [int(c) for c in _re_compiler._code(tree, p.flags)])
        state = tree.state
        groupindex = dict(state.groupdict)
        indexgroup = [None] * state.groups
        for k, i in groupindex.items():
            indexgroup[i] = k
        args = (p.pattern, p.flags | state.flags, code, state.groups - 1, groupindex,
                tuple(indexgroup))
        q = _restore_pattern(*args)
    except Exception:               # another Python's internals: store the text
        return None
    if q != p or q.groups != p.groups or dict(q.groupindex) != dict(p.groupindex):
        return None
    return args


def _reduce_pattern(p: re.Pattern):
    args = _program(p)
    if args is None:
        return re.compile, (p.pattern, p.flags)
    return _restore_pattern, args


def _reduce_module(m: types.ModuleType):
    return importlib.import_module, (m.__name__,)


def _reduce_action(a):
    # Shift and Reduce are compared by identity in lark's parser
    return getattr, (lalr_analysis, a.name)


class _LazyScanner:
    """A stored scanner, unpickled when it is first used: a parse reaches
    a fraction of the states (``cube.fe`` 20 of the command grammar's 100),
    so the others cost neither time nor memory.  On the first attribute
    read it becomes the :class:`lark.lexer.Scanner` it stands for."""

    def __init__(self, blob: bytes):
        self._blob = blob

    def __getattr__(self, name: str):
        blob = self.__dict__.pop("_blob", None)
        if blob is None:
            raise AttributeError(name)
        state = pickle.loads(blob)
        self.__dict__.update(state)
        self.__class__ = Scanner        # type: ignore[assignment]
        return getattr(self, name)


def _reduce_scanner(sc):
    buf = io.BytesIO()
    _Pickler(buf, protocol=pickle.HIGHEST_PROTOCOL).dump(dict(sc.__dict__))
    return _LazyScanner, (buf.getvalue(),)


class _Pickler(pickle.Pickler):
    dispatch_table = dict(copyreg.dispatch_table)
    dispatch_table[re.Pattern] = _reduce_pattern
    dispatch_table[types.ModuleType] = _reduce_module
    dispatch_table[lalr_analysis.Action] = _reduce_action
    dispatch_table[Scanner] = _reduce_scanner


def dumps(parser: Lark) -> bytes:
    """The stored form of ``parser`` with all its scanners compiled."""
    lexer = getattr(parser.parser, "lexer", None)
    for sub in set(getattr(lexer, "lexers", {}).values()):
        sub.scanner                             # (compiles it)
    root = getattr(lexer, "root_lexer", None)
    if root is not None:
        root.scanner
    buf = io.BytesIO()
    _Pickler(buf, protocol=pickle.HIGHEST_PROTOCOL).dump(parser)
    return buf.getvalue()


def cached_lark(grammar: str, **options: Any) -> Lark:
    """``Lark(grammar, **options)``, loaded from the cache folder when it
    was stored there before (else built and stored)."""
    folder = cache_dir()
    path = None
    if folder:
        path = os.path.join(folder, f"lark-{cache_key(grammar, options)}.pickle")
        try:
            with open(path, "rb") as fh:
                data = fh.read()
            was = gc.isenabled()
            gc.disable()        # (tens of thousands of new objects: no collections meanwhile)
            try:
                parser = pickle.loads(data)
            finally:
                if was:
                    gc.enable()
            if isinstance(parser, Lark):
                return parser
        except Exception:       # missing, truncated, another format: build it again
            pass
    parser = Lark(grammar, **options, cache=True)
    if path is not None:
        try:
            data = dumps(parser)
            os.makedirs(folder, mode=0o700, exist_ok=True)
            with atomic_write(path, "wb", durable=False) as fh:
                fh.write(data)
        except Exception:       # read-only home, a full disk: no cache
            pass
    return parser
