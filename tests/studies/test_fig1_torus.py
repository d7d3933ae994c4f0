"""pyevolver.studies.fig1_torus: the datafiles and a short run (the full
Figure 1 runs are in test_studies)."""
import math
import os

import numpy as np
import pytest

from pyevolver.session.core import Session
from pyevolver.studies import fig1_torus as F1
from pyevolver.studies.meshes import torus_grid
from pyevolver.studies.vesicle_shapes import min_angle


def test_datafile_is_written_when_missing_and_loads(tmp_path):
    path = F1.datafile("star_sq_mean_curvature", str(tmp_path))
    assert os.path.basename(path) == "torus5x9_star_sq_mean_curvature.fe"
    s = Session.load(path)
    assert (s.surface.nv, s.surface.nf) == (45, 90)
    # the smallest corner angle, as measured independently on the grid
    X, F = torus_grid(5, 9, R=math.sqrt(2.0), r=1.0)
    assert F1.min_angle(s.surface) == pytest.approx(min_angle(X, F), rel=1e-9)
    assert F1.datafile("star_sq_mean_curvature", str(tmp_path)) == path    # kept


@pytest.mark.parametrize("label", ["HKS", "MDSB"])
def test_a_short_run_lowers_the_energy(label):
    run = {r[0]: r for r in F1.RUNS}[label]
    s0 = Session.load(F1.datafile(run[1]))
    _, row = F1.run(*run, steps=3, iters=3)
    assert set(row) == {"label", "method", "minimizer", "iterations", "W", "min_angle_deg",
                        "seconds"}
    assert row["W"] < s0.total_energy + 1e-6 and math.isfinite(row["min_angle_deg"])
    assert np.isfinite(row["seconds"])
