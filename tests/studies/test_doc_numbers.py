"""pyevolver.studies.doc_numbers: the marker blocks of the docs are written
from CSV files, a stale block is found and rewritten, unknown ones raise."""
import os
import shutil

import pytest

from pyevolver.studies import doc_numbers as D


def _docs(tmp_path, text):
    d = tmp_path / "docs"
    d.mkdir()
    shutil.copy(os.path.join(D.DOCS, "fig1_torus.csv"), d)
    (d / "a.md").write_text(text, encoding="utf-8")
    (d / "notes.txt").write_text("<!-- doc_numbers nope -->\n<!-- /doc_numbers nope -->\n")
    return str(d)


def test_a_stale_block_is_reported_then_rewritten(tmp_path):
    docs = _docs(tmp_path, "intro\n\n<!-- doc_numbers fig1 -->\n| old |\n"
                           "<!-- /doc_numbers fig1 -->\n\nend\n")
    assert D.update(docs, check=True) == ["a.md:fig1"]
    assert "| old |" in open(os.path.join(docs, "a.md")).read()      # check writes nothing
    assert D.main(["--check", "--docs", docs]) == 1
    assert D.update(docs) == ["a.md:fig1"]
    text = open(os.path.join(docs, "a.md")).read()
    assert text.startswith("intro\n\n<!-- doc_numbers fig1 -->\n| energy |") and text.endswith("end\n")
    assert D.blocks_in(text)["fig1"] == D.render("fig1", docs)
    assert D.update(docs, check=True) == [] and D.main(["--check", "--docs", docs]) == 0


def test_the_fig1_rows_are_the_csvs(tmp_path):
    docs = _docs(tmp_path, "")
    with open(os.path.join(docs, "fig1_torus.csv"), "w") as fh:
        fh.write("label,method,minimizer,iterations,W,min_angle_deg,seconds\n"
                 "X,m,bfgs,7,9.869604401089358,0.5,1.25\n")
    lines = D.render("fig1", docs).splitlines()
    assert lines[2] == "| X | `m` | `bfgs` | 7 | 9.8696 | −50% | 0.5° | 1.2 |"


def test_unknown_block_raises(tmp_path):
    docs = _docs(tmp_path, "<!-- doc_numbers nosuch -->\n<!-- /doc_numbers nosuch -->\n")
    with pytest.raises(KeyError):
        D.update(docs, check=True)


def test_pct():
    assert D.pct(0.00932) == "+0.932%"
    assert D.pct(-0.5) == "−50%"
    assert D.pct(0.0009, 2) == "+0.09%"
