"""Headless pictures (pyevolver/render.py): ``snapshot``, ``pyevolver
show``, ``plot_history``.  The PNGs are read back and checked to be
images whose pixels are not all background."""
import io
import os
import subprocess
import sys

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.cli.main import main as cli_main
from pyevolver.errors import PyEvolverError
from pyevolver.io.render import camera

from conftest import example

mpimg = pytest.importorskip("matplotlib.image")
PNG = b"\x89PNG\r\n\x1a\n"


def _pixels(path):
    """(h, w, 3) RGB in [0, 1] of a PNG written by us (after its signature check)."""
    with open(path, "rb") as fh:
        assert fh.read(8) == PNG
    return mpimg.imread(path)[:, :, :3]


def _drawn(img):
    """Fraction of the pixels that differ from a blank (white) picture."""
    return float(np.mean(np.any(img < 0.99, axis=2)))


@pytest.fixture(scope="module")
def cube_gogo():
    s = Session.load(example("cube.fe"), out=io.StringIO(), err=io.StringIO())
    s.run("gogo")
    return s


def test_snapshot_of_cube_after_gogo(cube_gogo, tmp_path):
    s = cube_gogo
    path = tmp_path / "cube.png"
    s.out = io.StringIO()
    s.run(f'snapshot "{path}"')
    assert s.out.getvalue() == f"Snapshot written to {path}.\n"
    assert os.path.getsize(path) > 1000
    img = _pixels(path)
    assert img.shape == (600, 600, 3)
    # the rounded cube fills a disc of diameter about 1.4/2.8 of the width
    assert 0.15 < _drawn(img) < 0.9
    # coloured by mean curvature: more than a few distinct colours
    assert len(np.unique((img * 255).astype(int).reshape(-1, 3), axis=0)) > 20


def test_snapshot_camera_and_fields(cube_gogo, tmp_path):
    s = cube_gogo
    a, b, c = (str(tmp_path / n) for n in ("a.png", "b.png", "c.png"))
    s.run(f'snapshot("{a}", "area")')
    s.snapshot(b, field="area", view=camera(s.surface.X, azimuth=30, elevation=25))
    s.snapshot(c, field=None)
    A, B, C = _pixels(a), _pixels(b), _pixels(c)
    assert not np.array_equal(A, B)                 # the camera moved
    assert _drawn(C) > 0.15
    # no colour field: greys only (r = g = b within the tint of the surface)
    drawn = np.any(C < 0.99, axis=2)
    assert np.all(np.abs(C[drawn][:, 0] - C[drawn][:, 2]) < 0.1)
    # the session's view matrix is the camera: moving it moves the picture
    old = s.arrays["view_matrix"][1, 1]
    s.run("view_matrix[2][2] := 0.5")
    try:
        s.run(f'snapshot("{c}", "area")')
        assert not np.array_equal(_pixels(c), A)
    finally:
        s.arrays["view_matrix"][1, 1] = old


def test_snapshot_errors(cube_gogo, tmp_path):
    s = cube_gogo
    with pytest.raises(PyEvolverError, match=r"no field 'nosuch' \(known: .*mean_curvature"):
        s.run(f'snapshot("{tmp_path}/x.png", "nosuch")')
    with pytest.raises(PyEvolverError, match=r"cannot write a picture as '.xyz'"):
        s.run(f'snapshot "{tmp_path}/x.xyz"')
    with pytest.raises(PyEvolverError, match="snapshot takes at most 2 arguments"):
        s.run(f'snapshot("{tmp_path}/x.png", "area", "more")')
    assert os.listdir(tmp_path) == []


def test_plot_history(tmp_path):
    s = Session.load(example("cube.fe"), out=io.StringIO(), err=io.StringIO())
    with pytest.raises(PyEvolverError, match="no iterations yet"):
        s.run(f'plot_history "{tmp_path}/h.png"')
    s.run("g 5; r; g 5")
    assert len(s.history) == 10
    assert [h[0] for h in s.history] == list(range(1, 11))
    s.run(f'plot_history "{tmp_path}/h.png"')
    assert _drawn(_pixels(tmp_path / "h.png")) > 0.01


def test_show_cli(tmp_path, capsys):
    out = str(tmp_path / "show.png")
    assert cli_main(["show", example("cube.fe"), "-o", out, "-c", "r; g 5",
                     "--azimuth", "20", "--elevation", "15", "--size", "300"]) == 0
    assert _pixels(out).shape == (300, 300, 3) and _drawn(_pixels(out)) > 0.1
    assert cli_main(["show", example("cube.fe"), "-o", out, "--field", "bad"]) == 1
    assert "no field 'bad'" in capsys.readouterr().err


def test_matplotlib_is_imported_lazily():
    code = ("import sys, pyevolver; s = pyevolver.load(sys.argv[1]); s.run('g 2'); "
            "print('matplotlib' in sys.modules, 'tqdm' in sys.modules)")
    r = subprocess.run([sys.executable, "-c", code, example("cube.fe")], capture_output=True,
                       text=True, env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert r.stdout.split()[-2:] == ["False", "False"], r.stdout + r.stderr
