"""The axisymmetric Canham reference (pyevolver.studies.axisymmetric).

Expected numbers come only from closed forms (the sphere, 4π), theorems
(W ≥ 4π for closed surfaces, Willmore) or from consistency between
independent resolutions of the same solver (convergence under refinement,
two collocation densities, the volume multiplier against a difference of
energies).
"""
import numpy as np
import pytest

from pyevolver.studies import axisymmetric as ax
from pyevolver.studies.axisymmetric import canham_reference

FOURPI = 4 * np.pi


def _constraints_ok(res, tol=1e-10):
    assert abs(res.area - FOURPI) < tol
    assert abs(res.volume - res.v0 * FOURPI / 3) < tol
    assert abs(res.closure) < tol
    # the returned profile closes on the axis at both poles
    assert abs(res.r[0]) < 1e-12 and abs(res.r[-1]) < 1e-9


def test_sphere_is_4pi():
    res = canham_reference(1.0, "prolate", n=8)
    assert abs(res.W - FOURPI) < 1e-8
    _constraints_ok(res)
    assert res.descriptors["type"] == "sphere"
    # the profile is the unit circle
    assert np.max(np.abs(np.hypot(res.r, res.z - 1.0) - 1.0)) < 1e-10


def test_gradients_match_differences():
    rng = np.random.default_rng(1)
    b = ax._Basis(10, 40)
    a = 0.1 * rng.normal(size=10)
    W, gW, c, gc, v, gv, *_ = b.evaluate(a)
    eps = 1e-6
    for i in range(10):
        e = np.zeros(10)
        e[i] = eps
        p, m = b.evaluate(a + e), b.evaluate(a - e)
        assert abs((p[0] - m[0]) / (2 * eps) - gW[i]) < 1e-6 * max(1, abs(gW[i]))
        assert abs((p[2] - m[2]) / (2 * eps) - gc[i]) < 1e-7
        assert abs((p[4] - m[4]) / (2 * eps) - gv[i]) < 1e-7


def _converges(v0, branch, ns, coef_chain=False, ratio=5.0):
    """Energies at increasing n; successive differences must shrink by at
    least ``ratio`` each step (spectral: exponential convergence) until they
    reach round-off."""
    out, prev = [], None
    for n in ns:
        res = canham_reference(v0, branch, n=n,
                               coef0=None if (prev is None or not coef_chain) else prev.coef)
        _constraints_ok(res)
        out.append(res)
        prev = res
    W = np.array([r.W for r in out])
    d = np.abs(np.diff(W))
    for d0, d1 in zip(d[:-1], d[1:]):
        assert d1 < d0 / ratio or d1 < 1e-12 * W[-1]
    assert d[-1] < 1e-6 * W[-1]
    return out


def test_prolate_085_converges_and_is_prolate():
    out = _converges(0.85, "prolate", [6, 8, 10, 12, 16, 24])
    res = out[-1]
    assert res.W > FOURPI
    d = res.descriptors
    assert d["type"] == "prolate" and d["height_width"] > 1.5
    assert d["z_monotone"] and d["psi_min"] >= -1e-12 and d["psi_max"] <= np.pi + 1e-12
    assert d["updown_asym"] < 1e-8


def test_discocyte_062_converges_and_is_biconcave():
    out = _converges(0.62, "discocyte", [6, 8, 10, 12, 16])
    d = out[-1].descriptors
    assert out[-1].W > FOURPI
    assert d["type"] == "discocyte" and d["height_width"] < 0.5
    assert not d["z_monotone"] and d["psi_min"] < -0.1 and d["psi_max"] > np.pi + 0.1
    assert d["updown_asym"] < 1e-8 and not d["r_interior_min"]


def test_stomatocyte_050_converges_and_is_cup():
    out = _converges(0.50, "stomatocyte", [96, 128, 160], coef_chain=True, ratio=20.0)
    res = out[-1]
    d = res.descriptors
    assert res.W > FOURPI
    assert d["type"] == "stomatocyte"
    assert d["psi_max"] > 1.5 * np.pi            # the profile folds back into a bulb
    assert d["r_interior_min"] and not d["z_monotone"]
    assert d["updown_asym"] > 1.0
    # the inner pole lies inside: between the bottom and the top of the outer surface
    assert res.z.min() - 1e-12 <= res.z[-1] < res.z.max()


def test_two_collocation_densities_agree():
    a = canham_reference(0.62, "oblate", n=24, oversample=4)
    b = canham_reference(0.62, "oblate", n=24, oversample=7, coef0=a.coef)
    assert abs(a.W - b.W) < 1e-11 * a.W


def test_volume_multiplier_is_dW_dv():
    # at the constrained minimum dW*/dv0 equals the multiplier of v(a) = v0
    h = 1e-4
    mid = canham_reference(0.85, "prolate", n=24)
    up = canham_reference(0.85 + h, "prolate", n=24, coef0=mid.coef)
    dn = canham_reference(0.85 - h, "prolate", n=24, coef0=mid.coef)
    assert abs((up.W - dn.W) / (2 * h) - mid.lagrange[1]) < 1e-5 * abs(mid.lagrange[1])
    assert mid.lagrange[1] < 0                      # less volume, more bending


def test_unknown_branch_refused():
    with pytest.raises(ValueError, match="branch"):
        canham_reference(0.8, "torus")


def test_cli_prints_w(capsys):
    ax.main(["--v0", "0.85", "--branch", "prolate", "--n", "16"])
    out = capsys.readouterr().out
    W = float(out.splitlines()[0].split("=")[1])
    assert abs(W - canham_reference(0.85, "prolate", n=16).W) < 1e-11
    assert "type = prolate" in out


def test_a_failed_or_wandering_reference_is_said(capsys):
    """The stomatocyte's initial cup at v0 = 0.6 gives the trust region
    only non-finite trial shapes: a named error (exit status 1 from the
    command line), no traceback; at v0 = 0.65 it falls to the discocyte,
    which the command line says."""
    with pytest.raises(ax.NotConverged, match="stomatocyte reference at v0 = 0.6"):
        canham_reference(0.6, "stomatocyte", n=16)
    assert ax.main(["--v0", "0.6", "--branch", "stomatocyte", "--n", "16"]) == 1
    assert "did not converge" in capsys.readouterr().err
    assert ax.main(["--v0", "0.65", "--branch", "stomatocyte", "--n", "16"]) == 0
    cap = capsys.readouterr()
    assert "type = discocyte" in cap.out and "left the stomatocyte branch" in cap.err


# -- spontaneous curvature and area-difference elasticity (issue 27) -----------------------

@pytest.mark.parametrize("c0", [0.5, -1.0, 1.5])
def test_sphere_with_spontaneous_curvature(c0):
    """v = 1 leaves only the unit sphere: ∫(H - c0/2)² dA = 4π(1 - c0/2)²."""
    res = canham_reference(1.0, "prolate", n=8, model=ax.Helfrich(c0=c0))
    assert abs(res.W - FOURPI * (1 - c0 / 2) ** 2) < 1e-9 * FOURPI
    assert abs(res.willmore - FOURPI) < 1e-9 and abs(res.mean_curvature - FOURPI) < 1e-9


def test_sphere_with_ade():
    """ADE at v = 1: ∫H² dA + (πα/A)(M - 4π m0)², M = 4π on the unit sphere."""
    res = canham_reference(1.0, "prolate", n=8, model=ax.Helfrich(alpha=2.0, m0=1.3))
    assert abs(res.W - (FOURPI + np.pi * 2.0 / FOURPI * (FOURPI * 0.3) ** 2)) < 1e-9


def test_model_gradient_matches_differences():
    rng = np.random.default_rng(2)
    b = ax._Basis(10, 40, ax.Helfrich(c0=0.7, alpha=1.5, m0=1.1))
    a = 0.1 * rng.normal(size=10)
    gW = b.evaluate(a)[1]
    eps = 1e-6
    for i in range(10):
        e = np.zeros(10)
        e[i] = eps
        fd = (b.evaluate(a + e)[0] - b.evaluate(a - e)[0]) / (2 * eps)
        assert abs(fd - gW[i]) < 1e-6 * max(1, abs(gW[i]))


def test_minimum_energy_obeys_the_envelope_theorem():
    """dE*/dc0 = ∂E/∂c0 at the minimiser = -M + 2π c0, and dE*/dm0 =
    -(2πα/A)(M - 4π m0)·4π: the solver's minimisers are stationary (a
    difference of two solves against the formula at the solution)."""
    v, h = 0.8, 1e-4
    mk = lambda c0: canham_reference(v, "prolate", n=24, model=ax.Helfrich(c0=c0))
    mid, lo, hi = mk(0.3), mk(0.3 - h), mk(0.3 + h)
    assert abs((hi.W - lo.W) / (2 * h) - (-mid.mean_curvature + 2 * np.pi * 0.3)) < 1e-6
    alpha = 1.0
    mk = lambda m0: canham_reference(v, "prolate", n=24, model=ax.Helfrich(alpha=alpha, m0=m0))
    mid, lo, hi = mk(1.1), mk(1.1 - h), mk(1.1 + h)
    expect = -2 * np.pi * alpha / FOURPI * (mid.mean_curvature - FOURPI * 1.1) * FOURPI
    assert abs((hi.W - lo.W) / (2 * h) - expect) < 1e-6 * max(1, abs(expect))
