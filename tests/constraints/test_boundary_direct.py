"""pyevolver.constraints.boundary: points and Jacobians of parametric
boundaries (the rings of catfree_b.fe, radius RMAX = 1 at z = ±0.55),
boundary groups, batched small solves, snapshots and motion in parameter
space."""
import io
import os

import numpy as np

from tolerances import FD, ROUNDOFF
from pyevolver import Session
from pyevolver.constraints import boundary as BD

DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")


def _ring_surface():
    return Session.load(os.path.join(DATA, "catfree_b.fe"), out=io.StringIO()).surface


def test_boundary_eval_points_and_jacobians():
    s = _ring_surface()
    p = np.array([[0.0], [np.pi / 3], [2.0]])
    X, J = BD.boundary_eval(s, 1, p)
    t = p[:, 0]
    assert np.allclose(X, np.stack([np.cos(t), np.sin(t), np.full(3, 0.55)], 1), atol=ROUNDOFF)
    assert J.shape == (3, 3, 1)
    assert np.allclose(J[:, :, 0], np.stack([-np.sin(t), np.cos(t), np.zeros(3)], 1),
                       atol=ROUNDOFF)
    X2, _ = BD.boundary_eval(s, 2, p)
    assert np.allclose(X2[:, 2], -0.55)
    # the Jacobian is the derivative of the points
    h = 1e-6
    Xp, _ = BD.boundary_eval(s, 1, p + h)
    Xm, _ = BD.boundary_eval(s, 1, p - h)
    assert np.abs((Xp - Xm) / (2 * h) - J[:, :, 0]).max() <= FD


def test_groups_and_loaded_points_on_the_rings():
    s = _ring_surface()
    groups = dict(BD.boundary_groups(s))
    assert sorted(groups) == [1, 2]
    assert len(groups[1]) == 6 and len(groups[2]) == 6           # six vertices per ring
    for bid, z in ((1, 0.55), (2, -0.55)):
        X = s.X[groups[bid]]
        assert np.allclose(np.hypot(X[:, 0], X[:, 1]), 1.0, atol=ROUNDOFF)
        assert np.allclose(X[:, 2], z, atol=ROUNDOFF)
    mask = np.zeros(s.nv, bool)
    mask[groups[1][:2]] = True
    assert [(b, list(r)) for b, r in BD.boundary_groups(s, mask)] == [(1, list(groups[1][:2]))]


def test_solve_small_regular_and_singular():
    A = np.array([[[2.0, 0.0], [0.0, 4.0]], [[1.0, 1.0], [0.0, 1.0]]])
    b = np.array([[2.0, 8.0], [3.0, 1.0]])
    assert np.allclose(BD.solve_small(A, b), [[1.0, 2.0], [2.0, 1.0]])
    # singular: the least-squares (minimum-norm) solution instead of an error
    S = np.array([[[1.0, 1.0], [1.0, 1.0]]])
    x = BD.solve_small(S, np.array([[2.0, 2.0]]))
    assert np.allclose(x, [[1.0, 1.0]])


def test_displace_moves_ring_vertices_in_parameter_space_and_restore():
    s = _ring_surface()
    base = BD.state(s)
    rows = dict(BD.boundary_groups(s))[1]
    P0 = base[1][rows, 0].copy()
    dX = np.zeros((s.nv, 3))
    # a small tangential push (-sin, cos, 0)·δ moves the parameter by δ
    # (JᵀJ = 1 on the unit ring), and a radial or vertical push not at all
    d = 0.01
    X = s.X[rows]
    dX[rows] = d * np.stack([-X[:, 1], X[:, 0], np.zeros(len(rows))], 1) + \
        np.array([0.0, 0.0, 0.3]) + 0.2 * X * np.array([1, 1, 0])
    free = np.setdiff1d(np.arange(s.nv), np.concatenate([r for _, r in BD.boundary_groups(s)]))
    dX[free] = 0.05
    BD.displace(s, base, dX)
    P = s.vattr["params"][rows, 0]
    assert np.allclose(P - P0, d, atol=ROUNDOFF * 10)
    assert np.allclose(s.X[rows], np.stack([np.cos(P), np.sin(P), np.full(len(P), 0.55)], 1),
                       atol=ROUNDOFF)
    assert np.allclose(s.X[free], base[0][free] + 0.05)
    BD.restore_state(s, base)
    assert np.array_equal(s.X, base[0]) and np.array_equal(s.vattr["params"], base[1])
    # the snapshot is a copy
    s.X[0] += 1.0
    assert not np.array_equal(s.X, base[0])
