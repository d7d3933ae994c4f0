"""Direct tests of pyevolver.remesh.merge.append_surface (``addload``):
two cubes appended give two bodies of volume 1 and area 12."""
import os

import numpy as np
import pytest

import pyevolver
from comparison import consistent
from pyevolver.errors import UnsupportedError
from pyevolver.remesh.merge import append_surface
from tolerances import ROUNDOFF

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def _cube():
    return pyevolver.load(CUBE).surface


def test_append_two_cubes():
    a, b = _cube(), _cube()
    b.X = b.X + np.array([3.0, 0, 0])
    nv, ne, nf = a.nv, a.ne, a.nf
    t = append_surface(a, b)
    assert t is a                                 # modified in place
    assert (t.nv, t.ne, t.nf) == (2 * nv, 2 * ne, 2 * nf)
    assert t.bodies.n == 2
    consistent(t)
    assert np.array_equal(t.E[ne:], b.E + nv)
    tot = t.evaluate()
    assert tot.total_area == pytest.approx(12.0, rel=ROUNDOFF)
    assert np.allclose(tot.volumes, [1.0, 1.0], rtol=ROUNDOFF)
    # new elements numbered after the existing ones
    assert t.ids("vertex").tolist() == list(range(1, 2 * nv + 1))
    assert t.ids("facet").tolist() == list(range(1, 2 * nf + 1))
    assert t.nv - t.ne + t.nf == 4                # two spheres


def test_append_open_surface_to_cube():
    a = _cube()
    X = np.array([[5, 0, 0], [6, 0, 0], [5, 1, 0]], float)
    b = pyevolver.Surface.from_arrays(X, np.array([[0, 1, 2]]))
    t = append_surface(a, b)
    assert (t.nv, t.ne, t.nf) == (17, 39, 25)
    consistent(t)
    assert t.bodies.n == 1
    assert t.bodies.facet_matrix.shape == (1, 25)
    assert t.evaluate().total_area == pytest.approx(6.5, rel=ROUNDOFF)
    assert t.fattr["tension"][-1] == 1.0


def test_append_other_space_dimension_is_refused():
    a = _cube()
    b = _cube()
    b.sdim = 2
    with pytest.raises(UnsupportedError):
        append_surface(a, b)
