"""The axisymmetric ADE reference against the exact relations between the
spontaneous-curvature (SC), bilayer-couple (BC) and ADE models
(pyevolver.studies.phase_ade; Miao, Seifert, Wortis & Döbereiner 1994,
Sec. II; Seifert 1997, Adv. Phys. 46, 13).

Expected values: closed forms (the sphere: Δa = 1, E = 4π(1 − c0/2)² +
4π²α(1 − m0)²) and the relations, each checked between solves of
different problems (an ADE solve against an SC solve started elsewhere, a
BC solve reached through a sequence of SC solves), never against numbers
of the code under test.
"""
import numpy as np
import pytest

from pyevolver.studies import phase_ade as PA
from pyevolver.studies import phase_ade_points as PP
from pyevolver.studies import phase_reference as PR
from pyevolver.studies.axisymmetric import Helfrich, canham_reference

FOURPI = 4 * np.pi


@pytest.mark.parametrize("model", [Helfrich(c0=0.6, alpha=1.4, m0=1.2),
                                   Helfrich(c0=-1.0, alpha=3.0, m0=0.9)])
def test_sphere_closed_form(model):
    """v = 1: the unit sphere, Δa = 1 (SBL 1991), and the ADE energy in
    closed form; its BC form and effective c0 are consistent."""
    res = canham_reference(1.0, "prolate", n=8, model=model)
    m = PA.reduced_area_difference(res)
    assert abs(m - 1.0) < 1e-10
    exact = FOURPI * (1 - model.c0 / 2) ** 2 + 4 * np.pi ** 2 * model.alpha * (1 - model.m0) ** 2
    assert abs(res.W - exact) < 1e-9 * exact
    assert abs(PA.ade_energy_from_bc(FOURPI, 1.0, model) - exact) < 1e-12 * exact
    assert PA.effective_c0(model, 1.0) == pytest.approx(
        model.c0 + 2 * np.pi * model.alpha * (model.m0 - 1.0), rel=1e-15)


POINTS = [("prolate", 0.85, Helfrich(c0=0.5, alpha=1.4, m0=1.05)),
          ("prolate", 0.85, Helfrich(c0=0.0, alpha=5.0, m0=1.1)),
          ("oblate", 0.70, Helfrich(c0=0.5, alpha=1.4, m0=1.05))]


@pytest.mark.parametrize("branch,v,model", POINTS)
def test_ade_shape_is_the_sc_shape_of_the_effective_c0(branch, v, model):
    """The ADE minimiser equals the SC minimiser at c0_eff = c0 − 2πα(m − m0)
    (the SC problem solved from the c0 = 0 shape, not from the ADE one)."""
    ade = canham_reference(v, branch, n=32, model=model)
    m = PA.reduced_area_difference(ade)
    plain = PR.follow(branch, [v], n=32)[0].result
    sc = canham_reference(v, branch, n=32, coef0=plain.coef,
                          model=Helfrich(c0=PA.effective_c0(model, m)))
    assert abs(sc.willmore - ade.willmore) < 1e-9 * ade.willmore
    assert abs(sc.mean_curvature - ade.mean_curvature) < 1e-9 * ade.mean_curvature
    assert np.max(np.abs(sc.r - ade.r)) < 1e-8


@pytest.mark.parametrize("branch,v,model", POINTS)
def test_ade_energy_is_bc_energy_plus_penalty(branch, v, model):
    """E_ADE = W_BC(v, m) − 4π c0 m + π c0² + 4π²α(m − m0)² at the ADE
    minimiser's m, with W_BC from the bilayer-couple solve (secant on the
    SC multiplier, from the c0 = 0 shape), whose multiplier ∂W_BC/∂M is
    c0_eff."""
    ade = canham_reference(v, branch, n=32, model=model)
    m = PA.reduced_area_difference(ade)
    plain = PR.follow(branch, [v], n=32)[0].result
    bc, c_bc = PA.bilayer_couple(v, m, branch, n=32, coef0=plain.coef)
    assert abs(PA.reduced_area_difference(bc) - m) < 1e-11
    assert abs(PA.ade_energy_from_bc(bc.willmore, m, model) - ade.W) < 1e-9 * ade.W
    assert abs(c_bc - PA.effective_c0(model, m)) < 1e-6


def test_bc_multiplier_is_the_slope_of_w_bc():
    """∂W_BC/∂M = c0 (the multiplier): a centred difference of two BC
    solves against the returned c0.  (On the symmetric prolate branch M
    hardly moves with c0, ∂M/∂c0 ≈ 4π·1.2e-3 at v = 0.75: W_BC is steep in
    m there, so the steps in m are small.)"""
    plain = PR.follow("prolate", [0.75], n=32)[0].result
    m = PA.reduced_area_difference(plain) + 1e-3
    h = 2e-6
    mid, c = PA.bilayer_couple(0.75, m, "prolate", n=32, coef0=plain.coef)
    up, _ = PA.bilayer_couple(0.75, m + h, "prolate", n=32, c0=c, coef0=mid.coef)
    dn, _ = PA.bilayer_couple(0.75, m - h, "prolate", n=32, c0=c, coef0=mid.coef)
    slope = (up.willmore - dn.willmore) / (2 * h * FOURPI)
    assert abs(slope - c) < 1e-6 * max(1.0, abs(c))


def test_large_alpha_tends_to_the_bilayer_couple():
    """α → ∞: m → m0 and E_ADE → W_BC(m0) (c0 = 0), both as
    1/(s + 2πα) with s = ∂c_BC/∂m (about 800 here, W_BC being steep in m on
    the prolate branch): from α = 10³ to 10⁴ the ratio is
    (s + 2π·10³)/(s + 2π·10⁴) ≈ 0.11, not yet the asymptotic 0.1."""
    v = 0.75
    plain = PR.follow("prolate", [v], n=32)[0].result
    m0 = PA.reduced_area_difference(plain) + 1e-3
    bc, _ = PA.bilayer_couple(v, m0, "prolate", n=32, coef0=plain.coef)
    gaps, errs = [], []
    for alpha in (1e3, 1e4):
        r = canham_reference(v, "prolate", n=32, coef0=bc.coef,
                             model=Helfrich(alpha=alpha, m0=m0))
        gaps.append(PA.reduced_area_difference(r) - m0)
        errs.append(bc.willmore - r.W)
    assert gaps[0] < 0 and gaps[1] < 0          # the ADE shape relaxes towards the SC one
    assert 0.1 < gaps[1] / gaps[0] < 0.125
    assert 0 < errs[1] < errs[0] and 0.1 < errs[1] / errs[0] < 0.125


def test_zero_alpha_is_the_spontaneous_curvature_model():
    a = canham_reference(0.85, "prolate", n=32, model=Helfrich(c0=0.4, alpha=0.0, m0=3.0))
    b = canham_reference(0.85, "prolate", n=32, model=Helfrich(c0=0.4))
    assert a.W == b.W


# -- discrete ADE points ---------------------------------------------------------------------

def _stationarity(tmp_path, X, F, model, lam, method="normal_sq_mean_curvature"):
    """max |∇L| / max |∇E| of the energy written by ade_header (the
    FUNCTION quantity of mean_curvature_integral) plus λE, at fixed area and
    volume, on the mesh (X, F): an evaluation independent of the solver's
    linearised form."""
    import io
    from pyevolver import Session
    from pyevolver.evolve.iterate import _Constraints
    from pyevolver.studies.meshes import write_fe
    from pyevolver.studies.phase_newton import _grad_lagrangian
    from pyevolver.evolve import gradient as GR
    vol = float(np.einsum("ij,ij->i", X[F[:, 0]], np.cross(X[F[:, 1]], X[F[:, 2]])).sum() / 6)
    hdr = (PA.ade_header(model.c0, model.alpha, model.m0, method=method)
           + f"quantity surf fixed = 4*pi method facet_area global\n"
           + f"quantity harm energy modulus {lam!r} method harmonic_energy global\n")
    path = write_fe(str(tmp_path / "check.fe"), X, F, header=hdr, face_attrs="tension 0")
    with open(path, "a") as fh:
        fh.write("\nbodies\n1 " + " ".join(str(i + 1) for i in range(len(F)))
                 + f" volume {vol!r}\n")
    s = Session.load(path, out=io.StringIO(), err=io.StringIO())
    gL = _grad_lagrangian(s.surface, _Constraints(s.surface))[0]
    gE = GR.energy_gradient(s.surface.evaluate())
    return np.abs(gL).max() / np.abs(gE).max()


def test_discrete_ade_point_is_stationary_and_near_the_reference(tmp_path):
    """A 120-vertex prolate at v = 0.85, c0 = 0.5, α = 1.4, m0 = 1.05: the
    solver's mesh is a critical point of the ADE datafile's energy (FUNCTION
    quantity, evaluated separately) and its energy is within 2% above the
    axisymmetric ADE reference (c0 = 0 at this size: +1.2%)."""
    model = Helfrich(c0=0.5, alpha=1.4, m0=1.05)
    row, X, F = PP.solve_ade_point("prolate", 0.85, model, 120)
    assert row["converged"] is True
    assert 0 < row["rel_err"] < 0.02
    assert abs(row["m"] - row["m_ref"]) < 0.01
    # μ = 2k(M − M0) is the effective spontaneous curvature's shift
    assert row["c0_eff"] == pytest.approx(PA.effective_c0(model, row["m"]), abs=1e-8)
    assert row["method"] == "star_perp_sq_mean_curvature"     # the default at c0 != 0
    assert _stationarity(tmp_path, X, F, model, row["lambda"], row["method"]) < 1e-6


def test_docs_table_is_the_committed_csv():
    """docs/phase.md quotes docs/phase/ade.md, which is markdown() of the
    committed docs/phase/ade.csv (written by python -m
    pyevolver.studies.phase_ade_points --nv 642 --out docs/phase); its relation
    columns are at round-off and its discrete points within 1%."""
    import os
    docs = os.path.join(os.path.dirname(__file__), "..", "..", "docs")
    rows = PP.read_table(os.path.join(docs, "phase", "ade.csv"))
    text = PP.markdown(rows)
    with open(os.path.join(docs, "phase", "ade.md")) as fh:
        assert fh.read() == text
    with open(os.path.join(docs, "phase.md")) as fh:
        assert text in fh.read()
    for r in rows:
        assert abs(r["sc_rel_diff"]) < 1e-9 and abs(r["bc_rel_diff"]) < 1e-9
        if r.get("converged") is True:
            assert 0 < r["rel_err"] < 0.01


def test_ade_sweep_writes_its_tables(tmp_path):
    """Two 60-vertex ADE prolates (α = 1.4, m0 = 1.05): converged, within
    5% of the reference, the tables written."""
    import csv
    import os
    model = Helfrich(alpha=1.4, m0=1.05)
    rows, trans = PP.sweep([0.85, 0.9], model, 60, branches=("prolate",), out=str(tmp_path),
                           log=lambda t: None)
    assert [r["v"] for r in rows] == [0.85, 0.9]
    for r in rows:
        assert r["converged"] is True and r["type"] == "prolate" and abs(r["rel_err"]) < 0.05
        # near the sphere the prolate is the stable ADE shape (its eigenvalues
        # with the rank-one term 2k ∇M ∇Mᵀ: no negative one)
        assert r["stable"] is True and r["eig1"] > 0
    assert trans == []                                   # one branch: no crossing
    with open(os.path.join(tmp_path, "ade_phase.csv")) as fh:
        table = list(csv.DictReader(fh))
    assert [float(r["alpha"]) for r in table] == [1.4, 1.4]
    md = PP.sweep_markdown(PP.read_table(os.path.join(tmp_path, "ade_phase.csv")),
                           PP.read_table(os.path.join(tmp_path, "ade_transitions.csv")))
    assert "| prolate | 0.850 |" in md and "| prolate | 0.900 |" in md
    assert md.count("| yes |") == 2


def test_docs_sweep_table_is_the_committed_csv():
    import os
    d = os.path.join(os.path.dirname(__file__), "..", "..", "docs", "phase", "ade_sweep")
    md = PP.sweep_markdown(PP.read_table(os.path.join(d, "ade_phase.csv")),
                           PP.read_table(os.path.join(d, "ade_transitions.csv")))
    with open(os.path.join(d, "summary.md")) as fh:
        assert fh.read() == md
    with open(os.path.join(d, "..", "..", "phase.md")) as fh:
        assert md in fh.read()
