"""Per-facet normal-direction Hessian blocks (methods/normal_blocks.py),
checked against central differences of the analytic area and volume
gradients along the chosen directions (the assembly:
tests/evolve/test_normal_assembly.py)."""

import numpy as np
import pytest

from conftest import jittered_surface
from pyevolver.methods.normal_blocks import area_blocks, volume_blocks


@pytest.fixture(scope="module")
def rough_cube():
    return jittered_surface("cube.fe", 3, 0.05)


def _axis_major(S, V):
    return np.ascontiguousarray(V.T)[:, S.F.T]


def _fd_blocks(S, U, grad, h=1e-6):
    """K_ab of one facet function by central differences: the change of the
    gradient at corner a along u_a when corner b moves along u_b."""
    X0 = S.X.copy()
    m = S.nf
    K = np.zeros((m, 3, 3))
    try:
        for b in range(3):
            for sgn in (1, -1):
                S.X = X0.copy()
                # every facet's corner b moved at once would mix facets: do
                # it per facet through the per-corner gradient of that facet
                P = np.stack([S.X[S.F[:, c]] for c in range(3)], 1)
                P[:, b] += sgn * h * U[:, b]
                g = grad(P)                                       # (m, 3, 3)
                K[:, :, b] += sgn * np.einsum("mai,mai->ma", g, U) / (2 * h)
    finally:
        S.X = X0
    return K


def _area_grad(P):
    N = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    n = N / np.linalg.norm(N, axis=1)[:, None]
    e = np.stack([P[:, 2] - P[:, 1], P[:, 0] - P[:, 2], P[:, 1] - P[:, 0]], 1)
    return 0.5 * np.cross(n[:, None, :], e)


def _volume_grad(P, symmetric):
    if symmetric:
        return np.stack([np.cross(P[:, 1], P[:, 2]), np.cross(P[:, 2], P[:, 0]),
                         np.cross(P[:, 0], P[:, 1])], 1) / 6.0
    x, y, z = P[..., 0], P[..., 1], P[..., 2]
    cz = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (y[:, 1] - y[:, 0]) * (x[:, 2] - x[:, 0])
    Z = z.sum(1)
    g = np.zeros_like(P)
    nx, px = [1, 2, 0], [2, 0, 1]
    g[:, :, 0] = (y[:, nx] - y[:, px]) * Z[:, None] / 6.0
    g[:, :, 1] = (x[:, px] - x[:, nx]) * Z[:, None] / 6.0
    g[:, :, 2] = cz[:, None] / 6.0
    return g


def test_area_blocks_against_differences(rough_cube):
    S = rough_cube
    rng = np.random.default_rng(5)
    V = rng.standard_normal((S.nv, 3))
    U = V[S.F]                                                    # (m, 3, 3)
    w = np.linspace(0.5, 2.0, S.nf)
    K = area_blocks(_axis_major(S, S.X), _axis_major(S, V), w)
    Kf = _fd_blocks(S, U, _area_grad) * w[:, None, None]
    assert np.abs(K - Kf).max() <= 1e-7 * np.abs(Kf).max()
    assert np.array_equal(K, K.transpose(0, 2, 1))


@pytest.mark.parametrize("symmetric", [False, True])
def test_volume_blocks_against_differences(rough_cube, symmetric):
    S = rough_cube
    rng = np.random.default_rng(6)
    V = rng.standard_normal((S.nv, 3))
    w = np.linspace(-1.0, 2.0, S.nf)
    K = volume_blocks(_axis_major(S, S.X), _axis_major(S, V), w, symmetric)
    Kf = _fd_blocks(S, V[S.F], lambda P: _volume_grad(P, symmetric)) * w[:, None, None]
    assert np.abs(K - Kf).max() <= 1e-7 * np.abs(Kf).max()


def test_zero_area_facet_gives_zero_block():
    P = np.zeros((3, 3, 1))
    P[0, 1, 0] = 1.0
    P[0, 2, 0] = 2.0                      # three collinear corners
    U = np.ones((3, 3, 1))
    assert not np.any(area_blocks(P, U, np.ones(1)))
