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
from pyevolver.errors import UnsupportedError
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


# -- the ADE energy: the rank-one term 2k ∇M ∇Mᵀ of its Hessian -------------------------

def _ellipsoid_ade(tmp_path, alpha=1.4, m0=1.1):
    """The ADE datafile energy (FUNCTION quantity, phase_ade.ade_header) on
    an icosphere stretched to an ellipsoid (not a critical point: only the
    Hessian matters), area fixed at 4π and the volume at its own."""
    from pyevolver.studies.phase_ade import ade_header
    X, F = icosphere(2)
    X = X * np.array([1.25, 1.0, 0.8])
    vol = float(np.einsum("ij,ij->i", X[F[:, 0]], np.cross(X[F[:, 1]], X[F[:, 2]])).sum() / 6)
    hdr = (ade_header(0.0, alpha, m0, method="normal_sq_mean_curvature")
           + "quantity surf fixed = 4*pi method facet_area global\n")
    path = write_fe(str(tmp_path / "ell.fe"), X, F, header=hdr, face_attrs="tension 0")
    with open(path, "a") as fh:
        fh.write("\nbodies\n1 " + " ".join(str(i + 1) for i in range(len(F)))
                 + f" volume {vol!r}\n")
    return Session.load(path, out=io.StringIO(), err=io.StringIO()), X, F, vol


def test_ade_rank_term_in_lanczos_matches_dense(tmp_path):
    """With the nonlinear FUNCTION quantity the operator and the bordered
    shift-invert system carry ``W diag(±1) Wᵀ``: the eigenvalues equal the
    dense projected ones of ``H + W diag(±1) Wᵀ``; without the rank term
    (the sparse H alone) they differ."""
    from pyevolver.studies.phase_stability import constrained_system
    s, *_ = _ellipsoid_ade(tmp_path)
    ev = lowest_eigenvalues(s, k=4)
    H, B, m, W, sign = constrained_system(s)
    assert W is not None and W.shape[1] == 1 and sign[0] == 1.0
    w = 1 / np.sqrt(m)
    Z = la.null_space(_basis(B / w[:, None]).T)
    Hs = w[:, None] * H.toarray() * w[None, :]
    Ws = w[:, None] * W
    dense = np.linalg.eigvalsh(Z.T @ (Hs + (Ws * sign) @ Ws.T) @ Z)
    bare = np.linalg.eigvalsh(Z.T @ Hs @ Z)
    assert np.allclose(ev, dense[:4], rtol=1e-7, atol=1e-8)
    assert np.abs(bare[:4] - dense[:4]).max() > 1e-3 * np.abs(dense[:4]).max()
    with pytest.raises(UnsupportedError, match="nonlinear FUNCTION"):
        constrained_hessian(s)


def test_linearised_ade_point_with_extra_term_equals_the_function(tmp_path):
    """phase_ade_points solves with the ADE term linearised (``μM``,
    μ = 2k(M − M0)) and adds ``2k ∇M ∇Mᵀ`` (``extra``): at the same mesh
    its eigenvalues are those of the FUNCTION quantity's Hessian."""
    from pyevolver.studies import phase_ade_points as PP
    alpha, m0 = 1.4, 1.1
    s, X, F, vol = _ellipsoid_ade(tmp_path, alpha, m0)
    ev = lowest_eigenvalues(s, k=3)
    k = np.pi * alpha / (4 * np.pi)
    M = s.value("mci.value")
    mu = 2 * k * (M - 4 * np.pi * m0)
    lin = PP.ade_eigenvalues(X, F, vol / (4 * np.pi / 3), 0.3, 0.0, mu, k,
                             "normal_sq_mean_curvature")
    assert np.allclose(lin, ev, rtol=1e-9, atol=1e-10)
