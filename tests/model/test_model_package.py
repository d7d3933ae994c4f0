"""pyevolver.model (the package): importing it installs Surface.from_arrays;
the unit cube built from arrays has area 6, volume 1, Euler characteristic 2."""
import numpy as np

import pyevolver.model as model
from pyevolver.model import arrays
from pyevolver.model.surface import HOOKS, Surface

CUBE_X = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                   [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
# outward-oriented triangles, two per face
CUBE_F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7],
                   [0, 1, 5], [0, 5, 4], [2, 3, 7], [2, 7, 6],
                   [1, 2, 6], [1, 6, 5], [3, 0, 4], [3, 4, 7]])


def test_package_installs_from_arrays():
    assert model.arrays is arrays
    assert HOOKS.from_arrays is arrays.surface_from_arrays


def test_cube_from_arrays_area_volume_euler():
    s = Surface.from_arrays(CUBE_X, CUBE_F, body=True)
    assert (s.nv, s.ne, s.nf) == (8, 18, 12)
    assert s.nv - s.ne + s.nf == 2
    t = s.evaluate()
    assert abs(t.total_area - 6.0) <= 1e-12
    assert np.allclose(t.volumes, [1.0], atol=1e-12)
    # the same mesh with every facet reversed encloses volume -1
    r = Surface.from_arrays(CUBE_X, CUBE_F[:, ::-1], body=True)
    assert np.allclose(r.evaluate().volumes, [-1.0], atol=1e-12)
