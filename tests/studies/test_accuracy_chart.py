"""The accuracy-against-time chart (pyevolver/studies/accuracy_chart.py),
regenerated at its tiny size: every record's error is its energy against
the closed-form (2π²) or axisymmetric reference, the CSV has one row per
record and the PNG is drawn."""
import csv
import math

import numpy as np

from pyevolver.studies import accuracy_chart
from pyevolver.studies.axisymmetric import canham_reference


def test_tiny_chart(tmp_path):
    assert accuracy_chart.main(["--size", "tiny", "--out", str(tmp_path)]) == 0
    with open(tmp_path / "accuracy_vs_time.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert set(rows[0]) == set(accuracy_chart.COLUMNS)
    problems = {r["problem"] for r in rows}
    assert problems == {"torus", "vesicle v0=0.85"}
    for r in rows:
        W, ref, err = float(r["energy"]), float(r["reference"]), float(r["rel_error"])
        assert abs(abs(err) - abs(W / ref - 1)) <= 1e-9
        assert float(r["seconds"]) > 0 and int(r["resolution"]) > 0
        if r["problem"] == "torus":
            assert abs(ref - 2 * math.pi ** 2) <= 1e-9
    vesicle = [r for r in rows if r["problem"].startswith("vesicle")]
    ref = canham_reference(0.85, "prolate", n=24).W
    assert all(abs(float(r["reference"]) - ref) <= 1e-6 * ref for r in vesicle)
    # the regularized vesicle at 162 vertices is already within a few percent
    assert all(abs(float(r["rel_error"])) < 0.05 for r in vesicle)
    from matplotlib.image import imread
    img = imread(tmp_path / "accuracy_vs_time.png")
    assert img.shape[0] > 100 and np.ptp(img[..., :3]) > 0.5
