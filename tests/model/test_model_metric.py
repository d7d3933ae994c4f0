"""The metric declaration (pyevolver/model/metric.py): what the reader
fills in, the quadrature orders, the combinations refused by name."""
import io

import pytest

from pyevolver import Session
from pyevolver.errors import PyEvolverError
from pyevolver.model.metric import Metric, metric_of, metric_orders_refusal
from pyevolver.model.scene import Scene

CUBE_TOP = """{top}
vertices
1 0.1 0.2 0.3
2 0.6 0.1 0.2
3 0.2 0.5 0.4
edges
1 1 2
2 2 3
3 3 1
faces
1 1 2 3
"""


def _load(tmp_path, top):
    p = tmp_path / "m.fe"
    p.write_text(CUBE_TOP.format(top=top))
    return Session.load(str(p), out=io.StringIO(), err=io.StringIO())


def test_matrix_components_any_layout(tmp_path):
    s = _load(tmp_path, "PARAMETER k = 2\nMETRIC 1+x^2 0 0 0\n k 0 0\n0 1+z^2")
    m = s.surface.metric
    assert m.kind == "matrix" and m.dim == 3 and len(m.comps) == 9
    assert (m.order_1d, m.order_2d) == (3, 6)


def test_conformal(tmp_path):
    m = _load(tmp_path, "CONFORMAL_METRIC 1 + z^2").surface.metric
    assert m.kind == "conformal" and len(m.comps) == 1


def test_integral_order_sets_both_orders(tmp_path):
    m = _load(tmp_path, "INTEGRAL_ORDER 7\nCONFORMAL_METRIC 2").surface.metric
    assert (m.order_1d, m.order_2d) == (13, 7)


@pytest.mark.parametrize("top,words", [
    ("METRIC 1 0 0 0 1 0 0 0", "METRIC needs 9 components"),
    ("INTEGRAL_ORDER_2D 5\nCONFORMAL_METRIC 2", "INTEGRAL_ORDER_2D 5"),
    ("INTEGRAL_ORDER_2D 7", "INTEGRAL_ORDER_2D 7"),
    ("TORUS\nPERIODS\n1 0 0\n0 1 0\n0 0 1\nCONFORMAL_METRIC 2", "torus model"),
    ("CONFORMAL_METRIC 2\nCONFORMAL_METRIC 3", "second metric"),
])
def test_refused_or_malformed(tmp_path, top, words):
    with pytest.raises(PyEvolverError, match=words):
        _load(tmp_path, top)


def test_orders_refusal_reasons():
    sc = Scene()
    assert metric_orders_refusal(sc) == ""
    sc.values["_metric"] = Metric("conformal")
    sc.values["integral_order_2d"] = 7.0
    assert metric_orders_refusal(sc) is None
    sc.values["integral_order_2d"] = 4.0
    assert "orders" in metric_orders_refusal(sc) or "ORDER" in metric_orders_refusal(sc)
    sc.values["integral_order_2d"] = 6.0
    sc.flags.add("quadratic")
    assert "quadratic" in metric_orders_refusal(sc)


def test_metric_of_without_a_metric_and_unlocated_refusal():
    sc = Scene()
    assert metric_of(sc) is None
    sc.values["_metric"] = Metric("conformal")
    sc.flags.add("torus")
    with pytest.raises(PyEvolverError, match="torus model"):
        metric_of(sc)


def test_klein(tmp_path):
    s = _load(tmp_path, "KLEIN_METRIC").surface
    assert s.metric.kind == "klein" and s.metric.comps == []


def test_klein_points_outside_the_ball(tmp_path):
    """REF: ERROR 2087 "Points outside unit disk in Klein model." at load."""
    p = tmp_path / "k.fe"
    p.write_text(CUBE_TOP.format(top="KLEIN_METRIC").replace("2 0.6 0.1 0.2", "2 1.6 0.1 0.2"))
    with pytest.raises(PyEvolverError, match="Points outside unit disk in Klein model"):
        Session.load(str(p), out=io.StringIO(), err=io.StringIO())


@pytest.mark.parametrize("top,words", [
    ("CONFORMAL_METRIC 2\nquantity q energy method facet_scalar_integral global\n"
     "scalar_integrand: x", "method facet_scalar_integral with a metric"),
    ("CONFORMAL_METRIC 2\nconstraint 1\nformula: z = 0\nenergy:\ne1: 0\ne2: x\ne3: 0",
     "ENERGY integrals with a metric"),
    ("CONFORMAL_METRIC 2\nsquared_curvature 1", "SQUARED_CURVATURE with a metric"),
])
def test_unverified_combinations_refused(tmp_path, top, words):
    with pytest.raises(PyEvolverError, match=words):
        _load(tmp_path, top)


def test_verified_methods_accepted(tmp_path):
    s = _load(tmp_path, "CONFORMAL_METRIC 2\nquantity v info_only method facet_volume global")
    assert "v" in s.surface.quantities


def test_orders_printed_and_fixed_at_run_time(tmp_path):
    """quadm.fe: REF prints integral_order_1d 13 and integral_order_2d 7;
    changing them with a metric is refused by name."""
    out = io.StringIO()
    p = tmp_path / "m.fe"
    p.write_text(CUBE_TOP.format(top="INTEGRAL_ORDER 7\nCONFORMAL_METRIC 2"))
    s = Session.load(str(p), out=out, err=io.StringIO())
    s.run("print integral_order_1d; print integral_order_2d")
    assert out.getvalue().split()[-2:] == ["13", "7"]
    with pytest.raises(PyEvolverError, match="integral_order_2d := ... with a metric"):
        s.run_one("integral_order_2d := 6")


def test_deeply_nested_component_refused(tmp_path):
    """(found by tests/robustness/test_fuzz.py: a traceback before)"""
    deep = "sin(" * 400 + "x" + ")" * 400
    with pytest.raises(PyEvolverError, match="nested more than"):
        _load(tmp_path, f"METRIC\n1 {deep} 0\n0 1 0\n0 0 1")
