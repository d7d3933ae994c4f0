"""pyevolver.studies.vesicle_shapes: Figure 4's start shapes and descriptors."""
import math

import numpy as np
import pytest

from pyevolver.studies.meshes import icosphere
from pyevolver.studies.vesicle_shapes import (SHAPES, area_volume, initial_shape,
                                              mesh_descriptors, min_angle, reduced_volume)


def test_area_volume_of_a_cube_split_into_triangles():
    X = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    assert area_volume(X, F) == pytest.approx((6.0, 1.0))
    assert min_angle(X, F) == pytest.approx(45.0)


def test_sphere_is_round():
    X, F = icosphere(3)
    A, V = area_volume(X, F)
    assert A == pytest.approx(4 * math.pi, rel=1e-2) and V == pytest.approx(4 * math.pi / 3,
                                                                            rel=2e-2)
    assert reduced_volume(X, F) == pytest.approx(1.0, abs=1e-2)
    assert mesh_descriptors(X, F)["type"] == "sphere"


@pytest.mark.parametrize("shape", list(SHAPES))
def test_initial_shapes_meet_area_and_reduced_volume(shape):
    X, F = initial_shape(shape, 2)
    assert area_volume(X, F)[0] == pytest.approx(4 * math.pi, rel=1e-12)
    assert reduced_volume(X, F) == pytest.approx(SHAPES[shape][0], rel=1e-9)


def test_prolate_descriptors():
    X, F = icosphere(3)
    d = mesh_descriptors(X * np.array([1.0, 1.0, 2.0]), F)
    assert d["type"] == "prolate" and d["height_width"] == pytest.approx(2.0, rel=1e-2)
    assert d["axis_crossings"] == 2 and d["axisym_dev"] < 1e-2
