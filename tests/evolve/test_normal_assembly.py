"""The one-pass assembly of the facet terms of a hessian_normal Hessian
(evolve/normal_assembly.py) against Tᵀ H T of the full (3nv, 3nv) Hessians
of methods/basic.py, and the step it serves against the general path."""
import io

import numpy as np
import pytest

from conftest import example, jittered_surface
from pyevolver import Session
from pyevolver.evolve import hessian as H
from pyevolver.evolve import normal_assembly as NA


@pytest.fixture(scope="module")
def bumpy_mound():
    return jittered_surface("mound.fe", 12, 0.03)


@pytest.mark.parametrize("symmetric", [False, True])
def test_assembly_equals_TtHT(bumpy_mound, symmetric):
    """Area plus volume assembled in one pass equals Tᵀ (H_A + H_V) T, with
    some vertices fixed (no unknown) and the others along one direction."""
    S = bumpy_mound
    t = S.evaluate()
    rng = np.random.default_rng(8)
    ndof = (rng.random(S.nv) < 0.8).astype(int)
    B = rng.standard_normal((S.nv, 3, 1))
    basis = H.Basis(B, ndof)
    T = basis.matrix()
    wa, wv = np.linspace(0.5, 2.0, S.nf), np.linspace(-1.0, 1.0, S.nf)
    fb = NA.applies(t, basis)
    assert fb is not None
    fb.area(wa)
    fb.volume(wv, symmetric)
    M = fb.matrix()
    full = (H.facet_area_hessian(t, wa) + H.facet_volume_hessian(t, wv, symmetric)).toarray()
    ref = T.T @ full @ T
    assert M.shape == ref.shape
    assert np.abs(M.toarray() - ref).max() <= 1e-12 * np.abs(ref).max()


def test_general_bases_take_the_other_path(bumpy_mound):
    t = bumpy_mound.evaluate()
    basis = H.Basis(np.zeros((bumpy_mound.nv, 3, 2)) + 1.0, np.full(bumpy_mound.nv, 2))
    assert NA.applies(t, basis) is None
    assert NA.applies(t, None) is None


def test_hessian_step_is_the_same_with_and_without_the_blocks(monkeypatch):
    """The Newton system of the cube with the blocks equals the general
    path's (each term assembled on its own) to round-off."""
    systems = []
    for use in (True, False):
        if not use:
            monkeypatch.setattr(NA, "applies", lambda t, basis: None)
        s = Session.load(example("cube.fe"), out=io.StringIO())
        s.run("r\ng 5\n")
        systems.append(H.hessian_system(s.iterator))
    a, b = systems
    assert abs(a.K - b.K).max() <= 1e-13 * abs(b.K).max()
    assert np.array_equal(a.rhs, b.rhs)
