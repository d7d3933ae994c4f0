"""Direct tests of pyevolver.commands.nodes: the expression nodes of the
command language (element index, attributes, aggregates, arrays, sprintf),
built by the parser and evaluated on the cube, against the reference."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.commands.nodes import (Aggregate, ArrayLit, ArrayRef, Attr, ElemIndex, OnTest,
                                      Sprintf)
from pyevolver.commands.parser import parse_command
from pyevolver.commands.values import ElemRef, Generator
from pyevolver.errors import CommandError, ExpressionError
from pyevolver.expr import nodes as N

from reference import run_reference

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def session():
    return Session.load(CUBE, out=io.StringIO(), err=io.StringIO())


def expr(text):
    st = parse_command("print " + text)[1][0]
    assert st[0] == "print"
    return st[1]


EXPRS = [("vertex[2.9].id", Attr), ("sum(facet, area)", Aggregate),
         ("count(vertex where z > 0.5, 1)", Aggregate), ("max(edge, length)", Aggregate),
         ("min(vertex, x+y)", Aggregate), ("avg(facet, area)", Aggregate),
         ("vertex[3].x", Attr), ("facet[2].area", Attr), ("body[1].volume", Attr)]


def test_nodes_evaluate_as_the_evolver(evolver):
    ref = [float(l) for l in run_reference(evolver, CUBE,
                                           "\n".join("print " + e for e, _ in EXPRS))
           if l.strip()]
    assert len(ref) == len(EXPRS)
    s = session()
    for (text, cls), want in zip(EXPRS, ref):
        node = expr(text)
        assert isinstance(node, cls), text
        assert float(s.interp.value(node)) == pytest.approx(want, rel=1e-12, abs=1e-14), text


def test_element_index_and_generator():
    s = session()
    node = ElemIndex("vertices", N.Num(3.0))
    assert node.kind == "vertex"
    ref = node.ev(s.interp.env)
    assert isinstance(ref, ElemRef) and ref.kind == "vertex" and ref.i == 2
    assert repr(ref) == "vertex[3]"
    with pytest.raises(CommandError, match="element or quantity is not a value"):
        s.interp.value(node)
    with pytest.raises((CommandError, ExpressionError)):
        ElemIndex("vertex", N.Num(1000.0)).ev(s.interp.env)
    # an aggregate over no elements: REF's max -1e38, sum 0
    empty = Generator(("all", "vertex"), None, expr("0 > 1"))
    assert s.interp.value(Aggregate("max", empty, N.Num(1.0))) == -1e38
    assert s.interp.value(Aggregate("sum", empty, N.Num(1.0))) == 0.0
    assert s.interp.value(Aggregate("count", Generator(("all", "facet")), N.Num(1.0))) \
        == s.surface.nf


def test_arrays_and_sprintf():
    s = session()
    s.run("define aa real[3]; aa[1] := 1; aa[2] := 2")
    node = expr("aa[2]")
    assert isinstance(node, ArrayRef) and s.interp.value(node) == 2.0
    lit = ArrayLit([N.Num(1.0), N.Num(2.0)])
    assert np.array_equal(np.asarray(s.interp.value(lit)), [1.0, 2.0])
    with pytest.raises(ExpressionError, match="differ in length"):
        s.interp.value(ArrayLit([[N.Num(1.0)], [N.Num(1.0), N.Num(2.0)]]))
    sp = expr('sprintf("%g-%03d", 1.5, 7)')
    assert isinstance(sp, Sprintf) and s.interp.value(sp) == "1.5-007"
    with pytest.raises(ExpressionError, match="format string first"):
        s.interp.value(Sprintf([N.Num(1.0)]))


def test_on_test_needs_an_element():
    s = session()
    with pytest.raises((ExpressionError, CommandError), match="needs an element"):
        s.interp.value(OnTest("on_constraint", N.Num(1.0)))
