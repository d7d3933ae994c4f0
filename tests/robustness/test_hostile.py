"""Hostile input (issue 25): long tokens and flat expressions are read in
linear time, messages quote long text clipped, flat sums are evaluated
iteratively."""
from __future__ import annotations

import io
import os

import pytest

from pyevolver.datafile.reader import read_datafile
from pyevolver.datafile.scan import _BAD_NUMBER
from pyevolver.errors import DatafileError, CommandError
from pyevolver.session.core import Session

EX = "/usr/share/doc/evolver/examples"
CUBE = """vertices
1 0 0 0
2 1 0 0
3 1 1 0
edges
1 1 2
2 2 3
3 3 1
faces
1 1 2 3
"""


def test_long_digit_run_into_letter_is_refused_located():
    # the malformed-number check used to backtrack quadratically on a digit
    # run (200,000 digits: minutes); now linear, and the message is short
    digits = "1" * 200_000
    text = f"parameter p = {digits}a\n" + CUBE
    with pytest.raises(DatafileError) as e:
        read_datafile("long.fe", text)
    msg = str(e.value)
    assert "long.fe:1:" in msg and len(msg) < 2000


def test_long_digit_run_in_vertex_line():
    text = CUBE.replace("vertices\n", "vertices\n9 " + "1" * 200_000 + "a 0 0\n")
    with pytest.raises(DatafileError) as e:
        read_datafile("long.fe", text)
    assert "long.fe:2:" in str(e.value) and len(str(e.value)) < 2000


@pytest.mark.parametrize("text", ["1..2", "1.2.3", "3e", "3.e+", "12d-", ".5.", "1e+ 2"])
def test_bad_numbers_still_found(text):
    assert _BAD_NUMBER.search(text)


@pytest.mark.parametrize("text", ["1.5", "3e5", "2d-3", "a1e", "x.5", "1e-5", "0.25"])
def test_good_numbers_pass(text):
    assert not _BAD_NUMBER.search(text)


def _session():
    out = io.StringIO()
    return Session.load(os.path.join(os.path.dirname(__file__), "..", "..", "datafiles",
                                     "cube.fe"), out=out, err=io.StringIO()), out


def test_flat_sum_prints_its_value():
    # used to be refused as "nested more than 200 levels deep"
    s, out = _session()
    s.run("print " + "+".join(["1"] * 20_000))
    assert out.getvalue().split()[-1] == "20000"
    s.run("print " + "-".join(["2"] * 3000) + "*3/2")
    assert float(out.getvalue().split()[-1]) == 2 - 2 * 2998 - 3


@pytest.mark.slow
def test_flat_sum_of_100000_terms():
    s, out = _session()
    s.run("print " + "+".join(["1"] * 100_000))
    assert out.getvalue().split()[-1] == "100000"


def test_deep_nesting_still_refused():
    s, _ = _session()
    with pytest.raises(CommandError, match="nested more than"):
        s.run("print " + "1+(" * 300 + "1" + ")" * 300)
    with pytest.raises(CommandError, match="nested more than"):
        s.run("print " + "-sin(" * 300 + "1" + ")" * 300)


def test_syntax_error_in_long_line_quotes_around_the_column():
    s, _ = _session()
    with pytest.raises(CommandError) as e:
        s.run("print 1+" + "2" * 100_000 + "a")
    msg = str(e.value)
    assert ":1:100009:" in msg and len(msg) < 600
    assert msg.rstrip().endswith("^")


@pytest.mark.parametrize("text,where", [
    (CUBE.replace("vertices\n", "vertices\n" + "1" * 5000 + "a 0 0\n"), "long.fe:2:1:"),
    ("constraint " + "1" * 5000 + "\nformula: x = 0\n" + CUBE, "long.fe:1:12:"),
    ("boundary 1 parameters " + "2" * 5000 + "\nx1: p1\nx2: 0\nx3: 0\n" + CUBE, "long.fe:1:23:"),
])
def test_ids_beyond_pythons_int_conversion_are_located(text, where):
    # (Python refuses int() of more than 4,300 digits: it was a traceback)
    with pytest.raises(DatafileError) as e:
        read_datafile("long.fe", text)
    assert str(e.value).startswith(where) and "too large" in str(e.value)


@pytest.mark.parametrize("index", ["1e400", "-1e400", "(1e400-1e400)"])
def test_array_index_that_is_not_finite_is_located(index):
    # found by the deep hostile fuzz: int(inf) escaped as OverflowError
    text = ("space_dimension 4\ndefine vertex attribute rc real[2]\n"
            f"constraint 1 formula: x4 = rc[{index}]\n"
            "vertices\n1 0 0 0 0 constraint 1 rc 0 0\n2 1 0 0 0\n3 0 1 0 0\n"
            "edges\n1 1 2\n2 2 3\n3 3 1\nfaces\n1 1 2 3\n")
    with pytest.raises(DatafileError) as e:
        Session.load("idx.fe", out=io.StringIO(), err=io.StringIO(), text=text)
    assert str(e.value).startswith("idx.fe:") and "index must be one integer" in str(e.value)


@pytest.mark.parametrize("code", ["641e18", "1e400", "2.5"])
def test_wrap_code_out_of_range_is_located(code):
    # found by the deep hostile fuzz: int() of 6.41e20 overflowed a C long
    # (negative codes are group elements: SYMMETRY_GROUP "rotate" wrap -1)
    text = (f'symmetry_group "torus"\nvertices\n1 0 0 0\n2 0.5 0 0\n3 0 0.5 0\n'
            f"edges\n1 1 2 wrap {code}\n2 2 3\n3 3 1\nfaces\n1 1 2 3\n")
    with pytest.raises(DatafileError) as e:
        Session.load("wrap.fe", out=io.StringIO(), err=io.StringIO(), text=text)
    assert str(e.value).startswith("wrap.fe:")


@pytest.mark.parametrize("section", ["vertices", "faces"])
def test_element_id_beyond_the_float_range_is_located(section):
    # found by the deep hostile fuzz: a 400-digit id on a long line read as
    # inf by the fast numeric path, int(inf) escaped as OverflowError
    big = "1" * 50_000              # (the deep fuzz's input: a 50,006-character line)
    text = ("SIMPLEX_REPRESENTATION\nvertices\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
            "faces\n1 1 2 3\n")
    text = text.replace("faces\n", f"faces\n{big} 1 3 2\n") if section == "faces" else \
        text.replace("vertices\n", f"vertices\n{big} 0 0 0\n")
    with pytest.raises(DatafileError) as e:
        Session.load("big.fe", out=io.StringIO(), err=io.StringIO(), text=text)
    msg = str(e.value)
    assert msg.startswith("big.fe:") and ("out of range" in msg or "too large" in msg)


@pytest.mark.parametrize("sep", [":", ","])
def test_long_vertex_line_with_separators_reads_as_a_short_one(sep):
    # found by the deep hostile fuzz: a long line of numbers and ':' went to
    # the one-call numeric reader with its colons (ValueError escaped)
    text = ("STRING\nSPACE_DIMENSION 2\nvertices\n1 0 0\n2 2 0\n3 2.5 {tail}\n"
            "edges\n1 1 2\n2 2 3\n")
    short = Session.load("s.fe", out=io.StringIO(), err=io.StringIO(),
                         text=text.format(tail=sep * 3 + " 7"))
    long_ = Session.load("l.fe", out=io.StringIO(), err=io.StringIO(),
                         text=text.format(tail=sep * 3000 + " 7"))
    assert short.surface.X[2, :2].tolist() == long_.surface.X[2, :2].tolist() == [2.5, 7.0]


@pytest.mark.parametrize("order", ["71e308", "-1e400", "(1e400-1e400)"])
def test_integral_order_beyond_the_float_range_is_located(order):
    # found by the deep hostile fuzz: INTEGRAL_ORDER 71e308 with a METRIC,
    # int(inf) escaped as OverflowError
    text = (f"INTEGRAL_ORDER {order}\nMETRIC\n1 0 0\n0 1 0\n0 0 1\n"
            "vertices\n1 0 0 0\n2 1 0 0\n3 0 1 0\nedges\n1 1 2\n2 2 3\n3 3 1\nfaces\n1 1 2 3\n")
    with pytest.raises(DatafileError) as e:
        Session.load("order.fe", out=io.StringIO(), err=io.StringIO(), text=text)
    assert str(e.value).startswith("order.fe:1:")


def test_metric_of_the_wrong_size_is_located():
    # found by the deep hostile fuzz: metric.fe's STRING line made
    # "----------1", which continues SPACE_DIMENSION 2's expression (3): a
    # 2x2 METRIC met three coordinates (IndexError)
    with open(os.path.join(EX, "metric.fe")) as fh:
        text = fh.read()
    assert "STRING" in text
    with pytest.raises(DatafileError) as e:
        Session.load("m.fe", out=io.StringIO(), err=io.StringIO(),
                     text=text.replace("STRING", "----------1"), run_read=False)
    assert str(e.value).startswith("m.fe:14:") and "METRIC has 4 components" in str(e.value)


def test_simplex_surface_above_its_space_is_located():
    # found by the deep hostile fuzz: SPACE_DIMENSION 1 with the default
    # SURFACE_DIMENSION 2 in the simplex model: the message had no line
    text = ("SPACE_DIMENSION 1\nSIMPLEX_REPRESENTATION\nvertices\n1 0\n2 1\n3 2\n"
            "faces\n1 1 2 3\n")
    with pytest.raises(DatafileError) as e:
        Session.load("sx.fe", out=io.StringIO(), err=io.StringIO(), text=text)
    assert str(e.value).startswith("sx.fe:1:") and "above SPACE_DIMENSION 1" in str(e.value)
