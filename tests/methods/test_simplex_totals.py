"""pyevolver.methods.simplex: SimplexTotals' energy and volume gradients
against central differences; load-time numbers in closed form."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.methods.simplex import SimplexTotals

EX = "/usr/share/doc/evolver/examples/simplex3.fe"
DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")


def _load(path, cmds=""):
    s = Session.load(path, out=io.StringIO(), err=io.StringIO())
    if cmds:
        s.run(cmds)
    return s.surface


def _fd(s, fn, h=1e-6):
    X0 = s.X.copy()
    g = np.zeros_like(X0)
    for i in range(s.nv):
        for j in range(X0.shape[1]):
            s.X = X0.copy(); s.X[i, j] += h
            ep = fn(s.evaluate())
            s.X = X0.copy(); s.X[i, j] -= h
            em = fn(s.evaluate())
            g[i, j] = (ep - em) / (2 * h)
    s.X = X0
    return g


@pytest.mark.skipif(not os.path.exists(EX), reason="evolver-doc examples not installed")
def test_simplex3_closed_form():
    t = _load(EX).evaluate()
    assert isinstance(t, SimplexTotals)
    assert t.facet_area == pytest.approx([1 / 3, 1 / 6, 1 / 6, 1 / 6, 1 / 6])
    assert t.energy == pytest.approx(1.0) and t.volumes == pytest.approx([1 / 24])


@pytest.mark.parametrize("name", ["simplex_pressure.fe", "simplex_tetra.fe"])
def test_gradients_by_differences(name):
    s = _load(os.path.join(DATA, name), "r")
    rng = np.random.default_rng(3)
    s.X = s.X + 0.05 * rng.normal(size=s.X.shape)
    t = s.evaluate()
    assert np.allclose(t.energy_gradient(), _fd(s, lambda t: t.energy), atol=1e-6)
    vg = t.body_volume_gradients()
    assert np.allclose(vg[0], _fd(s, lambda t: t.volumes[0]), atol=1e-7)


def test_pressure_energy():
    s = _load(os.path.join(DATA, "simplex_pressure.fe"))
    t = s.evaluate()
    # facet 1 has tension 2: energy = 2/3 + 4/6 - 3 * 1/24
    assert t.energy == pytest.approx(2 / 3 + 4 / 6 - 3 / 24)
    assert t.volume_magnitudes() == pytest.approx([1 / 24])
    with pytest.raises(Exception, match="simplex model"):
        t.facet_N2
