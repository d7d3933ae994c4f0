"""Formulas that know their declaration: errors name it and its source line."""
from __future__ import annotations

import contextlib
from collections.abc import Iterator

from ..errors import PyEvolverError


class Integrand(tuple):
    """The components of a constraint's or boundary's ENERGY or CONTENT
    integrand (a tuple of formulas) with the name and source line of their
    declaration, for the messages of :func:`located`."""

    def __new__(cls, comps, what, line):
        self = super().__new__(cls, comps)
        self.what, self.line = what, line
        return self


class LocatedFormula:
    """A formula whose evaluation errors name its declaration ``what`` and
    source ``line`` (see :func:`located`)."""

    def __init__(self, formula, what, line):
        self.formula, self.what, self.line = formula, what, line

    def values(self, *args):
        with located(self.what, self.line):
            return self.formula.values(*args)

    def gradient(self, *args):
        with located(self.what, self.line):
            return self.formula.gradient(*args)

    def hessian(self, *args):
        with located(self.what, self.line):
            return self.formula.hessian(*args)


@contextlib.contextmanager
def located(what: str, line: int | None) -> Iterator[None]:
    """Give an error raised in the block without a source line the
    declaration ``what`` (e.g. ``"constraint 1"``) and its ``line``."""
    try:
        yield
    except PyEvolverError as exc:
        if getattr(exc, "line", None) is None and line:
            exc.line = line
            exc.args = (f"{what}: {exc}",)
        raise

