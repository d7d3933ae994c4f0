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


def _neck_curve(neck=0.05):
    """A smooth dumbbell: an elongated body whose waist narrows to a neck
    of radius ``neck`` (0.2 of the mesh size below; the c0 = -0.5
    stomatocyte's neck is 0.057 at v = 0.6), round at both poles."""
    t = np.linspace(0, np.pi, 4001)
    r = np.sin(t) * (1 - (1 - neck) * np.exp(-((t - np.pi / 2) / 0.3) ** 2))
    z = -2 * np.cos(t)
    r[0] = r[-1] = 0.0
    arc = np.concatenate([[0], np.cumsum(np.hypot(np.diff(r), np.diff(z)))])
    return arc, r, z


def _ring_sizes(X):
    """Vertices per ring (rings: equal z)."""
    _, counts = np.unique(np.round(X[:, 2], 9), return_counts=True)
    return counts


def test_min_ring_3_is_the_ungraded_mesh():
    arc, r, z = _neck_curve()
    X0, F0 = revolve(arc, r, z, 400)
    X1, F1 = revolve(arc, r, z, 400, min_ring=3)
    assert np.array_equal(F0, F1) and np.allclose(X0, X1, atol=1e-12)
    assert _ring_sizes(X0)[1:-1].min() == 3          # the neck: a triangle


@pytest.mark.parametrize("min_ring", [8, 12])
def test_graded_neck_keeps_its_rings_and_fat_triangles(min_ring):
    """With ``min_ring`` every ring off the poles has at least that many
    vertices and the rings in the neck come closer, so the triangles stay
    fat; the mesh is still closed, genus 0 and oriented outwards."""
    arc, r, z = _neck_curve()
    X0, F0 = revolve(arc, r, z, 400)
    X, F = revolve(arc, r, z, 400, min_ring=min_ring)
    sizes = _ring_sizes(X)
    assert sizes[0] == sizes[-1] == 1 and sizes[1:-1].min() >= min_ring
    counts = _edges_twice(F)
    assert np.all(counts == 2) and len(X) - len(counts) + len(F) == 2
    assert area_volume(X, F)[1] > 0
    q0, q = mesh_quality(X0, F0), mesh_quality(X, F)
    assert q["min_angle_deg"] > 25 and q["aspect"] < q0["aspect"]
    # the grading is local: more vertices near the neck, not a finer mesh
    assert len(X0) < len(X) < 2 * len(X0)
    # the narrow neck is resolved: the narrowest ring is near the curve's
    # neck radius, its polygon's area within 10% of its circle's (the
    # ungraded mesh's triangle has 41% of it)
    zs = np.unique(np.round(X[:, 2], 9))[1:-1]
    radii = [np.hypot(*X[np.abs(X[:, 2] - zz) < 1e-8, :2].T).mean() for zz in zs]
    k = int(np.argmin(radii))
    n = int(np.sum(np.abs(X[:, 2] - zs[k]) < 1e-8))
    assert n >= min_ring and 0.5 * n * math.sin(2 * math.pi / n) / math.pi > 0.9
    assert abs(radii[k] / 0.05 - 1) < 0.2                       # _neck_curve()
