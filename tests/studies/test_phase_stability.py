"""Direct tests of pyevolver.studies.phase_stability: the lowest eigenvalues
of the constrained, mass-weighted Hessian.

Closed form: the second variation of W = ∫H² dA (H = (κ1 + κ2)/2) at the
unit sphere under normal motions u is ½∫ Δu (Δ + 2)u dA, so on the
spherical harmonics of degree ℓ ≥ 2 the eigenvalues are
½ ℓ(ℓ+1)(ℓ(ℓ+1) − 2): 12 (five-fold) for ℓ = 2, 60 for ℓ = 3 (ℓ = 0 is
removed by the fixed area, ℓ = 1 by the rigid translations)."""
import io
import math

import numpy as np
import pytest
import scipy.linalg as la

from pyevolver import Session
from pyevolver.studies.meshes import icosphere, write_fe
from pyevolver.studies.phase_stability import (_basis, constrained_hessian, lowest_eigenvalues,
                                               stability)

HEADER = ("quantity willmore energy method normal_sq_mean_curvature global\n"
          "quantity surf fixed = 4*pi method facet_area global")


def _sphere(tmp_path, level, extra=""):
    X, F = icosphere(level)
    path = write_fe(str(tmp_path / f"s{level}.fe"), X, F, header=HEADER + extra,
                    face_attrs="tension 0")
    return Session.load(path, out=io.StringIO(), err=io.StringIO())


def test_sphere_spectrum_converges_to_the_closed_form(tmp_path):
    errs = []
    for level in (2, 3):
        ev = lowest_eigenvalues(_sphere(tmp_path, level), k=6)
        # Lanczos may return fewer copies of a degenerate eigenvalue than
        # its multiplicity: every value found is one of the two, the
        # smallest is ℓ = 2's
        errs.append(abs(ev[0] - 12) / 12)
        near = np.minimum(np.abs(ev - 12) / 12, np.abs(ev - 60) / 60)
        assert np.all(near < 0.1)
        assert abs(ev[-1] - 60) / 60 < 0.01                     # ℓ = 3
    assert errs[0] < 0.10 and errs[1] < 0.03
    assert errs[1] < errs[0] / 3                                # O(h²)


def test_lanczos_matches_the_dense_projected_problem(tmp_path):
    """The same eigenvalues from a dense null-space basis, in all vertex
    coordinates (3nv) and with the regularization left in the session
    (it is excluded from the Hessian, so λ must not change them)."""
    s = _sphere(tmp_path, 1, "\nquantity harm energy modulus 0.7 method harmonic_energy global")
    ev = lowest_eigenvalues(s, k=4, normal=False)
    H, B, m = constrained_hessian(s, normal=False)
    w = 1 / np.sqrt(m)
    Hs = w[:, None] * H.toarray() * w[None, :]
    Z = la.null_space(_basis(B / w[:, None]).T)
    dense = np.linalg.eigvalsh(Z.T @ Hs @ Z)[:4]
    assert np.allclose(ev, dense, rtol=1e-7, atol=1e-8)
    assert s.surface.quantities["harm"].modulus == 0.7         # restored


def test_stability_threshold():
    assert stability(np.array([0.5, 1.0]))
    assert stability(np.array([-1e-4, 1.0]))
    assert not stability(np.array([-0.1, 1.0]))
