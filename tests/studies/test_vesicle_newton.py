"""pyevolver.studies.vesicle_newton: the damped Newton solver of Figure 4
and the harmonic-energy continuation, on the 42-vertex icosphere
(studies.meshes, level 1) deformed into the prolate family (area 4π,
reduced volume 0.85).

What is checked is what the method guarantees: a step is kept only when
the energy does not rise; the bordered solve is exact; the step has no
rigid motion (the vertex centroid stays put: the area and volume gradients
sum to zero over the vertices); near the minimum the residual falls
quadratically and the fixed values are met; the continuation keeps only
healthy stages and undoes the first unhealthy one.
"""
from __future__ import annotations

import io
import math

import numpy as np
import pytest
import scipy.sparse as sp

from pyevolver import Session
from pyevolver.studies.meshes import icosphere
from pyevolver.evolve.symfactor import ND_MIN
from pyevolver.studies.vesicle_newton import (_bordered, _rigid_motions, harmonic_continuation,
                                              newton_lm, solve_step)
from pyevolver.studies.vesicle_shapes import initial_shape, min_angle, write_datafile

FOURPI = 4 * math.pi
V0 = 0.85 * FOURPI / 3          # the prolate's volume at area 4π


@pytest.fixture(scope="module")
def prolate42(tmp_path_factory):
    X, F = initial_shape("prolate", 1)
    assert len(X) == len(icosphere(1)[0]) == 42
    path = str(tmp_path_factory.mktemp("vn") / "prolate42.fe")
    return write_datafile(path, X, F, "prolate", "normal")


def load(path):
    return Session.load(path, out=io.StringIO(), err=io.StringIO())


def test_rigid_motions_are_an_orthonormal_basis():
    X, _ = icosphere(1)
    X = X * np.array([1.0, 1.3, 0.7]) + np.array([0.2, -1.0, 3.0])
    Q = _rigid_motions(X)
    assert Q.shape == (3 * len(X), 6)
    assert np.allclose(Q.T @ Q, np.eye(6), atol=1e-13)
    # a translation and an infinitesimal rotation about an axis through a point
    w, p = np.array([0.3, -0.5, 0.8]), np.array([1.0, 2.0, -1.0])
    for field in (np.tile([1.0, 2.0, -3.0], len(X)), np.cross(w, X - p).ravel()):
        assert np.linalg.norm(field - Q @ (Q.T @ field)) < 1e-12 * np.linalg.norm(field)
    # a stretch is not a rigid motion
    stretch = (X * np.array([1.0, 0.0, 0.0])).ravel()
    assert np.linalg.norm(stretch - Q @ (Q.T @ stretch)) > 0.1 * np.linalg.norm(stretch)


@pytest.mark.parametrize("definite", [True, False])
def test_bordered_solve_matches_the_dense_system(definite):
    rng = np.random.default_rng(3)
    n, k = 12, 3
    A = rng.standard_normal((n, n))
    K = A @ A.T + n * np.eye(n) if definite else A + A.T
    B = rng.standard_normal((n, k))
    r, d = rng.standard_normal(n), rng.standard_normal(k)
    y = _bordered(sp.csc_matrix(K), B, r, d, {})
    full = np.block([[K, B], [B.T, np.zeros((k, k))]])
    expect = np.linalg.solve(full, np.concatenate([r, d]))[:n]
    assert np.allclose(y, expect, rtol=1e-9, atol=1e-11)
    assert np.allclose(B.T @ y, d, atol=1e-11)


@pytest.mark.parametrize("singular", [False, True])
def test_large_bordered_solve_by_the_engine_solver_is_exact(singular, monkeypatch):
    """Above ND_MIN unknowns :func:`solve_step` takes the engine's
    hessian solver (nested-dissection LDLᵀ of K + δI, Schur complement of
    the border, refinement): on 3 coordinates of 900 grid points (2,700
    unknowns) with an indefinite stencil K — also singular along the
    translations, which the border holds as the rigid motions do on a
    closed surface — the solution meets the bordered system to round-off
    (checked by the residual of the sparse system itself)."""
    m = 30
    g = np.stack(np.meshgrid(np.arange(m), np.arange(m), indexing="ij"), -1).reshape(-1, 2)
    pts = np.column_stack([g, np.zeros(len(g))]).astype(float)
    L = sp.diags([4.0] * m * m) - sp.diags([1.0] * (m * m - 1), 1) - sp.diags(
        [1.0] * (m * m - 1), -1) - sp.diags([1.0] * (m * m - m), m) - sp.diags(
        [1.0] * (m * m - m), -m)
    L = sp.csr_matrix(L - sp.diags(np.asarray(L.sum(axis=1)).ravel()))   # rows sum to 0
    K = sp.kron(L - (0.0 if singular else 0.3) * sp.identity(m * m)
                + 0.05 * sp.diags(np.sin(np.arange(m * m))), sp.identity(3)).tocsc()
    n = K.shape[0]
    assert n > ND_MIN
    rng = np.random.default_rng(4)
    T = np.zeros((n, 3))
    for k in range(3):
        T[k::3, k] = 1 / math.sqrt(m * m)                 # translations
    B = np.column_stack([T, rng.standard_normal((n, 2))])
    if singular:                      # K's null space: exactly the translations
        K = sp.kron(L, sp.identity(3)).tocsc()
        assert np.abs(K @ T).max() < 1e-12
    r, d = rng.standard_normal(n), np.concatenate([np.zeros(3), rng.standard_normal(2)])
    import pyevolver.studies.vesicle_newton as VN

    def no_fallback(*a, **k):
        raise AssertionError("SuperLU on the bordered matrix")
    monkeypatch.setattr(VN, "solve_bordered", no_fallback)
    z = solve_step(K, B, r, d, np.repeat(pts, 3, axis=0))
    y, mu = z[:n], z[n:]
    assert np.abs(K @ y + B @ mu - r).max() < 1e-9 * np.abs(r).max()
    assert np.abs(B.T @ y - d).max() < 1e-11


def test_first_steps_lower_the_energy_and_the_residual(prolate42):
    s = load(prolate42)
    c0 = s.surface.X.mean(0).copy()
    energies = [s.totals.energy]
    gnorms, resid = [], [abs(s.totals.total_area - FOURPI) + abs(s.totals.volumes[0] - V0)]
    for _ in range(2):                       # one Newton step per call
        ok, steps, g = newton_lm(s, maxit=1)
        assert (ok, steps) == (False, 1)
        t = s.totals
        energies.append(t.energy)
        gnorms.append(g)
        resid.append(abs(t.total_area - FOURPI) + abs(t.volumes[0] - V0))
    assert energies[1] < energies[0] and energies[2] <= energies[1]
    assert gnorms[1] < gnorms[0]
    assert resid[2] < resid[1] < 1e-3
    # no translation: the vertex centroid stays put
    assert np.allclose(s.surface.X.mean(0), c0, atol=1e-14)
    # then convergence, quadratic: a few steps to max |∇L| < 1e-9
    ok, steps, g = newton_lm(s)
    assert ok and steps <= 6 and g < 1e-9
    t = s.totals
    assert abs(t.total_area - FOURPI) < 1e-10 * FOURPI and abs(t.volumes[0] - V0) < 1e-10 * V0
    assert t.energy <= energies[-1]
    # the energy is the Willmore quantity plus the harmonic one
    assert t.energy == pytest.approx(t.quantity_values["willmore"] + t.quantity_values["harm"],
                                     rel=1e-13)


def test_continuation_keeps_healthy_stages_and_undoes_the_first_bad_one(prolate42):
    s = load(prolate42)
    log = []
    # a 38.8° floor: λ = 1 keeps every angle above it (39.5°), halving λ does not
    lam = harmonic_continuation(s, lam_min=0.25, min_angle_deg=38.8, log=log)
    assert [e["lambda"] for e in log] == [1.0, 0.5]
    first, second = log
    assert first["kept"] and first["converged"] and first["min_angle_deg"] >= 38.8
    assert not second["kept"] and second["min_angle_deg"] < 38.8
    # the last kept stage is back: its λ, its surface, its energy
    assert lam == 1.0 and s.surface.quantities["harm"].modulus == 1.0
    assert min_angle(s.surface.X, s.surface.F) == pytest.approx(first["min_angle_deg"],
                                                                 rel=1e-12)
    assert s.totals.quantity_values["willmore"] == pytest.approx(first["W"], rel=1e-12)
    assert abs(s.totals.total_area - FOURPI) < 1e-10 * FOURPI
    assert abs(s.totals.volumes[0] - V0) < 1e-10 * V0


def test_continuation_stops_at_once_when_the_start_is_unhealthy(prolate42):
    s = load(prolate42)
    log = []
    lam = harmonic_continuation(s, lam_min=0.25, min_angle_deg=89.0, log=log)
    assert lam == 1.0 and len(log) == 1 and not log[0]["kept"]
    assert s.surface.quantities["harm"].modulus == 1.0
