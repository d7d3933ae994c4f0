"""s / show write the HTML viewer and say where; P and geomview are refused
by name with the alternatives; the display criteria (show facets where ...)
stay accepted."""
import io
import os

import pytest

from pyevolver import Session
from pyevolver.commands.display import ALTERNATIVES, viewer_path
from pyevolver.errors import DOCS_PAGE, PyEvolverError

CUBE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "datafiles",
                                    "cube.fe"))


@pytest.mark.parametrize("word", ["s", "show"])
def test_s_and_show_write_the_viewer_and_say_where(tmp_path, monkeypatch, word):
    monkeypatch.chdir(tmp_path)
    out = io.StringIO()
    s = Session.load(CUBE, out=out)
    s.run(word)
    path = tmp_path / "cube.html"
    assert path.is_file() and "<canvas" in path.read_text()
    assert f"Wrote the viewer {path} (open it in a web browser)." in out.getvalue()


def test_viewer_file_variable_chooses_the_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    s = Session.load(CUBE, out=io.StringIO())
    s.run('viewer_file := "sub.html"; s')
    assert (tmp_path / "sub.html").is_file() and not (tmp_path / "cube.html").exists()
    assert viewer_path(s) == "sub.html"


@pytest.mark.parametrize("cmd", ["P", "geomview", "geomview on"])
def test_P_and_geomview_are_refused_with_the_alternatives(cmd):
    s = Session.load(CUBE, out=io.StringIO())
    e0 = s.total_energy
    with pytest.raises(PyEvolverError) as exc:
        s.run(cmd)
    msg = str(exc.value)
    assert msg.startswith("<command>:1: not supported in pyevolver: ") and ALTERNATIVES in msg
    assert DOCS_PAGE in msg and s.total_energy == e0


def test_display_criteria_are_still_accepted(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    s = Session.load(CUBE, out=io.StringIO())
    s.run("show facets where area > 0; show_expr facets where 1")
    assert not list(tmp_path.iterdir())
