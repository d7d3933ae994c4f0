"""pyevolver.datafile.grammar: the LALR parsers of the top section and of
one element line, and their transformers (trees -> declaration tuples and
element items)."""
from __future__ import annotations

import math

import pytest
from lark.exceptions import UnexpectedInput

from pyevolver.datafile.grammar import _LINE, _TOP, _cid, line_parser, top_parser
from pyevolver.datafile.located import _Unsupported
from pyevolver.expr import nodes as N


def top(text):
    return _TOP.transform(top_parser().parse(text, start="start"))


def line(text, start):
    return _LINE.transform(line_parser().parse(text, start=start))


def ev(expr, **env):
    return expr.ev(N.MapEnv(env))


def test_parameters_and_constraint_level_sets():
    decls = top("parameter a = 3*2\nparameter b 1/4\n"
                "constraint 1 nonnegative formula: x^2 + y^2 = a\n"
                "constraint top formula: z\n")
    kinds = [d[0] for d in decls]
    assert kinds == ["parameter", "parameter", "constraint", "constraint"]
    (_, a, ea, la), (_, b, eb, lb) = decls[0], decls[1]
    assert (a, la, b, lb) == ("a", 1, "b", 2)
    assert ev(ea) == 6.0 and ev(eb) == 0.25
    _, cid, opts, phi, blocks, cline = decls[2]
    assert cid == 1 and cline == 3 and "nonnegative" in opts and blocks == []
    # 'lhs = rhs' becomes lhs - rhs: zero on the level set
    assert ev(phi, x=2.0, y=math.sqrt(2.0), a=6.0) == pytest.approx(0.0, abs=1e-15)
    assert ev(phi, x=1.0, y=1.0, a=6.0) == -4.0
    # a constraint named instead of numbered: its name, lower case
    assert decls[3][1] == "top" and ev(decls[3][3], z=0.5) == 0.5


def test_constraint_integrals_boundary_and_quantity():
    decls = top("constraint 2 formula: z = 0\nenergy:\ne1: -y/2\ne2: x/2\ne3: 0\n"
                "boundary 1 parameters 1 convex\nx1: cos(p1)\nx2: sin(p1)\nx3: 0\n"
                "quantity vol fixed = 4*pi/3 method facet_volume global\n"
                "define faces attribute w real[2][3]\n")
    c, b, q, attr = decls
    energy = dict(c[4][0][1])
    assert c[4][0][0] == "energy" and set(energy) == {"e1", "e2", "e3"}
    assert ev(energy["e1"], y=4.0) == -2.0 and ev(energy["e2"], x=4.0) == 2.0
    _, bid, npar, bopts, comps, _, bline = b
    assert (bid, npar, bopts, bline) == (1, 1, ["convex"], 6)
    comps = dict(comps)
    t = 0.7
    assert ev(comps["x1"], p1=t) ** 2 + ev(comps["x2"], p1=t) ** 2 == pytest.approx(1.0)
    _, qname, kind, rest, _ = q
    assert qname == "vol" and kind[:2] == ("kind", "fixed")
    assert ev(kind[2]) == pytest.approx(4 * math.pi / 3, rel=1e-15)
    assert rest == [("method", "facet_volume", False, [("global", None)])]
    # the plural and 'face' forms name the facet type; dimensions kept as expressions
    _, etype, name, atype, dims, _ = attr
    assert (etype, name, atype) == ("facet", "w", "real") and [ev(d) for d in dims] == [2, 3]


def test_unsupported_keyword_is_refused_by_the_lexer():
    with pytest.raises(_Unsupported) as exc:
        top_parser().parse("parameter a = 1\n  lagrange_order\n", start="start")
    tok = exc.value.args[0]
    assert str(tok).lower() == "lagrange_order" and (tok.line, tok.column) == (2, 3)


def test_element_lines():
    eid, items = line("3 1 -2.5 0 fixed constraint 1", "vertex_line")
    assert eid == 3
    assert [ev(e) for e in items[:3]] == [1.0, -2.5, 0.0]
    assert items[3] == ("kw", "fixed", 12) and items[4] == ("kw", "constraint", 18)
    assert ev(items[5]) == 1.0
    # braced array values are flattened into the line's items
    eid, items = line("1 0 0 0 rc { 1 2 3 }", "vertex_line")
    assert [ev(e) for e in items[:3]] + [ev(e) for e in items[4:]] == [0, 0, 0, 1, 2, 3]
    # an expression value and a negated quantity on a face line
    eid, items = line("2 1 2 -3 tension 2*pi q1-", "face_line")
    assert eid == 2 and [ev(e) for e in items[:3]] == [1.0, 2.0, -3.0]
    assert items[3][:2] == ("kw", "tension") and ev(items[4]) == pytest.approx(2 * math.pi)
    assert items[5] == ("name_neg", "q1", 23)


def test_malformed_element_line_raises_with_its_column():
    with pytest.raises(UnexpectedInput) as exc:
        line_parser().parse("2 2 ) 3", start="edge_line")
    assert exc.value.column == 5


def test_constraint_ids():
    assert _cid("12") == 12 and _cid("Pinned") == "pinned"
