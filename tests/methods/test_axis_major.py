"""pyevolver/methods/axis_major.py: the axis-major kernels give the
facet-major ones' numbers bit for bit (facet-area gradient, the curvature
energies' chain rule, the energy gradient)."""
import io

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.evolve import gradient as GR
from pyevolver.methods import axis_major as AM
from pyevolver.methods import basic
from pyevolver.studies.meshes import fe_text, icosphere


def _surface(tmp_path, method="star_perp_sq_mean_curvature", extra=""):
    X, F = icosphere(2)
    rng = np.random.default_rng(3)
    X = X * np.array([1.0, 0.8, 1.4]) + 0.02 * rng.standard_normal(X.shape)
    head = f"{extra}\nquantity bend energy modulus 1.3 method {method} global\n"
    text = fe_text(X, F, head) + "\nbodies\n1 " + " ".join(
        str(k + 1) for k in range(len(F))) + " volume 4\n"
    path = tmp_path / "s.fe"
    path.write_text(text)
    s = Session.load(str(path), out=io.StringIO())
    s.run("fix vertex where id < 4")
    return s.surface


def _both(monkeypatch, s, fn):
    new = fn(s.evaluate())
    with monkeypatch.context() as m:
        m.setattr(AM, "available", lambda t: False)
        old = fn(s.evaluate())
    return new, old


@pytest.mark.parametrize("method,extra", [
    ("star_perp_sq_mean_curvature", ""), ("star_perp_sq_mean_curvature", "parameter h_zero = 0.7"),
    ("star_sq_mean_curvature", ""), ("star_normal_sq_mean_curvature", ""),
    ("star_eff_area_sq_mean_curvature", ""), ("sq_mean_curvature", "")])
def test_energy_gradient_bit_for_bit(tmp_path, monkeypatch, method, extra):
    s = _surface(tmp_path, method, extra)
    new, old = _both(monkeypatch, s, GR.energy_gradient)
    assert np.array_equal(new, old)
    assert np.abs(new).max() > 0


@pytest.mark.parametrize("low_memory", [False, True])
def test_facet_area_gradient_bit_for_bit(tmp_path, monkeypatch, low_memory):
    if low_memory:          # (row by row, as on large surfaces)
        monkeypatch.setattr(AM, "LOW_MEMORY_FACETS", 0)
    s = _surface(tmp_path)
    new, old = _both(monkeypatch, s, basic.facet_area_grad)
    assert new.shape == old.shape == (s.nf, 3, 3) and np.array_equal(new, old)


@pytest.mark.parametrize("low_memory", [False, True])
def test_scatter_sums_as_corner_scatter(tmp_path, monkeypatch, low_memory):
    from pyevolver.methods._common import corner_scatter
    if low_memory:          # (axis by axis, as on large surfaces)
        monkeypatch.setattr(AM, "LOW_MEMORY_FACETS", 0)
    s = _surface(tmp_path)
    t = s.evaluate()
    G = np.random.default_rng(0).standard_normal((3, 3, s.nf))
    assert np.array_equal(AM.scatter(s, G), corner_scatter(t, AM.facet_major(G)))
    assert AM.scatter(s, G).flags.c_contiguous
    assert ("_axis_scatter" in s.__dict__) is not low_memory


def test_low_memory_cross_and_sides_bit_for_bit(monkeypatch):
    rng = np.random.default_rng(1)
    u, P = rng.standard_normal((3, 1, 40)), rng.standard_normal((3, 3, 40))
    v, a, b = rng.standard_normal((3, 3, 40)), P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
    want = AM.cross(u, v), AM.cross(v, P), *AM.sides(P, a, b)
    monkeypatch.setattr(AM, "LOW_MEMORY_FACETS", 0)
    got = AM.cross(u, v), AM.cross(v, P), *AM.sides(P, a, b)
    for w, g in zip(want, got):
        assert w.shape == g.shape and np.array_equal(w, g)


def test_cached_on_the_evaluation(tmp_path):
    s = _surface(tmp_path)
    t = s.evaluate()
    assert AM.available(t)
    assert AM.area_grad(t) is AM.area_grad(t)
    q = s.evaluate()
    assert AM.area_grad(q) is not AM.area_grad(t)
