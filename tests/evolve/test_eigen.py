"""Eigenvalues of the constrained Hessian (pyevolver/evolve/eigen.py) on
cases with a known spectrum.

* The periodic path Laplacian (circulant, eigenvalues 2 − 2cos(2πj/n))
  with the constraint Σy = 0, which removes exactly the constant mode
  (eigenvalue 0): the constrained spectrum is the rest.
* A flat grid with ``harmonic_energy`` (E = (1/√3) Σ|e|², Hessian
  (2/√3) L ⊗ I₃ with L the graph Laplacian) and its boundary fixed: the
  eigenvalues are (2/√3) times those of the Dirichlet graph Laplacian,
  with ``hessian_normal`` (one per vertex, the unit normal) and without it
  (each three times).
"""
import io
import math
import os

import numpy as np
import pytest
import scipy.sparse as sp

from pyevolver import Session
from pyevolver.evolve import eigen as EG
from pyevolver.evolve.hessian import Basis, HessianSystem, hessian_system
from pyevolver.studies.meshes import write_fe


def _system(K, B=None, rhs=None):
    n = K.shape[0]
    basis = Basis(np.tile(np.eye(3)[:, :1], (n, 1, 1)), np.ones(n, np.int64))
    rhs = np.zeros(n) if rhs is None else rhs
    return HessianSystem(sp.csc_matrix(K), B, rhs, None, basis.matrix(), basis,
                         np.zeros(0), [], np.ones(n, bool), np.zeros((n, 3)))


def _circulant(n):
    K = 2 * sp.identity(n) - sp.eye(n, k=1) - sp.eye(n, k=-1)
    K = K.tolil()
    K[0, n - 1] = K[n - 1, 0] = -1
    exact = np.sort(2 - 2 * np.cos(2 * np.pi * np.arange(1, n) / n))   # without j = 0
    return K.tocsc(), np.ones((n, 1)), exact


@pytest.mark.parametrize("dense_max", [EG.DENSE_MAX, 0])
def test_nearest_on_the_constrained_circulant(dense_max):
    n = 40
    K, B, exact = _circulant(n)
    hs = _system(K, B)
    for shift in (0.0, 1.3, -0.5):
        r = EG.nearest(hs, shift, 6, dense_max=dense_max)
        want = np.sort(exact[np.lexsort((exact, np.abs(exact - shift)))][:6])
        assert np.allclose(r.values, want, atol=1e-10)
        assert np.allclose(B.T @ r.vectors, 0, atol=1e-10)              # keep Σy = 0
        assert np.allclose(K @ r.vectors, r.vectors * r.values, atol=1e-8)


@pytest.mark.parametrize("dense_max", [EG.DENSE_MAX, 0])
def test_inertia_of_the_constrained_circulant(dense_max):
    n = 40
    K, B, exact = _circulant(n)
    hs = _system(K, B)
    for shift in (0.0, 0.5, 1.0, 3.9, 5.0):
        got = EG.inertia(hs, shift, eps=1e-10, dense_max=dense_max)
        assert (got.below, got.equal, got.above) == (
            int(np.sum(exact < shift - 1e-10)), int(np.sum(abs(exact - shift) <= 1e-10)),
            int(np.sum(exact > shift + 1e-10)))
    # at an eigenvalue (double: j and n − j): two equal
    for j in (1, 3, 10):
        lam = 2 - 2 * math.cos(2 * math.pi * j / n)
        got = EG.inertia(hs, lam, dense_max=dense_max)
        assert (got.below, got.equal) == (2 * j - 2, 2)
    # without the constraint the zero mode is there
    got = EG.inertia(_system(K), 0.0, dense_max=dense_max)
    assert got.line() == "Eigencounts:    0 <,  1 ==,  39 > \n"
    # the pivots of one LDLᵀ factorization give the same counts away from eigenvalues
    assert EG.ShiftedFactor(K, B, 1.0, 0.0).inertia() == EG.inertia(hs, 1.0)


def test_lowest_and_inverse_iteration_with_negative_eigenvalues():
    n = 30
    K, B, exact = _circulant(n)
    c = 0.3
    hs = _system(K - c * sp.identity(n), B, rhs=np.linspace(-1, 1, n))
    low = EG.lowest(hs)
    assert abs(low.values[0] - (exact[0] - c)) < 1e-10
    assert low.inertia.below == int(np.sum(exact < c))
    # inverse iteration converges to the eigenvalue nearest the probe
    target = exact[7] - c
    p = EG.inverse_iteration(hs, target + 0.01, 200)
    assert abs(p.value - target) < 1e-9
    assert p.lines[0].startswith("0  ev = ")
    assert float(p.vector @ hs.rhs) >= 0                           # downhill
    assert abs(np.linalg.norm(p.vector) - 1) < 1e-12


def _dirichlet_grid(tmp_path, k=7):
    """A flat k×k grid (squares split on one diagonal), boundary FIXED,
    energy harmonic_energy only; returns the session and the eigenvalues
    of the Dirichlet graph Laplacian of the interior vertices."""
    i, j = np.meshgrid(np.arange(k), np.arange(k), indexing="xy")
    i, j = i.ravel().astype(float), j.ravel().astype(float)
    X = np.stack([i, j, np.zeros_like(i)], 1)
    a, b = np.meshgrid(np.arange(k - 1), np.arange(k - 1), indexing="xy")
    a, b = a.ravel(), b.ravel()
    F = np.concatenate([np.stack([a + k * b, a + 1 + k * b, a + 1 + k * (b + 1)], 1),
                        np.stack([a + k * b, a + 1 + k * (b + 1), a + k * (b + 1)], 1)])
    path = str(tmp_path / "grid.fe")
    write_fe(path, X, F, header="quantity harm energy method harmonic_energy global",
             face_attrs="tension 0")
    s = Session.load(path, out=io.StringIO())
    inner = (i > 0) & (i < k - 1) & (j > 0) & (j < k - 1)
    s.surface.vattr["fixed"][:] = ~inner
    # graph Laplacian from the triangles' edges, independently of pyevolver
    E = {tuple(sorted((int(f[m]), int(f[(m + 1) % 3])))) for f in F for m in range(3)}
    L = np.zeros((k * k, k * k))
    for u, v in E:
        L[u, v] = L[v, u] = -1
        L[u, u] += 1
        L[v, v] += 1
    idx = np.nonzero(inner)[0]
    return s, np.linalg.eigvalsh(L[np.ix_(idx, idx)]) * 2 / math.sqrt(3)


@pytest.mark.parametrize("normal", [True, False])
def test_harmonic_grid_spectrum(tmp_path, normal):
    s, lap = _dirichlet_grid(tmp_path)
    hs = hessian_system(s.iterator, normal=normal)
    want = lap if normal else np.sort(np.repeat(lap, 3))
    r = EG.nearest(hs, 0.0, len(want))
    assert np.allclose(np.sort(r.values), want, atol=1e-9)
    assert EG.inertia(hs, float(lap[3]) + 1e-6).below == (4 if normal else 12)


@pytest.mark.parametrize("cholmod", [True, False])
def test_factor_inertia_with_and_without_cholmod(monkeypatch, cholmod):
    """The LDLᵀ pivots count the eigenvalues below a shift with CHOLMOD and
    with the SuperLU fallback alike (a shift away from the eigenvalues)."""
    if not cholmod:
        monkeypatch.setattr(EG, "_cholmod", lambda: None)
    K, B, exact = _circulant(24)
    for shift in (-0.1, 0.7, 2.05, 3.3):
        got = EG.ShiftedFactor(K, B, shift, 0.0).inertia()
        assert (got.below, got.equal, got.above) == (
            int(np.sum(exact < shift)), 0, int(np.sum(exact > shift)))
    fac = EG.ShiftedFactor(K, B, 0.7, 0.0)
    x = np.sin(np.arange(24.0))
    x -= x.mean()
    y = fac.op(x)                                # (K − 0.7) y = x on Σy = 0
    assert abs(y.sum()) < 1e-10
    r = K @ y - 0.7 * y - x
    assert np.allclose(r - r.mean(), 0, atol=1e-10)


def test_no_note_for_fixed_global_quantities(tmp_path):
    """REF refuses FIXED quantities of global methods in the Hessian (ERROR
    3362) only with worker threads (-p1); single-threaded it steps, so
    pyevolver says nothing (tests/reference/test_eigen_reference.py,
    column.fe, compares the steps)."""
    text = open(os.path.join(os.path.dirname(__file__), "..", "..", "datafiles",
                             "cube.fe")).read()
    path = tmp_path / "cubeq.fe"
    path.write_text(text.replace("vertices", "quantity qa fixed = 6 method facet_area global"
                                 "\n\nvertices", 1))
    s = Session.load(str(path), out=io.StringIO())
    assert EG.beyond_reference(s.surface) == []


def test_linear_metric_on_the_uniform_grid(tmp_path):
    """On the uniform grid every interior vertex has six triangles of area
    1/2: the star metric A_v/3 is the identity, so mix 0 gives the plain
    spectrum; any mix gives K v = μ M v, the same values on the sparse path."""
    s, lap = _dirichlet_grid(tmp_path)
    hs = EG.metric(hessian_system(s.iterator, normal=True), s.surface, mix=0.0)
    assert np.allclose(hs.M.toarray(), np.eye(len(lap)), atol=1e-14)
    assert np.allclose(EG.nearest(hs, 0.0, len(lap)).values, lap, atol=1e-9)
    hs = EG.metric(hessian_system(s.iterator, normal=True), s.surface, mix=0.5)
    dense = EG.nearest(hs, 1.0, 4)
    sparse = EG.nearest(hs, 1.0, 4, dense_max=0)
    assert np.allclose(dense.values, sparse.values, atol=1e-9)
    r = hs.K @ dense.vectors - hs.M @ dense.vectors * dense.values
    assert np.allclose(r, 0, atol=1e-9)
    assert EG.inertia(hs, 1.0) == EG.inertia(hs, 1.0, dense_max=0)
    low = EG.lowest(hs, dense_max=0)
    assert abs(low.values[0] - EG.nearest(hs, -1.0, 1).values[0]) < 1e-9


@pytest.mark.parametrize("cholmod", [pytest.param(True, marks=pytest.mark.cholmod), False])
def test_hessian_index_with_and_without_the_steps_pivots(monkeypatch, cholmod):
    """newton._index, REF's "Index" of warning 1825: from the solve's LDLᵀ
    pivots (CHOLMOD) or, without them, one factorization; the constrained
    circulant shifted by −c has as many negative eigenvalues as exact < c."""
    from pyevolver.evolve import newton
    from pyevolver.evolve.hessian import solve_bordered
    if not cholmod:
        monkeypatch.setattr(EG, "_cholmod", lambda: None)
        monkeypatch.setattr(newton, "_cholmod", lambda: None)
    K, B, exact = _circulant(30)
    for c in (0.05, 0.5, 1.7):
        hs = _system(K - c * sp.identity(30), B)
        piv: list = []
        if cholmod:
            solve_bordered(hs.K, hs.B, np.zeros(30), np.zeros(1), pivots=piv)
            assert piv
        assert newton._index(hs, piv, 1e-10) == int(np.sum(exact < c))


def test_arpack_without_convergence_is_a_plain_error(monkeypatch):
    """100grain.fe after `g 5` has 101 zero eigenvalues and ARPACK does not
    converge near them: a plain message, not an internal error."""
    import scipy.sparse.linalg as spla
    from pyevolver.errors import CommandError
    s = Session.load(os.path.join(os.path.dirname(__file__), "..", "..", "datafiles",
                                  "cube.fe"), out=io.StringIO())
    s.run("g 2")
    hs = hessian_system(s.iterator, normal=True)

    def no_convergence(*args, **kwargs):
        raise spla.ArpackNoConvergence("no convergence", np.zeros(0), np.zeros((0, 0)))
    monkeypatch.setattr(spla, "eigsh", no_convergence)
    with pytest.raises(CommandError, match="did not converge near 0 .0 of 2 eigenvalues"):
        EG._near(hs, 0.0, 2, 1e-10, dense_max=0)
