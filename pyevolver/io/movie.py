"""Movies of a run: a picture every N steps, assembled into a GIF (or an MP4).

The frames are recorded first (coordinates, facets and the colour field of
each) and drawn at the end, so that every frame has the same camera, framed
on the points of *all* the frames (a shape that moves or grows stays in the
picture from the first frame to the last), and the same colour range::

    s = pyevolver.load("cube.fe")
    s.movie("cube.gif", steps=100, every=10)     # Session.movie: g 10, ten times

or by hand::

    m = Movie(field="mean_curvature")
    m.add(s.surface)
    ...
    m.write("run.gif", fps=5)

GIFs need Pillow (a dependency of matplotlib); MP4 needs ``ffmpeg``, from
the ``imageio-ffmpeg`` package or on the PATH (refused by name otherwise).
Pictures are drawn as :func:`pyevolver.io.render.snapshot` draws them
(PyVista/VTK when installed, matplotlib otherwise).
"""
from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from types import SimpleNamespace

import numpy as np

from ..atomic import atomic_path
from ..errors import CommandError, UnsupportedError, dimension_error
from ..model.surface import Surface
from . import render, render_vtk
from .fields import clipped_range, facet_colors

__all__ = ["Movie", "ffmpeg_executable", "picture_data", "common_range", "draw"]

GREY = (0.78, 0.80, 0.84)


def ffmpeg_executable() -> str | None:
    """The ffmpeg program: imageio-ffmpeg's, else one on the PATH, else None."""
    try:
        import imageio_ffmpeg
        return str(imageio_ffmpeg.get_ffmpeg_exe())
    except (ImportError, RuntimeError):
        return shutil.which("ffmpeg")


def picture_data(surface: Surface, field: str | None = "auto",
                 title: str | None = None) -> SimpleNamespace:
    """What a picture of ``surface`` needs, copied: ``X`` (nv, 3), ``F``,
    ``nv``, ``nf``, the colour ``vvals`` (vertex) or ``fvals`` (facet)
    values with their ``label``, or ``rgb`` facet colours, and ``title``;
    ``field`` as :func:`pyevolver.io.render.snapshot`'s."""
    if surface is None or surface.nf == 0:
        raise CommandError("picture: no facets to draw")
    if surface.X.shape[1] > 3:
        raise dimension_error(surface.sdim, "pictures", "need")
    X = np.zeros((surface.nv, 3))
    X[:, :surface.X.shape[1]] = surface.X
    rgb, vvals, fvals, label = None, None, None, ""
    if field == "auto":
        rgb = facet_colors(surface)
        field = "mean_curvature" if rgb is None else "colors"
    if field == "colors":
        rgb = facet_colors(surface)
        if rgb is None:
            rgb = np.tile(GREY, (surface.nf, 1))
    elif field not in (None, "none"):
        vvals, fvals, label = render._field_values(surface, field)
    return SimpleNamespace(X=X, F=np.array(surface.F, copy=True), nv=surface.nv, nf=surface.nf,
                           vvals=vvals, fvals=fvals, label=label, rgb=rgb, title=title)


def common_range(pictures: list) -> tuple | None:
    """One colour range for several :func:`picture_data`: from the lowest of
    their clipped ranges to the highest (None when none has values)."""
    vals = [f.vvals if f.vvals is not None else f.fvals for f in pictures]
    vals = [v for v in vals if v is not None]
    if not vals:
        return None
    ranges = np.array([clipped_range(v) for v in vals], float)   # each picture's
    lo, hi = float(np.nanmin(ranges[:, 0])), float(np.nanmax(ranges[:, 1]))
    if not np.isfinite(lo) or not np.isfinite(hi):
        lo, hi = 0.0, 1.0
    if hi <= lo:
        lo, hi = lo - 0.5, hi + 0.5
    return lo, hi


def draw(pic: SimpleNamespace, path: str, view: np.ndarray, size: int, clim: tuple | None,
         frame: np.ndarray | None = None, backend: str | None = None,
         colorbar: bool = True, cmap: str = "viridis") -> str:
    """Draw a :func:`picture_data` into the PNG ``path`` (VTK when PyVista
    imports, else matplotlib), coloured over ``clim``, framed on ``frame``
    (default its own points), with a colour bar unless ``colorbar`` is
    False; returns ``path``."""
    if backend is None:
        backend = "vtk" if render_vtk.available() else "matplotlib"
    edges = pic.nf <= 5000
    if backend == "vtk":
        return render_vtk.render_png(path, pic.X, pic.F, view, size, point_values=pic.vvals,
                                     cell_values=pic.fvals if pic.vvals is None else None,
                                     clim=clim, label=pic.label, rgb=pic.rgb, edges=edges,
                                     title=pic.title, frame=frame, colorbar=colorbar,
                                     cmap=cmap)
    return render._snapshot_mpl(pic, path, view, size, cmap, pic.fvals, clim, pic.label,
                                pic.rgb, edges, pic.title, frame=frame, colorbar=colorbar)


class Movie:
    """Frames of a surface, written as one animation with a fixed camera.

    Parameters
    ----------
    field : str or None
        The colour of every frame, as :func:`pyevolver.io.render.snapshot`'s
        ``field`` ("auto", a field name, "colors", or None for grey).
    view : (4, 4) array, optional
        The view matrix (its direction); default the oblique view.
    size : int
        Width and height of the frames in pixels.
    """

    def __init__(self, field: str | None = "auto", view: np.ndarray | None = None,
                 size: int = 400) -> None:
        self.field = field
        self.view = None if view is None else np.asarray(view, float)
        self.size = int(size)
        self.frames: list[SimpleNamespace] = []

    def __len__(self) -> int:
        return len(self.frames)

    def add(self, surface: Surface, title: str | None = None) -> None:
        """Record the surface as it is now (copies of its arrays)."""
        self.frames.append(picture_data(surface, self.field, title))

    def _clim(self) -> tuple | None:
        return common_range(self.frames)

    def write_frames(self, folder: str, backend: str | None = None) -> list[str]:
        """Draw every frame into ``folder`` as ``frame0000.png``, ... with one
        camera and one colour range; returns the paths."""
        if not self.frames:
            raise CommandError("movie: no frames recorded")
        pts = np.concatenate([f.X for f in self.frames])
        M = render.camera(pts, *render.OBLIQUE) if self.view is None else self.view
        clim = self._clim()
        if backend is None:
            backend = "vtk" if render_vtk.available() else "matplotlib"
        paths = []
        for k, f in enumerate(self.frames):
            path = os.path.join(folder, f"frame{k:04d}.png")
            paths.append(draw(f, path, M, self.size, clim, frame=pts, backend=backend))
        return paths

    @staticmethod
    def check_path(path: str, fps: float = 5.0) -> str | None:
        """Refuse what :meth:`write` cannot write, before a run spends its
        time: returns the ffmpeg program for ``.mp4``, else None."""
        path = os.fspath(path)
        if fps <= 0:
            raise CommandError(f"movie: fps must be positive, not {fps}")
        if path.endswith(("/", os.sep)):
            return None
        ext = os.path.splitext(path)[1].lower()
        if ext not in (".gif", ".mp4"):
            raise CommandError(f"movie: write .gif or .mp4 (or a folder ending in /), "
                               f"not '{ext}': {path}")
        exe = ffmpeg_executable() if ext == ".mp4" else None
        if ext == ".mp4" and exe is None:
            raise UnsupportedError("MP4 movies without ffmpeg",
                                   "pip install imageio-ffmpeg, or write a .gif")
        return exe

    def write(self, path: str, fps: float = 5.0, backend: str | None = None) -> str:
        """Write the movie to ``path``: ``.gif`` (looping), ``.mp4`` (needs
        ffmpeg), or a folder name ending in ``/`` for the PNG frames alone.
        Written atomically; returns ``path``."""
        path = os.fspath(path)
        exe = self.check_path(path, fps)
        if path.endswith(("/", os.sep)):
            os.makedirs(path, exist_ok=True)
            self.write_frames(path, backend)
            return path
        ext = os.path.splitext(path)[1].lower()
        with tempfile.TemporaryDirectory(prefix="pyevolver_movie_") as tmp:
            frames = self.write_frames(tmp, backend)
            try:
                with atomic_path(path, ext) as out:
                    if ext == ".gif":
                        _gif(frames, out, fps)
                    else:
                        _mp4(str(exe), tmp, out, fps)
            except OSError as exc:
                raise CommandError(f"cannot write '{path}': {exc.strerror or exc}") from None
        return path


def _gif(frames: list[str], out: str, fps: float) -> None:
    from PIL import Image
    images = [Image.open(p).convert("RGB") for p in frames]
    pal = [im.quantize(colors=255, method=Image.Quantize.MEDIANCUT) for im in images]
    pal[0].save(out, format="GIF", save_all=True, append_images=pal[1:],
                duration=max(int(round(1000.0 / fps)), 20), loop=0, disposal=1)


def _mp4(exe: str, folder: str, out: str, fps: float) -> None:
    cmd = [exe, "-y", "-loglevel", "error", "-framerate", f"{fps:g}",
           "-i", os.path.join(folder, "frame%04d.png"), "-vf",
           "scale=trunc(iw/2)*2:trunc(ih/2)*2", "-pix_fmt", "yuv420p", "-f", "mp4", out]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise CommandError(f"movie: ffmpeg failed: {res.stderr.strip()[:300]}")
