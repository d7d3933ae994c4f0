"""``newton N`` (pyevolver/evolve/newton.py): damped Newton steps."""
import io
import math
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.studies.meshes import edges, torus_offset, write_fe


def _flat_grid(tmp_path, k=6, seed=0):
    """A k×k vertex grid of the plane z = 0.3x − 0.2y + 1 (every square split
    along the same diagonal), boundary vertices FIXED, interior vertices
    moved off the plane; energy harmonic_energy only."""
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="xy")
    i, j = i.ravel().astype(float), j.ravel().astype(float)
    X = np.stack([i, j, 0.3 * i - 0.2 * j + 1.0], 1)
    a, b = np.meshgrid(np.arange(k - 1), np.arange(k - 1), indexing="xy")
    a, b = a.ravel(), b.ravel()
    F = np.concatenate([np.stack([a + k * b, a + 1 + k * b, a + 1 + k * (b + 1)], 1),
                        np.stack([a + k * b, a + 1 + k * (b + 1), a + k * (b + 1)], 1)])
    inner = (i > 0) & (i < k - 1) & (j > 0) & (j < k - 1)
    rng = np.random.default_rng(seed)
    Y = X.copy()
    Y[inner] += 0.3 * rng.standard_normal((int(inner.sum()), 3))
    path = str(tmp_path / "flat.fe")
    write_fe(path, Y, F, header="quantity harm energy method harmonic_energy global",
             face_attrs="tension 0")
    s = Session.load(path, out=io.StringIO())
    s.surface.vattr["fixed"][:] = ~inner
    return s, X, F


def test_newton_finds_the_affine_harmonic_map(tmp_path):
    """E = (1/√3) Σ|e|² with the boundary fixed on a plane: on this grid the
    neighbours of an interior vertex come in opposite pairs, so the affine
    map (the plane itself) is the minimizer; E is quadratic, so Newton steps
    reach it at once (to round-off), and the energy is (1/√3) Σ|e|² of the
    planar grid."""
    s, X, F = _flat_grid(tmp_path)
    E, _ = edges(F)
    E_plane = np.sum(np.sum((X[E[:, 1]] - X[E[:, 0]]) ** 2, axis=1)) / math.sqrt(3)
    r = s.newton(10, echo=False)
    assert r.success and r.nit <= 3, r
    assert np.max(np.abs(s.surface.X - X)) < 1e-7          # converged: rtol 1e-10 on E
    assert abs(s.total_energy - E_plane) < 1e-9 * E_plane


def test_newton_torus_regularized_reaches_a_constrained_critical_point():
    """W_NormalCur + λE on the 10×16 torus with the area FIXED: newton keeps the
    area at its target and ends where the energy gradient is parallel to the
    area gradient (the KKT conditions), with a decreasing energy history."""
    from pyevolver.evolve import gradient as GR
    from pyevolver.studies import fig3_torus as F3
    s = Session.load(F3.datafile(10, 16, "NormalCur", True), out=io.StringIO())
    target = s.surface.quantities["area_fix"].target
    s.run("set vertex x x + 0.001*sin(12.9898*id); recalc")
    e0 = s.total_energy
    r = s.newton(60, echo=False)
    assert r.success, r
    assert np.all(np.diff([e0] + r.history) < 0)
    t = s.surface.evaluate()
    assert abs(t.quantity_values["area_fix"] - target) < 1e-8 * target
    g = GR.energy_gradient(t).ravel()
    a = GR.quantity_gradient(t, s.surface.quantities["area_fix"]).ravel()
    resid = g - (g @ a) / (a @ a) * a
    assert np.linalg.norm(resid) < 1e-4 * np.linalg.norm(g), np.linalg.norm(resid)


def test_newton_command_prints_steps_and_counts_down():
    from pyevolver.studies import fig3_torus as F3
    out = io.StringIO()
    s = Session.load(F3.datafile(10, 16, "EffArea", True), out=out)
    s.run("set vertex x x + 0.001*sin(12.9898*id); recalc")
    s.run("newton 3")
    lines = [ln for ln in out.getvalue().splitlines() if "delta:" in ln]
    assert [int(ln.split(".")[0]) for ln in lines] == [2, 1, 0][:len(lines)] and lines


def test_newton_with_a_fixed_volume_reaches_the_evolvers_full_newton_minimum(evolver):
    """cube.fe (area, body volume fixed at 1) refined once, `g 30`: the
    Evolver's Newton iteration on all coordinates (`hessian_normal off`, then
    `hessian` five times; it warns that the Hessian is not positive definite
    but converges) gives the minimum; `newton` from the same start reaches
    the same energy and keeps the volume."""
    from reference import run_reference
    path = os.path.join(os.path.dirname(os.path.dirname(__file__)), "..", "datafiles", "cube.fe")
    lines = run_reference(evolver, path, "r\ng 30\nhessian_normal off\n" + "hessian\n" * 5 +
                          'printf "RESULT %.17g\\n", total_energy\n')
    ref = next(float(ln.split()[1]) for ln in lines if ln.startswith("RESULT"))
    b = Session.load(path, out=io.StringIO())
    b.run("r; g 30")
    r = b.newton(50, echo=False)
    assert r.success, r
    assert abs(b.total_energy - ref) < 1e-8 * ref, (b.total_energy, ref)
    assert abs(b.totals.volumes[0] - 1.0) < 1e-8


def test_clock_counts_seconds():
    s = Session.load(os.path.join(os.path.dirname(os.path.dirname(__file__)), "..", "datafiles", "cube.fe"),
                     out=io.StringIO())
    out = io.StringIO()
    s.out = out
    s.run("c1 := clock; g 5; print clock - c1 >= 0; print clock < 3600")
    assert out.getvalue().split()[-2:] == ["1", "1"]


def test_torus_offset_is_regular_and_on_the_torus():
    """Every vertex of valence 6, Euler characteristic 0, outward oriented
    (positive volume), vertices on the torus of radii R, r."""
    R, r = math.sqrt(2.0), 1.0
    X, F = torus_offset(10, 16, R, r)
    E, _ = edges(F)
    assert set(np.bincount(E.ravel()).tolist()) == {6}
    assert len(X) - len(E) + len(F) == 0
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    assert np.einsum("ij,ij->i", a, np.cross(b, c)).sum() > 0
    rho = np.hypot(X[:, 0], X[:, 1])
    assert np.allclose(np.hypot(rho - R, X[:, 2]), r)
    with pytest.raises(ValueError):
        torus_offset(10, 15)


def test_factor_without_cholmod_refuses_indefinite_matrices_as_cholmod_does(monkeypatch):
    """The SuperLU fallback of the damped Newton step answers "not positive
    definite" exactly when the smallest eigenvalue is not positive (inertia of
    the symmetric LU pivots), and otherwise solves."""
    import numpy as np
    import scipy.sparse as sp
    from pyevolver.evolve import newton as NW
    monkeypatch.setattr(NW, "_cholmod", lambda: None)
    A = sp.random(120, 120, density=0.03, random_state=3)
    A = A + A.T
    lam = np.linalg.eigvalsh(A.toarray())
    b = np.arange(120, dtype=float)
    for shift in (-lam.min() + 0.1, -lam.min() - 0.1, 0.0):
        M = (A + shift * sp.eye(120)).tocsc()
        f = NW._factor(M)
        if lam.min() + shift > 0:
            assert f is not None and np.allclose(M @ f(b), b)
        else:
            assert f is None


_CHAIN = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data", "string_chain.fe")


def _chain(*cmds):
    out = io.StringIO()
    s = Session.load(_CHAIN, out=out)
    e0 = s.total_energy
    for c in cmds:
        s.run(c + "\n")
    return s, e0, out.getvalue()


_CUBE = os.path.join(os.path.dirname(os.path.dirname(__file__)), "..", "datafiles", "cube.fe")


def _cube_g2(*cmds):
    """cube.fe after ``g 2``: its Newton step raises the area (by 3.7e-5;
    tests/reference/test_eigen_reference.py, check_increase, compares REF)."""
    out = io.StringIO()
    s = Session.load(_CUBE, out=out)
    s.run("g 2\n")
    e0 = s.total_energy
    for c in cmds:
        s.run(c + "\n")
    return s, e0, out.getvalue()


def test_hessian_takes_the_rising_newton_step_as_the_evolver():
    s, e0, _ = _cube_g2("hessian")
    assert s.total_energy > e0 + 1e-6


def test_hessian_backtrack_halves_a_rising_step():
    s, e0, out = _cube_g2("hessian_backtrack on", "hessian")
    # (on cube.fe after g 2 no fraction of the step lowers the area: scale 0,
    # and the surface stays as it was)
    assert "hessian: the Newton step raised the energy; step scaled by 0 " in out
    assert s.total_energy == pytest.approx(e0, rel=1e-14)


def test_check_increase_undoes_a_rising_step_even_with_backtrack():
    """(REF's WARNING 1596 goes to stderr; the energy tells the step was undone.)"""
    s, e0, out = _cube_g2("check_increase on", "hessian_backtrack on", "hessian")
    assert s.total_energy == pytest.approx(e0, rel=1e-14)
    assert "step scaled" not in out


def test_hessian_seek_never_rises():
    s, e0, _ = _chain("hessian_seek")
    assert s.total_energy <= e0
    for _ in range(3):
        e = s.total_energy
        s.run("hessian_seek\n")
        assert s.total_energy <= e * (1 + 1e-13)
