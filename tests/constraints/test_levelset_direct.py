"""pyevolver.constraints.levelset itself: Newton projection onto one and
two level sets (a sphere ∩ a plane is a circle), one-sided constraints,
tangent projection orthogonal to every constraint gradient, vertex
attributes in formulas, and the edges carrying ENERGY integrands."""
import numpy as np

from tolerances import ROUNDOFF
from pyevolver.constraints import levelset as LS
from pyevolver.datafile.reader import read_datafile
from pyevolver.model.build import build_surface

TEXT = """
define vertex attribute zfix real

constraint 1
formula: x^2 + y^2 + z^2 = 4

constraint 2
formula: z = 1

constraint 3 nonnegative
formula: x

constraint 4
formula: z = zfix

constraint 5
formula: y = 0
energy:
e1: -y/2
e2: x/2
e3: 0

vertices
1  0.3 0.2 1.5   constraint 1, 2
2  1.5 0.5 0.4   constraint 1
3  0.5 1.0 0.2   constraint 3
4 -0.5 1.0 0.7   constraint 3
5  1.0 1.0 0.0   zfix 0.25 constraint 4
6  1.0 0.0 0.0   constraint 5
7  2.0 0.0 0.0   constraint 5

edges
1  1 2
2  2 3
3  3 1
4  3 4
5  4 5
6  5 3
7  6 7   constraint 5
8  7 5
9  5 6   constraint 5 fixed

faces
1  1 2 3
2  4 5 6
3  7 8 9
"""


def surface():
    return build_surface(read_datafile("levelsets.fe", TEXT))


def test_loading_projects_onto_one_and_two_constraints():
    s = surface()
    on = LS.constrained_vertices(s)
    assert on.tolist() == [True] * 7
    # vertex 1 on the sphere and the plane: the circle of radius √3 at z = 1
    assert abs(np.linalg.norm(s.X[0]) - 2.0) <= 1e-12
    assert abs(s.X[0, 2] - 1.0) <= 1e-12
    assert abs(np.hypot(*s.X[0, :2]) - np.sqrt(3)) <= 1e-12
    assert abs(np.linalg.norm(s.X[1]) - 2.0) <= 1e-12
    # one-sided x >= 0: vertex 3 satisfies it and stays, vertex 4 is put on x = 0
    assert np.allclose(s.X[2], [0.5, 1.0, 0.2])
    assert np.allclose(s.X[3], [0.0, 1.0, 0.7], atol=1e-12)
    # z = zfix with the vertex attribute zfix = 0.25
    assert abs(s.X[4, 2] - 0.25) <= 1e-12


def test_projection_after_moves_returns_no_failures():
    s = surface()
    s.X[0] += [0.4, -0.3, 0.2]
    s.X[1] *= 1.5
    s.X[4, 2] = 3.0
    failed = LS.project_to_constraints(s, np.arange(s.nv))
    assert len(failed) == 0
    assert abs(np.linalg.norm(s.X[0]) - 2.0) <= 1e-12 and abs(s.X[0, 2] - 1.0) <= 1e-12
    assert abs(np.linalg.norm(s.X[1]) - 2.0) <= 1e-12
    assert abs(s.X[4, 2] - 0.25) <= 1e-12
    c = LS.vertex_coords(s, np.array([4]))
    assert np.allclose(c["zfix"], 0.25) and np.allclose(c["z"], s.X[4, 2])


def test_tangent_projection_is_orthogonal_and_idempotent():
    s = surface()
    v = np.random.default_rng(0).standard_normal((s.nv, 3))
    (t,) = LS.project_tangent(s, [v])
    n1 = s.X[0]                                  # sphere gradient direction
    assert abs(t[0] @ n1) <= ROUNDOFF * 10 and abs(t[0, 2]) <= ROUNDOFF * 10
    # the circle's tangent: along z × x at vertex 1
    tang = np.cross([0, 0, 1], s.X[0])
    assert np.allclose(np.cross(t[0], tang), 0.0, atol=ROUNDOFF * 10)
    assert abs(t[1] @ s.X[1]) <= ROUNDOFF * 10
    assert abs(t[4, 2]) <= ROUNDOFF and abs(t[5, 1]) <= ROUNDOFF
    (tt,) = LS.project_tangent(s, [t])
    assert np.allclose(tt, t, atol=ROUNDOFF * 10)


def test_integral_edges_skip_fixed_edges():
    s = surface()
    out = LS.integral_edges(s, "energy")
    assert len(out) == 1
    comps, idx, sign = out[0]
    assert idx.tolist() == [6]                   # edge 7 (edge 9 is FIXED)
    assert np.array_equal(np.abs(sign), [1.0])
    assert LS.integral_edges(s, "content") == []


def test_tangent_projectors_equal_project_tangent_and_find_curved_constraints():
    """The per-vertex projector matrices act as project_tangent does; the
    sphere (constraint 1) is curved at its vertices, the planes are not."""
    s = surface()
    rows = np.arange(s.nv)
    P = LS.tangent_projectors(s, rows)
    v = np.random.default_rng(1).standard_normal((s.nv, 3))
    (t,) = LS.project_tangent(s, [v])
    assert np.allclose(np.einsum("nij,nj->ni", P, v), t, atol=ROUNDOFF * 10)
    assert np.allclose(P, np.swapaxes(P, 1, 2), atol=ROUNDOFF)
    assert LS.curved_constraints(s, rows) == [1]
    assert LS.curved_constraints(s, np.array([4, 5, 6])) == []
