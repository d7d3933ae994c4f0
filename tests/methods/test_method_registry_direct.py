"""pyevolver.methods.registry itself: register_method, lookup, method_info
and the read-only views."""
import pytest

from pyevolver.errors import UnsupportedError
from pyevolver.methods import registry as R


def _val(t, m, idx):
    return idx * 0.0


def _grad(t, m, idx, w):
    return None


def test_register_replaces_and_lowercases():
    try:
        a = R.register_method("Test_Reg_X", "edge", _val)
        assert a.name == "test_reg_x" and R.REGISTRY["test_reg_x"] is a
        assert a.gradient is None and a.hessian is None and a.no_hessian is None
        b = R.register_method("test_reg_x", "vertex", _val, _grad, no_hessian="why")
        assert R.lookup("test_reg_x") is b and b.etype == "vertex"
        assert R.method_info("test_reg_x") == ("vertex", _val)
        assert R.GRADIENTS["test_reg_x"] is _grad
        assert R.NO_HESSIAN["test_reg_x"] == "why"
        assert "test_reg_x" not in R.HESSIANS
        with pytest.raises(KeyError):
            R.HESSIANS["test_reg_x"]
    finally:
        R.REGISTRY.pop("test_reg_x", None)
    assert "test_reg_x" not in R.METHODS


def test_registering_a_known_curvature_name_removes_the_refusal():
    name = "test_reg_curv"
    R.CURVATURE_METHODS.add(name)
    try:
        with pytest.raises(UnsupportedError, match="curvature energy is not implemented"):
            R.lookup(name)
        R.register_method(name, "vertex", _val)
        assert name not in R.CURVATURE_METHODS
        assert R.lookup(name).value is _val
    finally:
        R.REGISTRY.pop(name, None)
        R.CURVATURE_METHODS.discard(name)


def test_views_are_counts_of_the_entries_that_have_the_field():
    assert len(R.METHODS) == len(R.REGISTRY)
    assert len(R.GRADIENTS) == sum(m.gradient is not None for m in R.REGISTRY.values())
    assert set(R.HESSIANS) == {k for k, m in R.REGISTRY.items() if m.hessian is not None}
    assert len(R.HESSIANS) < len(R.GRADIENTS) <= len(R.METHODS)
    m = R.lookup("facet_area")
    with pytest.raises(Exception):
        m.name = "other"                   # frozen dataclass
    with pytest.raises(UnsupportedError):
        R.method_info("no_such_method_here")
