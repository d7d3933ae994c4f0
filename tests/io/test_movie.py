"""Movies (pyevolver.io.movie, Session.movie): one camera framed on the
whole run, measured on the PNG frames: a shape that moves and grows is in
every frame, never clipped, and the run fills the picture; GIF and MP4."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.errors import CommandError, UnsupportedError
from pyevolver.io import movie as movie_mod
from pyevolver.io import render_vtk
from pyevolver.io.movie import Movie

DATAFILES = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles")
# VTK starts in about 4 s: its frames are checked in the slow run; the
# framing rule is the same code for both backends (io.movie)
BACKENDS = [pytest.param("vtk", marks=pytest.mark.slow), "matplotlib"]


def _drawn(path):
    """Boolean mask of the pixels that are not the white background."""
    from PIL import Image
    img = np.asarray(Image.open(path).convert("RGB"), dtype=np.int64)
    return np.any(img < 245, axis=2)


def _backend(backend):
    if backend == "vtk" and not render_vtk.available():
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("PyVista is not installed: the test extra installs it")
        pytest.skip("PyVista (the view extra) is not installed")
    return backend


def _cube():
    return Session.load(os.path.join(DATAFILES, "cube.fe"), out=io.StringIO())


@pytest.mark.parametrize("backend", BACKENDS)
def test_a_moving_growing_shape_stays_in_every_frame(tmp_path, backend):
    _backend(backend)
    s = _cube()
    m = Movie(field=None, size=200)
    X0 = s.surface.X.copy()
    for k in range(4):                      # moves 6 cube sizes along x and grows 2.5 times
        s.surface.X = (1 + 0.5 * k) * X0 + [2.0 * k, 0.0, 0.5 * k]
        m.add(s.surface)
    frames = m.write_frames(str(tmp_path), backend=backend)
    assert len(frames) == 4
    union = None
    for k, path in enumerate(frames):
        d = _drawn(path)
        assert d.sum() > 0.005 * d.size, (k, d.sum())          # the shape is there
        border = np.concatenate([d[:2].ravel(), d[-2:].ravel(), d[:, :2].ravel(),
                                 d[:, -2:].ravel()])
        assert not border.any(), f"frame {k} is clipped"       # and whole
        union = d if union is None else union | d
    rows, cols = np.nonzero(union)
    # the camera is framed on the run: its extent spans most of the picture
    assert max(np.ptp(rows), np.ptp(cols)) >= 0.8 * union.shape[0]
    # a frame framed on itself alone would be much larger: the camera did not follow
    assert _drawn(frames[0]).sum() < 0.5 * _drawn(frames[-1]).sum()


def test_session_movie_writes_a_looping_gif(tmp_path, monkeypatch):
    monkeypatch.setattr(render_vtk, "available", lambda: False)     # matplotlib: quick
    from PIL import Image
    s = _cube()
    out = str(tmp_path / "cube.gif")
    assert s.movie(out, steps=6, every=3, size=160) == out
    im = Image.open(out)
    assert (im.n_frames, im.size, im.info.get("loop")) == (3, (160, 160), 0)
    assert s.history and len(s.history) == 6                   # the steps did run


def test_the_stomatocytes_frames_keep_the_shape_in_frame(tmp_path, monkeypatch):
    monkeypatch.setattr(render_vtk, "available", lambda: False)
    from pyevolver.studies.vesicle_shapes import datafile
    s = Session.load(datafile("stomatocyte", "perp"), out=io.StringIO())
    folder = str(tmp_path / "frames") + os.sep
    s.movie(folder, steps=4, every=2, commands="g 2; V", field=None, size=200)
    names = sorted(os.listdir(folder))
    assert names == ["frame0000.png", "frame0001.png", "frame0002.png"]
    for n in names:
        d = _drawn(os.path.join(folder, n))
        d[:25, :] = False                                       # the title "step k"
        assert not (d[-2:].any() or d[:, :2].any() or d[:, -2:].any()), n
        rows, cols = np.nonzero(d)
        assert max(np.ptp(rows), np.ptp(cols)) >= 0.6 * d.shape[0], n   # fills the frame


def test_mp4_with_ffmpeg_or_refused_by_name(tmp_path, monkeypatch):
    monkeypatch.setattr(render_vtk, "available", lambda: False)
    s = _cube()
    out = str(tmp_path / "cube.mp4")
    if movie_mod.ffmpeg_executable() is not None:
        s.movie(out, steps=2, every=1, size=120, field=None)
        with open(out, "rb") as fh:
            assert fh.read(12)[4:8] == b"ftyp"                   # an MP4 container
    monkeypatch.setattr(movie_mod, "ffmpeg_executable", lambda: None)
    with pytest.raises(UnsupportedError, match="MP4 movies without ffmpeg"):
        s.movie(str(tmp_path / "again.mp4"), steps=1)


def test_one_colour_range_for_all_frames():
    s = _cube()
    a = movie_mod.picture_data(s.surface, "area")
    s.surface.X = 3.0 * s.surface.X
    b = movie_mod.picture_data(s.surface, "area")
    lo, hi = movie_mod.common_range([a, b])
    assert lo <= a.fvals.min() + 1e-12 and hi >= b.fvals.max() - 1e-12 and hi > 8 * lo
    assert movie_mod.common_range([movie_mod.picture_data(s.surface, None)]) is None


def test_bad_requests_are_refused(tmp_path):
    s = _cube()
    with pytest.raises(CommandError, match="write .gif or .mp4"):
        s.movie(str(tmp_path / "cube.avi"), steps=1)
    with pytest.raises(CommandError, match="no frames"):
        Movie().write(str(tmp_path / "none.gif"))
    with pytest.raises(ValueError, match="every must be"):
        s.movie(str(tmp_path / "x.gif"), steps=2, every=0)
    assert not os.path.exists(tmp_path / "cube.avi")
