"""pyevolver.methods.registry: one entry per method with value, gradient
and Hessian; the compatibility views; totals of cube.fe."""
import numpy as np
import pytest

from pyevolver import Session
from pyevolver.errors import UnsupportedError
from pyevolver.methods import (GRADIENTS, HESSIANS, METHODS, REGISTRY, Method, evaluate, lookup,
                               method_info, register_method)
from pyevolver.methods.totals import MODEL_TOTALS, Totals


def test_builtin_entries_have_value_gradient_hessian():
    for name in ("facet_area", "facet_volume", "edge_length", "harmonic_energy",
                 "star_sq_mean_curvature", "mean_curvature_integral", "sq_gauss_curvature"):
        m = lookup(name)
        assert isinstance(m, Method) and m.name == name
        assert callable(m.value) and callable(m.gradient) and callable(m.hessian)
    assert lookup("circle_willmore").hessian is None and lookup("circle_willmore").no_hessian
    assert lookup("loop_area").no_hessian


def test_views_follow_the_registry():
    assert METHODS["facet_area"] == ("facet", REGISTRY["facet_area"].value)
    assert GRADIENTS["edge_length"] is REGISTRY["edge_length"].gradient
    assert "edge_scalar_integral" in METHODS and "edge_scalar_integral" not in GRADIENTS
    assert "edge_area" in GRADIENTS and "edge_area" not in HESSIANS
    assert method_info("edge_length")[0] == "edge"


def test_unknown_and_unimplemented_methods():
    assert lookup("sqcurve_string").etype == "vertex"      # (tests/methods/test_string_curvature.py)
    with pytest.raises(UnsupportedError, match="1559"):
        lookup("mix_sq_mean_curvature")
    with pytest.raises(UnsupportedError):
        lookup("no_such_method")


def test_register_a_user_method():
    try:
        register_method("test_twice_area", "facet", lambda t, m, idx: 2 * t.facet_area[idx])
        assert METHODS["test_twice_area"][0] == "facet"
        assert lookup("test_twice_area").gradient is None
    finally:
        REGISTRY.pop("test_twice_area", None)


def test_totals_of_the_cube():
    s = Session.load("datafiles/cube.fe").surface
    t = evaluate(s)
    assert type(t) is Totals and MODEL_TOTALS["soapfilm"] is Totals
    assert np.isclose(t.total_area, 6.0) and np.isclose(t.energy, 6.0)
    assert np.allclose(t.volumes, [1.0])
    assert np.isclose(s.evaluate().energy, t.energy)       # the model's hook
    idx = np.arange(s.nf)
    assert np.isclose(lookup("facet_area").value(t, None, idx).sum(), 6.0)
