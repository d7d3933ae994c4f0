"""Lengths and areas in a Riemannian metric (pyevolver/methods/metric.py):
the quadrature rules, the analytic gradients against central differences,
the Hessians against differences of the gradient, the split points of
``r``; the numbers of evolver-nox-d are checked live in
tests/reference/test_metric_reference.py."""
import io
from math import factorial

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.errors import PyEvolverError
from pyevolver.evolve.gradient import energy_gradient
from pyevolver.methods import metric as MT
from pyevolver.methods._common import corner_scatter

from conftest import example
from finite_differences import assert_hessian_columns

SOAP = """{top}
vertices
1 0.1 0.2 0.3
2 1.2 0.1 0.2
3 0.2 1.1 0.4
4 1.0 1.3 0.9
edges
1 1 2
2 2 3
3 3 1
4 2 4
5 4 3 tension 0.7
faces
1 1 2 3
2 4 5 -2
"""

STRING = """STRING
SPACE_DIMENSION 2
{top}
vertices
1 1 0.2
2 0.1 2
3 -2 0.3
4 0.2 -1
edges
1 1 2
2 2 3
3 3 4
4 4 1
"""

METRICS = {
    "matrix": "METRIC\n1+x^2 x*y 0\nx*y 1+y^2 0.1*z\n0 0.1*z 2+sin(x)",
    "conformal": "CONFORMAL_METRIC 1 + z^2 + x*y/3",
}


def _load(tmp_path, text, name="m.fe"):
    p = tmp_path / name
    p.write_text(text)
    return Session.load(str(p), out=io.StringIO(), err=io.StringIO())


def _fd_gradient(s, h=1e-6):
    X0 = s.surface.X.copy()
    g = np.zeros_like(X0)
    for v in range(len(X0)):
        for k in range(X0.shape[1]):
            for sgn in (1, -1):
                s.surface.X = X0.copy()
                s.surface.X[v, k] += sgn * h
                g[v, k] += sgn * s.surface.evaluate().energy / (2 * h)
    s.surface.X = X0
    return g


@pytest.mark.parametrize("order", [1, 3, 5, 13])
def test_line_rule_exact_to_its_order(order):
    t, w = MT.line_rule(order)
    assert len(t) == order // 2 + 1
    for p in range(order + 1):
        assert abs(np.sum(w * t ** p) - 1.0 / (p + 1)) < 1e-14


@pytest.mark.parametrize("order,degree", [(6, 6), (7, 8)])
def test_triangle_rule_exact_to_its_degree(order, degree):
    B, W = MT.triangle_rule(order)
    assert abs(W.sum() - 1.0) < 1e-14
    for i in range(degree + 1):
        for j in range(degree + 1 - i):
            exact = 2.0 * factorial(i) * factorial(j) / factorial(i + j + 2)
            assert abs(np.sum(W * B[:, 1] ** i * B[:, 2] ** j) - exact) < 1e-14


def test_other_triangle_orders_refused():
    with pytest.raises(PyEvolverError, match="INTEGRAL_ORDER_2D 5 with a metric"):
        MT.triangle_rule(5)


@pytest.mark.parametrize("kind", sorted(METRICS))
def test_soapfilm_gradient_against_differences(tmp_path, kind):
    s = _load(tmp_path, SOAP.format(top=METRICS[kind]))
    g = energy_gradient(s.surface.evaluate())
    fd = _fd_gradient(s)
    assert np.max(np.abs(g - fd)) < 1e-7


@pytest.mark.parametrize("kind", ["matrix", "conformal"])
def test_string_gradient_against_differences(tmp_path, kind):
    top = ("METRIC\n(1+1/(x^2+y^2))^2 x*y/5\nx*y/5 1+y^2" if kind == "matrix"
           else "CONFORMAL_METRIC (1 + x^2 + y^2/2)")
    s = _load(tmp_path, STRING.format(top=top))
    g = energy_gradient(s.surface.evaluate())
    fd = _fd_gradient(s)
    assert np.max(np.abs(g - fd)) < 1e-7
    assert np.all(g[:, 2] == 0)


def test_identity_metric_is_euclidean(tmp_path):
    plain = _load(tmp_path, SOAP.format(top=""), "a.fe").surface.evaluate()
    ident = _load(tmp_path, SOAP.format(top="METRIC\n1 0 0\n0 1 0\n0 0 1"), "b.fe")
    t = ident.surface.evaluate()
    assert np.allclose(t.facet_area, plain.facet_area, rtol=1e-14)
    assert np.allclose(t.edge_length, plain.edge_length, rtol=1e-14)
    assert abs(t.energy - plain.energy) < 1e-14


def test_conformal_area_is_the_integral_of_the_factor(tmp_path):
    """In 2-d tangent planes sqrt(det(λ² SᵀS)) = λ|s1×s2|: a linear factor is
    integrated exactly; an edge's length is ∫ sqrt(λ)."""
    tri = """CONFORMAL_METRIC {lam}
vertices
1 0 0 0
2 1 0 0
3 0 1 0
edges
1 1 2
2 2 3
3 3 1
faces
1 1 2 3
"""
    s = _load(tmp_path, tri.format(lam="1 + 3*x + 2*y"))
    t = s.surface.evaluate()
    assert abs(t.facet_area[0] - 0.5 * (1 + 3 / 3 + 2 / 3)) < 1e-14
    s = _load(tmp_path, tri.format(lam="(1 + x)^2"), "b.fe")
    assert abs(s.surface.evaluate().edge_length[0] - 1.5) < 1e-14


@pytest.mark.parametrize("kind", sorted(METRICS))
def test_hessians_against_differences_of_the_gradient(tmp_path, kind):
    s = _load(tmp_path, SOAP.format(top=METRICS[kind]))
    surf = s.surface
    t = surf.evaluate()
    w = np.array([1.0, 0.6])
    H = MT.facet_area_hessian(t, w).toarray()
    idx = np.array([0, 3, 4])
    ew = np.array([0.3, 1.0, 0.7])
    H = H + MT.edge_length_hessian(t, idx, ew).toarray()

    def grad(surf):
        tt = surf.evaluate()
        return corner_scatter(tt, MT.facet_area_grad(tt), w) + MT.edge_length_grad(tt, idx, ew)

    assert np.max(np.abs(H - H.T)) < 1e-12
    assert_hessian_columns(surf, H, grad)


def test_split_fractions_closed_form(tmp_path):
    """Density 1 + a x on [0, 1] (CONFORMAL_METRIC (1 + a x)²): the tail part
    over the head part at t is (t + a t²/2) / (1 − t + a (1 − t²)/2); the
    bisection stops at the first of ½, ¾ or ¼, ... with a ratio in (0.8, 1.2)."""
    line = """STRING
SPACE_DIMENSION 2
CONFORMAL_METRIC (1 + {a}*x)^2
vertices
1 0 0
2 1 0
edges
1 1 2
"""
    def expected(a):
        lo, hi, t = 0.0, 1.0, 0.5
        while True:
            r = (t + a * t * t / 2) / (1 - t + a * (1 - t * t) / 2)
            if 0.8 < r < 1.2:
                return t
            lo, hi = (lo, t) if r >= 1.2 else (t, hi)
            t = (lo + hi) / 2

    for a, want in ((1, 0.5625), (2, 0.625), (4, 0.625), (10, 0.6875), (-0.5, 0.375)):
        s = _load(tmp_path, line.format(a=a), f"l{a}.fe")
        got = MT.split_fractions(s.surface, np.array([0]))[0]
        assert got == expected(a) == want, (a, got)


def test_refine_puts_the_split_points(tmp_path):
    s = Session.load(example("metric.fe"), out=io.StringIO(), err=io.StringIO())
    s.run("r")
    assert np.allclose(s.surface.X[4:, :2], [[0.625, 0.75], [-1, 1], [-0.875, -0.5625],
                                             [0.5, -0.5]], atol=0, rtol=0)


def test_motion_is_the_coordinate_gradient(tmp_path):
    """REF moves metric.fe's vertices by −scale ∇E at a fixed scale (not
    G⁻¹∇E): x − 0.01 ∇E after ``m 0.01; g 1``."""
    s = Session.load(example("metric.fe"), out=io.StringIO(), err=io.StringIO())
    X0 = s.surface.X.copy()
    g = energy_gradient(s.surface.evaluate())
    s.run("m 0.01; g 1")
    assert np.allclose(s.surface.X, X0 - 0.01 * g, rtol=0, atol=1e-13)


KLEIN_SOAP = SOAP.replace("1 0.1 0.2 0.3\n2 1.2 0.1 0.2\n3 0.2 1.1 0.4\n4 1.0 1.3 0.9",
                          "1 0.05 0.1 0.15\n2 0.6 0.05 0.1\n3 0.1 0.55 0.2\n4 0.5 0.45 0.3")
KLEIN_STRING = STRING.replace("1 1 0.2\n2 0.1 2\n3 -2 0.3\n4 0.2 -1",
                              "1 0.5 0.1\n2 0.05 0.7\n3 -0.6 0.15\n4 0.1 -0.45")


def test_klein_gradients_against_differences(tmp_path):
    for text, name in ((KLEIN_SOAP, "ks.fe"), (KLEIN_STRING, "kst.fe")):
        s = _load(tmp_path, text.format(top="KLEIN_METRIC"), name)
        g = energy_gradient(s.surface.evaluate())
        fd = _fd_gradient(s)
        assert np.max(np.abs(g - fd)) < 1e-7, name


def test_klein_closed_forms(tmp_path):
    """Hyperbolic distance from the origin is artanh(r); a triangle's area is
    π minus its angles (a right isosceles triangle at the origin: the angle
    at the origin is π/2, the others from the hyperbolic law of cosines)."""
    s = _load(tmp_path, KLEIN_SOAP.format(top="KLEIN_METRIC"))
    surf = s.surface
    X = np.array([[0.0, 0, 0], [0.6, 0, 0], [0, 0.6, 0]])
    L = MT.segment_lengths(surf, X[0], X[1])[0]
    assert abs(L - np.arctanh(0.6)) < 1e-14
    A = MT.triangle_areas(surf, X[0], X[1], X[2])[0]
    a = MT.segment_lengths(surf, X[1], X[2])[0]
    b = np.arctanh(0.6)
    # angle at X1 from cos B = (cosh a cosh c - cosh b) / (sinh a sinh c), c = b
    cosB = (np.cosh(a) * np.cosh(b) - np.cosh(b)) / (np.sinh(a) * np.sinh(b))
    assert abs(A - (np.pi - np.pi / 2 - 2 * np.arccos(cosB))) < 1e-13


def test_klein_hessian_against_differences(tmp_path):
    s = _load(tmp_path, KLEIN_SOAP.format(top="KLEIN_METRIC"))
    surf = s.surface
    t = surf.evaluate()
    H = MT.facet_area_hessian(t, np.ones(surf.nf)).toarray()
    assert_hessian_columns(
        surf, H, lambda surf: corner_scatter(surf.evaluate(), MT.facet_area_grad(surf.evaluate())))
