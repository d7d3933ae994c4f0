"""``python -m pyevolver.studies.doc_numbers --merge DIR``: a study's run on
some meshes replaces exactly those meshes' rows of the committed CSV."""
import csv

from pyevolver.studies import doc_numbers as D


def _write(path, rows):
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def test_merge_replaces_the_rows_of_the_meshes_run(tmp_path):
    docs, run = tmp_path / "docs", tmp_path / "run"
    docs.mkdir()
    run.mkdir()
    _write(docs / "fig3_torus.csv", [{"label": "a", "mesh": "5x10", "W": "1"},
                                     {"label": "a", "mesh": "20x32", "W": "2"}])
    _write(run / "fig3_torus.csv", [{"label": "a", "mesh": "20x32", "W": "3", "extra": "x"},
                                    {"label": "a", "mesh": "40x64", "W": "4", "extra": "y"}])
    assert D.merge_csv("fig3_torus.csv", str(run / "fig3_torus.csv"), str(docs)) == 2
    rows = D.read_csv("fig3_torus.csv", str(docs))
    assert [(r["mesh"], r["W"], r["extra"]) for r in rows] == [
        ("5x10", "1", ""), ("20x32", "3", "x"), ("40x64", "4", "y")]


def test_every_merged_csv_has_its_key_column():
    for name, key in D.MERGED.items():
        assert all(key in r for r in D.read_csv(name)), name
