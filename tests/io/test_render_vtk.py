"""Pictures on PyVista/VTK off-screen (pyevolver.io.render_vtk) and the
matplotlib fallback: ``pyevolver show`` of the cube and of catbody fills at
least a quarter of the picture and is shaded (at least 64 distinct colours),
measured on the PNG; a surface moved far away stays framed."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.cli.main import main
from pyevolver.io import render_vtk
from conftest import EXAMPLES

DATAFILES = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles")


def _vtk_or_fail():
    if not render_vtk.available():
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("PyVista is not installed: the test extra installs it")
        pytest.skip("PyVista (the view extra) is not installed")


def picture_stats(path):
    """(fraction of the picture that is not background, distinct colours)
    of a PNG; the colour bar's right fifth is left out of the count."""
    from matplotlib.image import imread
    img = imread(path)[:, :, :3]
    img = (np.asarray(img) * 255).round().astype(np.int64)
    h, w, _ = img.shape
    body = img[:, : int(0.8 * w)]
    drawn = np.any(body < 245, axis=2)
    codes = body[drawn] @ np.array([65536, 256, 1])
    return float(drawn.sum()) / (h * w), len(np.unique(codes))


@pytest.mark.parametrize("backend", ["vtk", "matplotlib"])
@pytest.mark.parametrize("name", ["cube.fe", "catbody.fe"])
def test_pyevolver_show_fills_a_quarter_and_is_shaded(tmp_path, evolver, name, backend,
                                                      monkeypatch, capsys):
    if backend == "vtk":
        _vtk_or_fail()
    else:
        monkeypatch.setattr(render_vtk, "available", lambda: False)
    out = str(tmp_path / "shape.png")
    assert main(["show", os.path.join(EXAMPLES, name), "-o", out, "--size", "400"]) == 0
    assert f"wrote {out}" in capsys.readouterr().out
    frac, colours = picture_stats(out)
    assert frac >= 0.25, frac
    assert colours >= 64, colours


def test_a_moved_surface_stays_in_frame(tmp_path):
    _vtk_or_fail()
    s = Session.load(os.path.join(DATAFILES, "cube.fe"), out=io.StringIO())
    s.run("r")
    s.snapshot(str(tmp_path / "a.png"), size=300)
    s.run("set vertex x x + 40; set vertex z 3 * z")
    s.snapshot(str(tmp_path / "b.png"), size=300)
    for p in ("a.png", "b.png"):
        frac, colours = picture_stats(str(tmp_path / p))
        assert frac >= 0.2 and colours >= 64, (p, frac, colours)


def test_facet_colours_of_the_datafile_are_drawn(tmp_path):
    _vtk_or_fail()
    s = Session.load(os.path.join(DATAFILES, "cube.fe"), out=io.StringIO())
    s.run("set facet color red where id <= 2; set facet color blue where id > 2")
    path = str(tmp_path / "c.png")
    s.snapshot(path, size=300, edges=False)
    from matplotlib.image import imread
    img = np.asarray(imread(path))[:, :, :3]
    red = (img[:, :, 0] > 0.3) & (img[:, :, 1] < 0.1) & (img[:, :, 2] < 0.1)
    blue = (img[:, :, 2] > 0.3) & (img[:, :, 0] < 0.1) & (img[:, :, 1] < 0.1)
    assert red.sum() > 100 and blue.sum() > 100, (red.sum(), blue.sum())


def test_only_png_and_jpg(tmp_path):
    _vtk_or_fail()
    from pyevolver.errors import CommandError
    X = np.eye(3)
    with pytest.raises(CommandError, match=".png or .jpg"):
        render_vtk.render_png(str(tmp_path / "x.svg"), X, np.array([[0, 1, 2]]), np.eye(4))
