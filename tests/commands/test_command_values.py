"""Direct tests of pyevolver.commands.values: number conversions as C
converts, truth of where conditions, element references, procedures,
generators, control-flow signals."""
import io
import math
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.commands.values import (ElemRef, Generator, Proc, Quit, TimeLimitExceeded, as_float,
                                       as_int, is_true)
from pyevolver.errors import CommandError, ExpressionError

from reference import run_reference

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def test_as_float_and_as_int():
    assert as_float(2) == 2.0 and as_float(np.array([3.5])) == 3.5
    assert as_int(2.9) == 2 and as_int(-2.9) == -2          # toward zero
    with pytest.raises(ExpressionError, match="must be a number"):
        as_float("abc", "the count")
    with pytest.raises(ExpressionError, match="must be a number"):
        as_float(np.zeros(3))
    with pytest.raises(ExpressionError, match="finite"):
        as_int(math.inf)
    with pytest.raises(ExpressionError, match="finite"):
        as_int(math.nan)


def test_is_true():
    assert is_true(1.0) and is_true(-0.5) and not is_true(0.0)
    assert not is_true("yes")                     # a string is false
    assert is_true(np.array([2.0]))
    with pytest.raises(ExpressionError):
        is_true(np.ones(2))


def test_index_truncation_like_the_evolver(evolver):
    """Element indices convert as C does: vertex[2.9] is vertex 2 (REF)."""
    ref = [l.strip() for l in run_reference(evolver, CUBE, "print vertex[2.9].id\n")
           if l.strip()]
    assert ref == [str(as_int(2.9))]
    s = Session.load(CUBE, out=io.StringIO(), err=io.StringIO())
    assert s.value("vertex[2.9].id") == float(ref[0])


def test_references_and_generators():
    r = ElemRef("edge", 4, -1)
    assert (r.kind, r.i, r.sign) == ("edge", 4, -1) and repr(r) == "edge[5]"
    assert Generator(("all", "facet")).kind == "facet"
    assert Generator(("index", "vertex", None)).kind == "vertex"
    assert Generator(("sub", ("all", "vertex"), "edge", None)).kind == "edge"
    assert Generator(("var", "ff")).kind is None
    p = Proc("pp", [("real", "a")], ("seq", []))
    assert p._nested() == (("seq", []),) and not p.function
    assert Quit(3).code == 3 and issubclass(TimeLimitExceeded, CommandError)
