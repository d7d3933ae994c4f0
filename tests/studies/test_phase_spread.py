"""pyevolver.studies.phase_spread: the spread of the phase study's numbers
over perturbed starting meshes (random ring rotations of the revolved
start, vertex jitter), the seeds recorded in the output.  Expected values
are closed forms (a Gaussian's deviation, crossings of straight lines)
or independent recomputations from the CSV."""
import csv
import math
import os

import numpy as np
import pytest

from pyevolver.studies import phase_spread as SP
from pyevolver.studies import phase_study as PS
from pyevolver.studies.phase_mesh import mesh_quality, revolve
from pyevolver.studies.vesicle_shapes import area_volume


def _sphere_curve(n=801):
    t = np.linspace(0, np.pi, n)
    return t, np.sin(t), -np.cos(t)


def test_jitter_has_the_stated_deviation_and_is_seeded():
    X, F = revolve(*_sphere_curve(), 2000)
    h = mesh_quality(X, F)["h"]
    Y = SP.jitter(X, F, np.random.default_rng(5))
    d = (Y - X).ravel()
    assert abs(d.mean()) < 0.1 * SP.JITTER * h
    assert d.std() == pytest.approx(SP.JITTER * h, rel=0.05)
    assert np.array_equal(Y, SP.jitter(X, F, np.random.default_rng(5)))
    assert not np.array_equal(Y, SP.jitter(X, F, np.random.default_rng(6)))


def test_random_ring_rotations_triangulate_the_same_surface_otherwise():
    X0, F0 = revolve(*_sphere_curve(), 600)
    X1, F1 = revolve(*_sphere_curve(), 600, rng=np.random.default_rng(1))
    assert len(X1) == len(X0) and len(F1) == len(F0)
    assert not np.array_equal(F0, F1)                      # another triangulation
    # the same rings: the same heights and radii, on the unit sphere
    assert np.allclose(np.sort(X0[:, 2]), np.sort(X1[:, 2]))
    assert np.allclose(np.linalg.norm(X1, axis=1), 1.0)
    e = np.sort(np.concatenate([F1[:, [0, 1]], F1[:, [1, 2]], F1[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    assert np.all(counts == 2) and len(X1) - len(counts) + len(F1) == 2
    A, V = area_volume(X1, F1)
    assert V > 0 and abs(A - 4 * math.pi) < 8 * math.pi / 600 ** 0.8   # inscribed: O(h²)


def test_add_seeds_fills_the_columns():
    row = {"W": 10.0, "converged": True}
    seed_rows = [{"W": 10.5, "eig1": 2.0, "converged": True, "stable": True,
                  "start": "revolved/min", "lambda": 0.3},
                 {"W": 99.0, "eig1": float("nan"), "converged": False, "stable": "",
                  "start": "continued/critical", "lambda": 0.3},
                 {"W": 9.75, "eig1": -1.0, "converged": True, "stable": False,
                  "start": "continued/min", "lambda": 0.6}]
    SP.add_seeds(row, [4, 5, 6], seed_rows)
    assert row["seeds"] == "4;5;6" and SP.parse_seeds(row["seeds"]) == [4, 5, 6]
    assert SP.values(row, "W_seeds") == [10.5, None, 9.75]
    assert SP.values(row, "eig1_seeds") == [2.0, None, -1.0]
    assert row["stable_seeds"] == "1/2"
    assert row["W_spread"] == pytest.approx(0.75)           # 10.5 - 9.75, not 99
    assert row["start_seeds"] == "revolved/min@0.3;;continued/min@0.6"


def test_crossing_spread_per_seed():
    """Branch a: W = 1 - v, branch b: W = 0.5 (seed 0) and 0.4 (seed 1):
    crossings at v = 0.5 and 0.6; a seed that did not converge at one
    point drops that point only."""
    rows = []
    for v in (0.3, 0.5, 0.7, 0.9):
        rows.append({"branch": "a", "v": v, "converged": True,
                     "W_seeds": f"{1 - v};{1 - v}"})
        rows.append({"branch": "b", "v": v, "converged": True,
                     "W_seeds": "0.5;0.4" if v != 0.3 else "0.5;"})
    got = SP.crossing_spread(rows, "a", "b", PS.crossing_linear)
    assert got == [pytest.approx(0.5), pytest.approx(0.6)]


def test_study_records_seeds_spread_and_resumes(tmp_path):
    out = str(tmp_path / "out")
    logged = []
    rows, trans = PS.run(nv=60, volumes=[0.9], branches=("prolate",), out=out, modes=12,
                         plot=False, seeds=(1, 2), log=logged.append)
    assert len(logged) == 2                                # the point, then its seeds
    (r,) = rows
    assert r["converged"] is True and r["seeds"] == "1;2" and r["stable_seeds"] == "2/2"
    W = [r["W"]] + SP.values(r, "W_seeds")
    assert r["W_spread"] == pytest.approx(max(W) - min(W), rel=1e-6)   # CSV: 10 digits
    # another triangulation of the same surface: a different W, by little
    assert 0 < r["W_spread"] < 0.02 * r["W"]
    with open(os.path.join(out, "phase.csv")) as fh:
        (raw,) = list(csv.DictReader(fh))
    assert raw["seeds"] == "1;2" and raw["seed"] == ""
    assert "spread of W (stable seeds)" in open(os.path.join(out, "summary.md")).read()
    # the same seeds again: nothing solved; more seeds: only their solves
    PS.run(nv=60, volumes=[0.9], branches=("prolate",), out=out, modes=12, plot=False,
           seeds=(1, 2), log=logged.append)
    assert len(logged) == 2
    rows3, _ = PS.run(nv=60, volumes=[0.9], branches=("prolate",), out=out, modes=12,
                      plot=False, seeds=(1, 2, 3), log=logged.append)
    assert len(logged) == 3 and rows3[0]["W"] == r["W"]
    assert SP.values(rows3[0], "W_seeds")[:2] == pytest.approx(SP.values(r, "W_seeds"))


def test_a_seed_is_its_own_start():
    """solve_point with a seed records it and starts from another mesh."""
    from pyevolver.studies import phase_reference as PR
    p = PR.follow("prolate", [0.9], n=12, seed=0.9)[0]
    a, Xa, Fa = PS.solve_point("prolate", 0.9, p.result, 60, eigen=False)
    b, Xb, Fb = PS.solve_point("prolate", 0.9, p.result, 60, eigen=False, seed=7)
    assert a["seed"] == "" and b["seed"] == 7 and b["converged"] is True
    assert not np.array_equal(Fa, Fb)


def test_transitions_with_their_spread_round_trip(tmp_path):
    """transitions() gives each seed's crossing and the spread;
    write_transitions/read_transitions keep them (the summary reads them
    back from the CSV)."""
    rows = []
    for v in (0.5, 0.6, 0.7):
        rows.append({"branch": "prolate", "v": v, "W": 1 - v, "converged": True,
                     "W_seeds": f"{1 - v};{1.02 - v}"})
        rows.append({"branch": "oblate", "v": v, "W": 0.4, "converged": True,
                     "W_seeds": "0.4;0.4"})
    trans = PS.transitions(rows)
    po = trans[0]
    assert (po["from"], po["to"]) == ("prolate", "oblate")
    assert po["v"] == pytest.approx(0.6) and po["v_spread"] == pytest.approx(0.02)
    assert SP.values({"x": po["v_seeds"]}, "x") == [pytest.approx(0.6), pytest.approx(0.62)]
    assert trans[1]["v"] is None and trans[1]["v_spread"] is None
    path = str(tmp_path / "transitions.csv")
    PS.write_transitions(path, trans)
    back = PS.read_transitions(path)
    for a, b in zip(trans, back):
        for k in ("v", "v_ref", "v_published", "v_spread"):
            assert (a[k] is None and b[k] is None) or a[k] == pytest.approx(b[k], rel=1e-9)
