"""Direct tests of pyevolver.studies.phase_mesh: surfaces of revolution
meshed from a generating curve.  Expected values are closed forms (the
sphere's area, an equilateral triangle's quality numbers, Euler's formula)."""
import math

import numpy as np
import pytest

from pyevolver.studies.phase_mesh import mesh_quality, revolve
from pyevolver.studies.vesicle_shapes import area_volume


def _sphere_curve(n=801):
    t = np.linspace(0, np.pi, n)
    return t, np.sin(t), -np.cos(t)


def _edges_twice(F):
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return counts


@pytest.mark.parametrize("nv", [60, 300, 1000])
def test_revolved_sphere_is_a_closed_oriented_genus_0_mesh(nv):
    X, F = revolve(*_sphere_curve(), nv)
    counts = _edges_twice(F)
    assert np.all(counts == 2)                                   # closed, manifold
    assert len(X) - len(counts) + len(F) == 2                    # Euler: genus 0
    # consistently oriented: every directed edge appears once
    d = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    assert len(np.unique(d, axis=0)) == len(d)
    A, V = area_volume(X, F)
    assert V > 0
    assert abs(A - 4 * math.pi) < 8 * math.pi / nv ** 0.8           # inscribed: O(h²) below
    assert abs(len(X) - nv) < 0.15 * nv
    assert mesh_quality(X, F)["min_angle_deg"] > 25


def test_area_scaling_and_a_narrow_neck():
    """Two spheres joined by a neck of radius 0.1 (a stomatocyte-like
    profile): the neck's rings get few vertices, the triangles stay fat."""
    s = np.linspace(0, 1, 2001)
    # radius profile: two unit bumps and a neck of radius 0.1 in between
    z = 4 * s
    r = np.maximum(np.abs(np.sin(np.pi * z / 2)), 0.1) * np.sin(np.pi * s) ** 0.5
    r[0] = r[-1] = 0.0
    arc = np.concatenate([[0], np.cumsum(np.hypot(np.diff(r), np.diff(z)))])
    X, F = revolve(arc, r, z, 600, area=4 * math.pi)
    assert abs(area_volume(X, F)[0] - 4 * math.pi) < 1e-12
    assert np.all(_edges_twice(F) == 2)
    assert mesh_quality(X, F)["min_angle_deg"] > 15


def test_quality_of_an_equilateral_triangle():
    X = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, math.sqrt(3) / 2, 0]])
    q = mesh_quality(X, np.array([[0, 1, 2]]))
    assert abs(q["min_angle_deg"] - 60) < 1e-9
    assert abs(q["aspect"] - 1) < 1e-12
    assert abs(q["h"] - 1) < 1e-12
