"""Datafile reader: text -> :class:`pyevolver.model.scene.Scene`.

The top section and non-trivial element lines are parsed by the LALR
grammars ``fe_top.lark`` and ``fe_elements.lark`` (with the shared expression
grammar); element lines made only of plain numbers take a fast path that
gives the same result.  The work is shared out: :mod:`.preprocess` (macros,
sections), :mod:`.scan` (regular expressions), :mod:`.grammar` (parsers and
transformers), :mod:`.top` (the top section), :mod:`.elements` (the element
sections), :mod:`.located` (located errors).
"""
from __future__ import annotations

import numpy as np

from ..errors import DatafileError, ExpressionError
from ..memory import loading
from ..expr import nodes as N
from ..model.scene import Scene
from .elements import ElementSections
from .grammar import line_parser, top_parser
from .located import _LocatedName, _walk, describe
from .preprocess import preprocess, read_source
from .source_lines import SourceLines
from .top import TopSection

__all__ = ["Reader", "read_datafile", "top_parser", "line_parser"]


class Reader(TopSection, ElementSections):
    """Reads one datafile into a :class:`Scene`.

    Parameters
    ----------
    filename : str
        The datafile's path (the name in messages).
    text : str, optional
        Its text; read from ``filename`` when None.
    """

    def __init__(self, filename: str, text: str | None = None):
        self.filename = filename
        self.text = read_source(filename) if text is None else text
        self.scene = Scene(filename=filename)
        self._src_lines = None
        self._named_forward: set[str] = set()     # names declared ahead ("constraint pinned;")

    @property
    def src_lines(self):
        if self._src_lines is None:
            self._src_lines = SourceLines(self.text)
        return self._src_lines

    # -- errors -----------------------------------------------------------
    def error(self, msg: str, line: int | None, col: int | None = None) -> DatafileError:
        """A :class:`DatafileError` at ``line`` (and ``col``) with the source excerpt."""
        excerpt = self.src_lines[line - 1] if line and 0 < line <= len(self.src_lines) else None
        return DatafileError(msg, self.filename, line, col, excerpt)

    def read(self) -> Scene:
        """The preprocessed sections read in order; returns the scene
        (raises :class:`DatafileError`, located)."""
        self.scene.source_lines = self.src_lines
        sections, self.macros = preprocess(self.text, self.filename)
        top = sections[0]
        self._top(top)
        if "keep_macros" in self.scene.flags:
            self.scene.macros = self.macros     # active at run time too (manual)
        seen: list = []
        for k in range(1, len(sections)):
            sec = sections[k]
            sections[k] = None  # type: ignore[call-overload]  # its text goes once read
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

    def _describe(self, exc, text):
        return describe(exc, text)

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
                    or (name in N.COORD_NAMES[4:] and "x" in allowed
                        and int(name[1:]) <= self.scene.space_dimension)
                    or any(name == a[1] for a in self.scene.attributes)):
                continue
            line = col = None
            for node in _walk(expr):       # a Var, or an indexed name such as a[1]
                if getattr(node, "name", None) == name:
                    line = getattr(node, "line", None)
                    col = getattr(node, "column", None)
                    break
            raise _LocatedName(name, line, col)

    def warn(self, msg: str, line: int | None, col: int | None = None) -> None:
        """Record a warning about a line (the Evolver warns and goes on)."""
        self.scene.warnings.append((msg, line, col))

    def _value(self, expr, line, what):
        if isinstance(expr, float):
            return expr
        if isinstance(expr, N.Num):
            return expr.value
        if not isinstance(expr, N.Node):       # a keyword where a number belongs
            raise self.error(f"{what}: expected a number", line)
        try:
            names = expr.names()
        except RecursionError:
            raise self.error(f"{what}: expression nested too deeply", line) from None
        for name in names:
            if name not in self.scene.parameters and name not in N.CONSTANTS and \
                    name not in self._named_ids():
                col = None
                for node in _walk(expr):
                    if isinstance(node, N.Var) and node.name == name:
                        col = node.column
                raise _LocatedName(name, line, col)
        return self._const(expr, line, what)


@loading
def read_datafile(filename: str, text: str | None = None) -> Scene:
    """Read a datafile into a :class:`~pyevolver.model.scene.Scene`.

    Parameters
    ----------
    filename : str
        The datafile's path (also the name in error messages).
    text : str, optional
        The datafile's text; read from ``filename`` when None.

    Returns
    -------
    Scene
        The declarations and element blocks, not yet built into a surface.

    Raises
    ------
    DatafileError
        With the file, line, column and source excerpt of the first error.
    """
    try:
        return Reader(filename, text).read()
    except OSError as exc:
        raise DatafileError(f"cannot read datafile: {exc.strerror}", filename) from None
