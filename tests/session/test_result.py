"""Session.g returns one GResult: the final energy, area, scale and
pressures, and still the list of its steps."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.session.result import GResult

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def _cube():
    return Session.load(CUBE, out=io.StringIO())


def test_g_returns_the_final_numbers_and_the_steps():
    s = _cube()
    r = s.g(4)
    assert isinstance(r, GResult) and isinstance(r, list) and len(r) == 4
    assert r.energy == s.total_energy == pytest.approx(r[-1].energy, rel=1e-12)
    assert r.area == pytest.approx(s.totals.total_area, rel=1e-12)
    assert r.scale == r[-1].scale
    assert r.pressures.shape == (1,) and np.isfinite(r.pressures[0])
    assert np.array_equal(r.energies, [st.energy for st in r])
    assert r.steps == list(r) and r.energies[0] > r.energies[-1]
    assert [st.energy for st in r] == list(r.energies)        # iterates as before


def test_short_repr():
    r = _cube().g(2)
    text = repr(r)
    assert text.startswith("<g: 2 steps, energy ") and "pressures" in text
    assert len(text) < 120 and str(r) == text


def test_no_vertices_no_steps():
    s = _cube()
    r = GResult().finish(s)
    assert len(r) == 0 and r.energy == s.total_energy and r.pressures.shape == (0,)
    assert repr(r).startswith("<g: 0 steps")
