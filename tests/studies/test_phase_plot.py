"""Direct tests of pyevolver.studies.phase_plot: the figure is written as
PNG and PDF from rows, references and transitions (synthetic here); the
tables of docs/phase.md are the committed study output's."""
import os
from types import SimpleNamespace

from pyevolver.studies.phase_plot import plot, summary_markdown
from pyevolver.studies.phase_study import read_rows, read_transitions

DOCS = os.path.join(os.path.dirname(__file__), "..", "..", "docs")


def test_png_and_pdf_are_written(tmp_path):
    refs = {"prolate": {v: SimpleNamespace(v=v, W=20.0 - 10 * v) for v in (0.6, 0.7)}}
    rows = [{"branch": "prolate", "v": 0.6, "W": 14.1, "nv": 100, "converged": True,
             "stable": True, "rel_err": 0.01},
            {"branch": "oblate", "v": 0.7, "W": 13.2, "nv": 100, "converged": True,
             "stable": False, "rel_err": 0.02},
            {"branch": "oblate", "v": 0.6, "W": 14.5, "nv": 100, "converged": False,
             "stable": "", "rel_err": 0.5, "W_ref": 14.4}]
    trans = [{"from": "prolate", "to": "oblate", "v": 0.65, "v_published": 0.652},
             {"from": "oblate", "to": "stomatocyte", "v": None, "v_published": 0.592}]
    paths = plot(str(tmp_path / "phase"), rows, refs, trans)
    assert paths == [str(tmp_path / "phase.png"), str(tmp_path / "phase.pdf")]
    assert all(os.path.getsize(p) > 1000 for p in paths)


def test_summary_tables():
    rows = [{"branch": "oblate", "v": 0.7, "W": 4 * 3.14159265358979, "W_ref": 12.0, "nv": 642,
             "converged": True, "stable": False, "rel_err": 0.0123, "eig1": -1.5,
             "lambda": 0.3, "min_angle_deg": 40.0, "start": "revolved/critical"},
            {"branch": "prolate", "v": 0.6, "W": 30.0, "W_ref": 29.0, "nv": 642,
             "converged": False, "stable": "", "rel_err": 0.5, "eig1": float("nan"),
             "lambda": 0.6, "min_angle_deg": 3.0, "start": "continued/min"}]
    trans = [{"from": "prolate", "to": "oblate", "v": 0.64591, "v_ref": None,
              "v_published": 0.652}]
    text = summary_markdown(rows, trans)
    lines = text.splitlines()
    assert lines[2] == "| prolate/oblate | 0.6459 | — | 0.652 |"
    # prolate first (branch order), not converged; then the oblate saddle
    assert lines[-2].startswith("| prolate | 0.600 | 642 |") and "not converged" in lines[-2]
    assert "| +1.230% | -1.5 | no | 0.3 | 40.0° | revolved/critical |" in lines[-1]
    assert "| 1.00000 |" in lines[-1]





def test_committed_study_tables_are_the_committed_csv():
    """docs/phase/summary.md, docs/phase/n2562/summary.md,
    docs/phase/c0_m0.5/summary.md, docs/phase/c0_p0.5/summary.md and the tables
    quoted in docs/phase.md are what summary_markdown writes from the
    committed CSV files next to them."""
    for sub in ("phase", os.path.join("phase", "n2562"), os.path.join("phase", "c0_m0.5"),
                os.path.join("phase", "c0_p0.5")):
        rows = read_rows(os.path.join(DOCS, sub, "phase.csv"))
        trans = read_transitions(os.path.join(DOCS, sub, "transitions.csv"))
        text = summary_markdown(rows, trans)
        with open(os.path.join(DOCS, sub, "summary.md")) as fh:
            assert fh.read() == text
        with open(os.path.join(DOCS, "phase.md")) as fh:
            assert text in fh.read()
