"""pyevolver.constraints: projection onto level sets, tangent spaces,
boundaries (analytic checks on small surfaces)."""
import numpy as np

from pyevolver.constraints import (constrained_vertices, displace, project_tangent,
                                   project_to_constraints, restore_state, state, vertex_coords)
from pyevolver.datafile.reader import read_datafile
from pyevolver.model.build import build_surface

SPHERE_CUBE = """
constraint 1
formula: x^2 + y^2 + z^2 = 4

vertices
1  0.0 0.0 0.0  constraint 1
2  1.0 0.0 0.0  constraint 1
3  1.0 1.0 0.0  constraint 1
4  0.0 1.0 0.0  constraint 1
5  0.0 0.0 1.0  constraint 1
6  1.0 0.0 1.0  constraint 1
7  1.0 1.0 1.0  constraint 1
8  0.0 1.0 1.0

edges
1   1 2
2   2 3
3   3 4
4   4 1
5   5 6
6   6 7
7   7 8
8   8 5
9   1 5
10  2 6
11  3 7
12  4 8

faces
1   1 10 -5  -9
2   2 11 -6 -10
3   3 12 -7 -11
4   4  9 -8 -12
5   5  6  7   8
6  -4 -3 -2  -1
"""


def surface():
    return build_surface(read_datafile("sphere_cube.fe", SPHERE_CUBE))


def test_loading_projects_onto_the_sphere():
    s = surface()
    on = constrained_vertices(s)
    assert on.sum() == 7 and not on[7]
    r = np.linalg.norm(s.X[on], axis=1)
    assert np.allclose(r[1:], 2.0, atol=1e-12)          # vertex 1 (the origin) cannot move
    assert np.allclose(s.X[7], [0, 1, 1])                  # unconstrained: as read


def test_projection_after_a_move_and_tangent_projection():
    s = surface()
    s.X[1] *= 1.3
    failed = project_to_constraints(s, np.arange(s.nv))
    assert len(failed) == 0
    assert np.isclose(np.linalg.norm(s.X[1]), 2.0, atol=1e-12)
    v = np.ones((s.nv, 3))
    (t,) = project_tangent(s, [v])
    n = s.X[1] / np.linalg.norm(s.X[1])
    assert abs(t[1] @ n) < 1e-12                          # radial part removed
    assert np.allclose(t[7], 1.0)                          # free vertex unchanged


def test_vertex_coords_and_state_restore():
    s = surface()
    c = vertex_coords(s, np.array([2, 3]))
    assert np.allclose(c["x"], s.X[[2, 3], 0]) and set(c) >= {"x", "y", "z"}
    st = state(s)
    displace(s, st, np.full((s.nv, 3), 0.5))
    assert np.allclose(s.X, st[0] + 0.5)
    restore_state(s, st)
    assert np.array_equal(s.X, st[0])
