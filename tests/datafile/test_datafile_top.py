"""pyevolver.datafile.top: the top section read into the Scene (parameters,
settings, constraints, boundaries, quantities, attributes, arrays, PERIODS,
procedures), through the public reader; the refusals are located."""
from __future__ import annotations

import math

import numpy as np
import pytest

from pyevolver.datafile.reader import Reader, read_datafile
from pyevolver.datafile.top import VALUE_NAMES, TopSection
from pyevolver.errors import DatafileError
from pyevolver.expr import nodes as N
from reference import numbers

VERT = "vertices\n1 0 0 0\n"


def read(top, elements=VERT):
    return read_datafile("top.fe", top + "\n" + elements)


def at(formula, params, **coords):
    """A Formula evaluated at one point."""
    pts = {k: np.array([float(v)]) for k, v in coords.items()}
    return float(formula.values(N.MapEnv(params), pts, 1)[0])


def test_reader_is_a_top_section():
    assert issubclass(Reader, TopSection)
    assert VALUE_NAMES["spring_constant"] == "gap_constant"


def test_parameters_in_order_and_constraint_formulas():
    sc = read("parameter rad = 2\nparameter h = rad/4\n"
              "constraint 1 formula: x^2 + y^2 + z^2 = rad^2\n"
              "constraint 2 nonnegative\nformula: z - h\n"
              "energy:\ne1: 0\ne2: x*h\ne3: 0\n")
    assert sc.parameters == {"rad": 2.0, "h": 0.5}
    c1, c2 = sc.constraints[1], sc.constraints[2]
    assert (c1.line, c2.line) == (3, 4)
    P = sc.parameters
    # the sphere of radius rad: zero on it, negative inside, positive outside
    assert at(c1.formula, P, x=2, y=0, z=0) == 0.0
    assert at(c1.formula, P, x=0, y=math.sqrt(2), z=math.sqrt(2)) == pytest.approx(0, abs=1e-15)
    assert at(c1.formula, P, x=1, y=1, z=1) == -1.0
    assert at(c1.formula, P, x=3, y=0, z=0) == 5.0
    assert "nonnegative" in c2.flags and at(c2.formula, P, x=9, y=9, z=0.5) == 0.0
    assert c2.energy is not None and len(c2.energy) == 3 and c2.content is None
    assert at(c2.energy[1], P, x=4, y=0, z=0) == 2.0


def test_boundary_parametrisation():
    sc = read("parameter rad = 2\nboundary 1 parameters 1\n"
              "x1: rad*cos(p1)\nx2: rad*sin(p1)\nx3: 1\n",
              "vertices\n1 0.3 boundary 1 fixed\n")
    b = sc.boundaries[1]
    assert b.nparams == 1 and len(b.coords) == 3 and b.line == 2
    for t in (0.0, 0.3, 2.0):
        x, y, z = (at(c, sc.parameters, p1=t) for c in b.coords)
        assert math.hypot(x, y) == pytest.approx(2.0, rel=1e-15) and z == 1.0
        assert math.atan2(y, x) == pytest.approx(t, rel=1e-14)


NAMED = ("constraint aa formula: x = 0\nconstraint bb formula: y = 0\n"
         "constraint 1 formula: z = 0\n")


def test_named_constraints_take_free_numbers(evolver, tmp_path):
    # a name takes the lowest free number; a later numbered declaration of a
    # number a name holds moves the name to the next free one (as REF does)
    path = tmp_path / "named.fe"
    path.write_text(NAMED + VERT)
    aa, bb = numbers(evolver, str(path), ["aa", "bb"])
    sc = read(NAMED)
    assert sorted(sc.constraints) == [1, 2, 3]
    names = sc.constraint_names
    assert names == {int(aa): "aa", int(bb): "bb"}
    # each name kept its own formula
    by_name = {n: sc.constraints[c] for c, n in names.items()}
    assert at(by_name["aa"].formula, {}, x=2, y=0, z=0) == 2.0
    assert at(by_name["bb"].formula, {}, x=0, y=3, z=0) == 3.0
    assert at(sc.constraints[1].formula, {}, x=0, y=0, z=5) == 5.0


def test_settings_quantities_attributes_and_arrays():
    sc = read("parameter n = 2\nscale 0.1 fixed\ngravity_constant 3\n"
              "quantity q1 energy modulus 2 method facet_area\n"
              "quantity vol fixed = 4*pi/3 method facet_volume global\n"
              "method_instance mi method edge_length\n"
              "define vertex attribute rc real[n+1]\n"
              "define arr real[2][3] = {{1,2,3},{4,5,6}}\n")
    assert sc.values["scale"] == 0.1 and sc.values["scale_fixed"] == 1.0
    assert sc.values["gravity_constant"] == 3.0
    q1, vol = sc.quantities["q1"], sc.quantities["vol"]
    assert (q1.kind, q1.modulus, [m.method for m in q1.methods]) == ("energy", 2.0,
                                                                     ["facet_area"])
    assert vol.kind == "fixed" and vol.target == pytest.approx(4 * math.pi / 3, rel=1e-15)
    assert vol.methods[0].is_global and not q1.methods[0].is_global
    assert sc.method_instances["mi"].method == "edge_length"
    assert sc.attributes[("vertex", "rc")] == ("real", 3, [3])
    kind, arr = sc.arrays["arr"]
    assert kind == "real" and np.array_equal(arr, [[1, 2, 3], [4, 5, 6]])


def test_periods_by_expressions_and_procedures_cut_out():
    text = ("procedure pp() { print 1 }\nparameter w = 2\ntorus\nperiods\n"
            "w 0 0\n0 w/2 0\n0 0 1\n")
    sc = read(text, "vertices\n1 0 0 0\n2 1 0 0\nedges\n1 1 2 + * -\n")
    assert "torus" in sc.flags
    assert sc.values["_periods"] == [2, 0, 0, 0, 1, 0, 0, 0, 1]
    assert sc.top_commands == [("procedure pp() { print 1 }", 1)]
    assert sc.wraps == {0: [1, 0, -1]}
    with pytest.raises(DatafileError) as exc:
        read("torus\nperiods\n1 0 0\n0 1 0\n")
    assert exc.value.line == 2 and "PERIODS needs 9 numbers, found 6" in exc.value.message


@pytest.mark.parametrize("top, line, col, words", [
    ("constraint 1 formula: x = 0\nconstraint 1 formula: y = 0", 2, None, "defined twice"),
    ("boundary 1 parameters 4 x1: p1 x2: p2 x3: 0", 1, None, "PARAMETERS must be 1, 2 or 3"),
    ("boundary 1 parameters 1 x1: p1 x2: x x3: 0", 1, 36, "undefined parameter 'x'"),
    ("parameter a = 1\n\n  wulff \"x\"", 3, 3, "not supported in pyevolver: WULFF"),
    ("space_dimension 10", 1, None, "SPACE_DIMENSION 10"),
    ("integral_order_2d 8", 1, None, "INTEGRAL_ORDER_2D 8"),
    ("parameter a = 1\nconstraint 1 formula: x + q = a", 2, 27, "undefined parameter 'q'"),
    # an undefined indexed name (an UnboundLocalError the fuzzer found)
    ("constraint 1 formula: qq[1]*x = 0", 1, 23, "undefined parameter 'qq'"),
    ("parameter a = 1\nfoo bar", 2, 1, "unexpected 'foo'"),
])
def test_refusals_are_located(top, line, col, words):
    with pytest.raises(DatafileError) as exc:
        read(top)
    e = exc.value
    assert (e.filename, e.line, e.column) == ("top.fe", line, col)
    assert words in e.message
    where = f"top.fe:{line}" + (f":{col}" if col else "")
    assert str(e).startswith(where + ": ")


def test_a_top_section_of_comments_needs_no_parser(monkeypatch):
    import pyevolver.datafile.top as top_module

    def refuse():
        raise AssertionError("the top parser was asked for")
    monkeypatch.setattr(top_module, "top_parser", refuse)
    sc = read_datafile("c.fe", "// a comment\n/* another */\n\t\nvertices\n1 0 0 0\n")
    assert len(sc.vertices.ids) == 1 and not sc.parameters
    with pytest.raises(AssertionError):         # anything else is parsed
        read_datafile("c.fe", "\xa0\nvertices\n1 0 0 0\n")
