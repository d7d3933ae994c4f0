"""docs/tutorial.md runs: its python blocks are executed in order, in one
namespace, in a fresh folder (a notebook run cell by cell)."""
import os
import re

DOCS = os.path.join(os.path.dirname(os.path.dirname(__file__)), "..", "docs")
DATAFILES = os.path.abspath(os.path.join(os.path.dirname(os.path.dirname(__file__)), "..", "datafiles"))


def blocks(path):
    """The ```python fenced blocks of a Markdown file, with their line numbers."""
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    out = []
    for m in re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M):
        out.append((text.count("\n", 0, m.start()) + 2, m.group(1)))
    return out


def test_tutorial_runs(tmp_path, monkeypatch):
    path = os.path.join(DOCS, "tutorial.md")
    code = blocks(path)
    assert len(code) >= 8
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("PYEVOLVER_DATAFILES", DATAFILES)
    ns = {"__name__": "__tutorial__"}
    for line, src in code:
        # compiled with the tutorial's file name and line, so a failure points at the doc
        exec(compile("\n" * (line - 1) + src, path, "exec"), ns)
    # the sweep's drops sit on the table: finite heights, lower where heavier
    rows = ns["result"].rows
    height = {(r["parameters"]["angle"], r["parameters"]["body[1].density"]):
              r["record"]["max(vertex, z)"] for r in rows}
    assert len(height) == 4 and all(0.3 < h < 1.5 for h in height.values()), height
    for angle in (60, 120):
        assert height[(angle, 1.0)] < height[(angle, 0.0)], height
    for name in ("cube.vtu", "cube.ply", "cube_again.fe", "cube.png", "cube_area.png",
                 "history.png", "cube.gif", "drops/results.csv"):
        assert os.path.getsize(tmp_path / name) > 0, name
