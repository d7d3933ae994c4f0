"""docs/guide.md documents the sweep file: its example loads as written
(with the shipped mound.fe), and its table lists exactly the keys the
loader knows."""
import os
import re
import shutil

from pyevolver.studies.sweep import SPEC_KEYS, load_spec

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")
GUIDE = os.path.join(ROOT, "docs", "guide.md")


def _section():
    with open(GUIDE, encoding="utf-8") as fh:
        text = fh.read()
    start = text.index("### The sweep file")
    return text[start:text.index("\n## ", start)]


def test_the_documented_example_loads(tmp_path):
    sec = _section()
    toml = re.search(r"```toml\n(.*?)```", sec, re.S).group(1)
    shutil.copy(os.path.join(ROOT, "datafiles", "mound.fe"), tmp_path)
    path = tmp_path / "spec.toml"
    path.write_text(toml, encoding="utf-8")
    spec = load_spec(str(path))
    assert spec.parameters == {"angle": [60.0, 90.0, 120.0],
                               "body[1].density": [0.0, 0.5, 1.0]}
    assert spec.continuation == "angle" and spec.plot_color == "total_energy"
    assert spec.output == str(tmp_path / "mound_sweep") and spec.record == ["max(vertex, z)"]
    assert len(spec.points()) == 9


def test_the_table_lists_every_key():
    keys = set(re.findall(r"^\| `(\w+)` \|", _section(), re.M))
    assert keys == SPEC_KEYS
