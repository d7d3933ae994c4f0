"""Direct tests of pyevolver.studies.phase_plot: the figure is written as
PNG and PDF from rows, references and transitions (synthetic here)."""
import os
from types import SimpleNamespace

from pyevolver.studies.phase_plot import plot


def test_png_and_pdf_are_written(tmp_path):
    refs = {"prolate": {v: SimpleNamespace(v=v, W=20.0 - 10 * v) for v in (0.6, 0.7)}}
    rows = [{"branch": "prolate", "v": 0.6, "W": 14.1, "nv": 100, "converged": True,
             "stable": True, "rel_err": 0.01},
            {"branch": "oblate", "v": 0.7, "W": 13.2, "nv": 100, "converged": True,
             "stable": False, "rel_err": 0.02},
            {"branch": "oblate", "v": 0.6, "W": 14.5, "nv": 100, "converged": False,
             "stable": "", "rel_err": 0.5}]
    trans = [{"from": "prolate", "to": "oblate", "v": 0.65, "v_published": 0.652},
             {"from": "oblate", "to": "stomatocyte", "v": None, "v_published": 0.592}]
    paths = plot(str(tmp_path / "phase"), rows, refs, trans)
    assert paths == [str(tmp_path / "phase.png"), str(tmp_path / "phase.pdf")]
    assert all(os.path.getsize(p) > 1000 for p in paths)
