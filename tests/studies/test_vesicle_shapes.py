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


def test_a_given_axis_is_used_instead_of_the_moments():
    """The known axis of a revolved mesh overrides the second moments (a
    deep stomatocyte's are nearly isotropic): the same spheroid is a
    prolate about its long axis, and read about a short one it is as wide
    as half its height; the lateral moments are those about that axis."""
    X, F = icosphere(3)
    Y = X * np.array([1.0, 1.0, 2.0])
    assert mesh_descriptors(Y, F, (0.0, 0.0, 3.0)) == pytest.approx(mesh_descriptors(Y, F))
    d = mesh_descriptors(Y, F, (1.0, 0.0, 0.0))
    assert d["height_width"] == pytest.approx(0.5, rel=1e-2)
    # lateral moments about x: y² against z², far from equal (about z:
    # equal): a prolate lying across the axis is no oblate
    assert d["axisym_dev"] > 0.5 and d["type"] == "other"
    # an oblate spheroid read about its short axis is one
    assert mesh_descriptors(X * np.array([2.0, 2.0, 1.0]), F, (0, 0, 1))["type"] == "oblate"
    # a rotated copy read about its rotated axis: the same numbers
    c, s = math.cos(0.7), math.sin(0.7)
    R = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    assert mesh_descriptors(Y @ R.T, F, R @ np.array([0.0, 0.0, 1.0])) == pytest.approx(
        mesh_descriptors(Y, F, (0.0, 0.0, 1.0)))
