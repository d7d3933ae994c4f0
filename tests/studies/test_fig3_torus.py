"""pyevolver/studies/fig3_torus.py: the paper's Figure 3 and Proposition 1.

Expected values come from closed-form geometry (2π², 4π, the radius ratio of
a sampled torus), the paper's claims (unregularized PL energies collapse below
2π²; regularization keeps the mesh healthy) and the reference Evolver.
"""
import io
import math

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.studies import fig3_torus as F3
from pyevolver.studies.meshes import edges, torus_grid

CLIFFORD = 2 * math.pi ** 2


# -- failures the paper reports are real ---------------------------------------------------

def test_unregularized_effarea_collapses_far_below_the_clifford_bound():
    """W_EffAreaCur on the 10×16 torus, 50 damped Newton steps: far below
    2π² (every smooth torus has W ≥ 2π²) with collapsed triangles."""
    row = F3.newton_run(10, 16, "EffArea", None, steps=50, moebius=False)
    assert row["W"] < 0.9 * CLIFFORD and row["min_angle_deg"] < 1.0, row


@pytest.mark.slow
def test_unregularized_normalcur_collapses_far_below_the_clifford_bound():
    row = F3.newton_run(10, 16, "NormalCur", None, steps=300, moebius=False)
    assert row["W"] < 0.9 * CLIFFORD and row["min_angle_deg"] < 1.0, row


# -- the cures work ---------------------------------------------------------------------------

@pytest.mark.parametrize("energy", ["EffArea", "NormalCur"])
def test_fixed_lambda_regularization_keeps_the_torus_healthy(energy):
    """W + 0.25 E on the offset 10×16 grid: smallest angle above 10°, W not
    below 2π²(1 − 1%), a torus of revolution (circle fit within 5%) with
    R/r within 3.5% of √2."""
    row = F3.newton_run(10, 16, energy, 0.25, moebius=False)
    assert row["min_angle_deg"] > 10.0, row
    assert row["W"] >= CLIFFORD * 0.99, row
    assert row["revolution_dev"] < 0.05, row
    assert abs(row["R_over_r"] / math.sqrt(2) - 1) < 0.035, row


def test_paper_grid_regularized_minimizer_is_not_a_torus_of_revolution():
    """On the one-diagonal grid the equilateral conformal structure is a
    sheared lattice: with λ = 0.5 the minimizer is far from any torus of
    revolution (circle-fit deviation above 10%), on the offset grid it is one
    (below 5%)."""
    paper = F3.newton_run(10, 16, "NormalCur", 0.5, grid="paper", moebius=False)
    offset = F3.newton_run(10, 16, "NormalCur", 0.5, grid="offset", moebius=False)
    assert paper["revolution_dev"] > 0.1 and offset["revolution_dev"] < 0.05, (paper, offset)
    assert paper["min_angle_deg"] > 5 and offset["min_angle_deg"] > 10


@pytest.mark.parametrize("energy", ["EffArea", "NormalCur"])
def test_continuation_in_lambda_stays_healthy_and_near_the_clifford_torus(energy):
    """fig3_continuation.cmd at 10×16: every kept stage has its smallest angle
    ≥ 10° (the undone ones below), the result is healthy, its W not below
    2π²(1 − 1%), and the Loop surface of the mesh (a smooth torus, so
    W_Loop ≥ 2π² by Marques–Neves) within 1% of 2π²."""
    row, stages = F3.continuation_run(10, 16, energy, moebius=False)
    assert stages and stages[0]["lambda"] == 0.25
    for st in stages:
        assert (st["minangle"] >= 10.0) == (st["status"] == "healthy"), st
    assert row["min_angle_deg"] > 10.0, row
    assert row["W"] >= CLIFFORD * 0.99, row
    assert CLIFFORD <= row["W_loop"] <= 1.01 * CLIFFORD, row


@pytest.mark.slow
@pytest.mark.parametrize("energy", ["EffArea", "NormalCur"])
def test_continuation_20x32(energy):
    """At 20×32 the Loop energy of the continued mesh is within 0.3% of 2π²."""
    row, _ = F3.continuation_run(20, 32, energy)
    assert row["min_angle_deg"] > 10.0, row
    assert CLIFFORD <= row["W_loop"] <= 1.003 * CLIFFORD, row
    assert abs(row["R_over_r"] / math.sqrt(2) - 1) < 0.03, row


def _check_consistency_stages(stages):
    for st in stages:
        healthy = st["minangle"] >= 10.0
        status = ("healthy" if st["W"] > st["loop_w"] else "crossed") if healthy else "undone"
        assert st["status"] == status, st


def test_consistency_rule_picks_the_lambda_where_w_meets_the_loop_energy():
    """The consistency rule for λ (procedure ``consistency`` of
    fig3_continuation.cmd) on the 10×16 NormalCur torus: every stage is
    labelled by its own test, the bracket where W − W_Loop changes sign is
    found (stages on both sides), and the kept stage is healthy with W within
    0.1% of its Loop energy, which is ≥ 2π² (Marques–Neves), and W within 1%
    of 2π² (the issue's acceptance for W; R/r, measured 1.31, is not within
    3% of √2: docs/paper.md)."""
    row, stages = F3.continuation_run(10, 16, "NormalCur", rule="consistency", nbis=4,
                                      moebius=False)
    _check_consistency_stages(stages)
    assert {"healthy", "crossed"} <= {st["status"] for st in stages}, stages
    assert row["min_angle_deg"] > 10.0, row
    assert abs(row["W"] / row["W_loop"] - 1) < 1e-3, row
    assert row["W_loop"] >= CLIFFORD, row
    assert abs(row["W"] / CLIFFORD - 1) < 0.01, row
    assert abs(row["R_over_r"] / math.sqrt(2) - 1) < 0.1, row


@pytest.mark.slow
@pytest.mark.parametrize("energy", ["EffArea", "NormalCur"])
def test_consistency_rule_20x32(energy):
    """At 20×32 the consistency rule ends within 0.3% of 2π² with R/r within
    3% of √2 and the smallest angle above 10°."""
    row, stages = F3.continuation_run(20, 32, energy, rule="consistency")
    _check_consistency_stages(stages)
    assert row["min_angle_deg"] > 10.0, row
    assert row["W_loop"] >= CLIFFORD, row
    assert abs(row["W"] / CLIFFORD - 1) < 0.003, row
    assert abs(row["R_over_r"] / math.sqrt(2) - 1) < 0.03, row


# -- the Evolver's recipe, in both programs ----------------------------------------------------

def test_evolver_recipe_runs_unchanged_in_the_reference(evolver):
    """fig3_evolver_recipe.cmd (g, V, u, n) for two short rounds: the Evolver
    and pyevolver print the same rounds (W to 1e-9, angles to 1e-6, counts)."""
    rows, recs = F3.recipe_run(10, 16, "NormalCur", rounds=2, gsteps=10, moebius=False)
    py = [r for r in recs if r["program"] == "pyevolver"]
    ref = [r for r in recs if r["program"] == "evolver"]
    assert len(py) == len(ref) == 3
    for a, b in zip(py, ref):
        assert a["round"] == b["round"] and a["vertices"] == b["vertices"]
        assert abs(a["W"] - b["W"]) < 1e-9 * b["W"], (a, b)
        assert abs(a["minangle"] - b["minangle"]) < 1e-6, (a, b)
    assert {r["program"] for r in rows} == {"pyevolver", "evolver-nox-d"}


def test_plain_and_star_spellings_agree_with_the_reference(evolver, tmp_path):
    """The paper's energies by their Evolver names: on the closed torus the
    plain and star_ variants are the same numbers, in pyevolver and in REF."""
    from reference import numbers
    for energy in F3.ENERGIES:
        path = F3.datafile(10, 16, energy, False)
        ref = numbers(evolver, path, ["willmore.value"])[0]
        s = Session.load(path, out=io.StringIO())
        assert abs(s.totals.quantity_values["willmore"] - ref) < 1e-12 * ref
        with open(path) as fh:
            text = fh.read().replace("method " + F3.ENERGIES[energy],
                                     "method star_" + F3.ENERGIES[energy])
        star = tmp_path / "star.fe"
        star.write_text(text)
        s2 = Session.load(str(star), out=io.StringIO())
        assert abs(s2.totals.quantity_values["willmore"] - ref) < 1e-12 * ref


# -- measurements ------------------------------------------------------------------------------

def test_radius_ratio_of_sampled_tori_and_cyclides():
    """A sampled torus of revolution gives its R/r with no deviation from the
    circle; its images under inversions (cyclides: same W) do not fit, and
    the Möbius-normalized fit recovers R/r."""
    for R, r in [(math.sqrt(2), 1.0), (1.7, 0.6)]:
        X, _ = torus_grid(20, 32, R, r)
        X = X @ np.array([[0.6, 0.8, 0.0], [-0.8, 0.6, 0.0], [0.0, 0.0, 1.0]]).T + [1, 2, 3]
        ratio, dev = F3.radius_ratio(X)
        assert abs(ratio - R / r) < 1e-12 and dev < 1e-12
    for R, r in [(math.sqrt(2), 1.0), (1.7, 0.6)]:
        X, _ = torus_grid(20, 32, R, r)
        for c in ([4.0, 1.0, 0.5], [-2.0, 3.0, 1.0]):
            c = np.array(c)
            Y = c + (X - c) / np.sum((X - c) ** 2, axis=1)[:, None]    # inversion about c
            assert F3.radius_ratio(Y)[1] > 0.05                          # a cyclide
            ratio, dev, _ = F3.moebius_radius_ratio(Y)
            assert abs(ratio - R / r) < 1e-6 and dev < 1e-6, (R / r, ratio, dev)


def test_min_angle_of_an_equilateral_and_a_right_triangle():
    X = np.array([[0, 0, 0], [1, 0, 0], [0.5, math.sqrt(3) / 2, 0], [0, 1, 0]], float)
    assert abs(F3.min_angle(X, np.array([[0, 1, 2]])) - 60) < 1e-12
    assert abs(F3.min_angle(X, np.array([[0, 1, 3]])) - 45) < 1e-12


# -- Proposition 1 -----------------------------------------------------------------------------

def test_almost_spherical_tori_lie_on_the_sphere_with_a_small_hole():
    X, F = F3.almost_spherical_torus(10, 20, 0.05)
    assert np.allclose(np.linalg.norm(X, axis=1), 1.0)
    assert abs(np.hypot(X[:, 0], X[:, 1]).min() - 0.05) < 1e-12      # hole diameter 2ε
    E, _ = edges(F)
    assert set(np.bincount(E.ravel()).tolist()) == {6}
    assert len(X) - len(E) + len(F) == 0


def test_proposition1_bobenko_energy_decreases_to_4pi():
    """Proposition 1: for each grid size the Bobenko energy of the almost
    spherical tori decreases monotonically as the hole shrinks, towards
    4π < 2π² (the energy of the Clifford torus)."""
    rows = F3.proposition1(grids=((5, 10), (10, 20), (20, 40)),
                           eps=(0.5, 0.2, 0.1, 0.05, 0.01, 1e-3, 1e-4))
    for m, n in ((5, 10), (10, 20), (20, 40)):
        W = [r["W_bobenko"] for r in rows if (r["m"], r["n"]) == (m, n)]
        assert np.all(np.diff(W) < 0), W
        assert all(w > 4 * math.pi for w in W), W
        assert W[-1] - 4 * math.pi < 1e-6, W
        assert W[0] < CLIFFORD - 4, W


# -- the chart ------------------------------------------------------------------------------

def test_chart_records_have_the_lead_s_keys(monkeypatch):
    monkeypatch.setitem(F3.SIZES, "small", [(5, 10)])
    monkeypatch.setattr(F3, "_recipe_rounds", lambda m: 1)
    monkeypatch.setattr(F3, "ENERGIES", {"NormalCur": F3.ENERGIES["NormalCur"]})
    recs = F3.chart_records(full=False)
    keys = {"method", "resolution", "seconds", "energy", "reference", "rel_error",
            "min_angle_deg"}
    assert recs and all(set(r) == keys for r in recs)
    assert {r["method"] for r in recs} == {"NormalCur+harmonic(cont.)",
                                           "NormalCur+harmonic(cont.) Loop W",
                                           "NormalCur Evolver recipe (g,V,u,n)"}
    for r in recs:
        assert r["resolution"] == 50 and r["reference"] == CLIFFORD
        assert math.isfinite(r["energy"]) and r["seconds"] > 0
        assert abs(r["rel_error"] - abs(r["energy"] / CLIFFORD - 1)) < 1e-15


@pytest.mark.slow
def test_study_small_writes_its_outputs(tmp_path):
    out = str(tmp_path / "fig3")
    assert F3.main(["--size", "small", "--out", out]) == 0
    import os
    for name in ("fig3_torus.csv", "fig3_stages.csv", "fig3_recipe.csv", "fig3_prop1.csv",
                 "fig3_chart.csv", "fig3_torus.png"):
        assert os.path.getsize(os.path.join(out, name)) > 100
    import csv
    with open(os.path.join(out, "fig3_chart.csv")) as fh:
        recs = list(csv.DictReader(fh))
    assert {r["method"] for r in recs} >= {"NormalCur Evolver recipe (g,V,u,n)",
                                           "EffArea+harmonic(cont.)"}


def test_the_figure_is_readable():
    """Titles and axis labels inside the picture (not clipped), the three
    grids' Proposition 1 curves each in its own marker and line style (they
    nearly coincide, none may hide another), the λ ticks plain numbers."""
    import csv
    import os
    plt = pytest.importorskip("matplotlib.pyplot")
    from pyevolver.studies.doc_numbers import DOCS

    def read(name):
        with open(os.path.join(DOCS, name)) as fh:
            return [{k: (v if k in ("status", "mesh", "energy", "grid", "rule") else float(v))
                     for k, v in r.items()} for r in csv.DictReader(fh)]
    fig = F3.figure(read("fig3_stages.csv"), read("fig3_prop1.csv"))
    fig.canvas.draw()
    box = fig.bbox
    for ax in fig.axes:
        for t in (ax.title, ax.xaxis.label, ax.yaxis.label):
            assert t.get_text()
            e = t.get_window_extent()
            assert box.x0 <= e.x0 and e.x1 <= box.x1 and box.y0 <= e.y0 and e.y1 <= box.y1, \
                t.get_text()
    lines = fig.axes[2].get_lines()
    assert len(lines) == 3
    assert len({(ln.get_marker(), ln.get_linestyle()) for ln in lines}) == 3
    assert all("10^" not in t.get_text() and "times" not in t.get_text()
               for t in fig.axes[0].get_xticklabels())
    plt.close(fig)


def test_cli_refuses_an_unknown_run(tmp_path):
    with pytest.raises(SystemExit):
        F3.main(["--meshes", "5x10", "--runs", "recipe,bogus", "--out", str(tmp_path)])
