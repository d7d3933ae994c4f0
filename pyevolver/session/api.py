"""The notebook side of :class:`pyevolver.Session`: files and pictures
(``export``, ``snapshot``, ``plot_history``) and the progress bars of long
runs.  The values (``quantities``, ``value``) are on the Session itself::

    import pyevolver
    s = pyevolver.load("cube.fe")
    s.run("r; u; g 10")
    s.quantities                 # {"name": value} of the named quantities
    s.value("body[1].volume")    # any expression of the command language
    s.export("cube.vtu")         # any meshio format, with data arrays
    s.snapshot("cube.png", field="mean_curvature")
    s.plot_history("energy.png")
    s.movie("cube.gif", steps=50, every=5)   # a picture every 5 steps, one camera

Progress bars (tqdm) are the API's only: :meth:`Session.g` shows one for
long runs at a terminal or in a notebook, never in the Evolver-compatible
text output of the commands.
"""
from __future__ import annotations

import sys
from typing import Any

import numpy as np

from ..datafile.writer import DumpSettings
from ..errors import UnsupportedError
from ..io import meshio_plugin

#: ``progress=None`` shows a bar for runs of at least this many steps.
PROGRESS_MIN_STEPS = 100


def progress_bar(total, progress=None, desc=None):
    """A tqdm bar of ``total`` steps, or None.

    ``progress`` True: a bar (refused by name when tqdm is not installed);
    False: none; None: a bar when ``total >= PROGRESS_MIN_STEPS``, tqdm is
    installed and the output is a terminal or a notebook.
    """
    if progress is False or total <= 0:
        return None
    if progress is None:
        interactive = "ipykernel" in sys.modules or sys.stderr.isatty()
        if total < PROGRESS_MIN_STEPS or not interactive:
            return None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        if progress:
            raise UnsupportedError("progress bars without tqdm", "pip install tqdm") from None
        return None
    return tqdm(total=total, desc=desc, leave=False)


class SessionAPI:
    """Files and pictures of :class:`pyevolver.Session` (a mixin)."""

    # the Session state these methods read (set by Session.__init__)
    surface: Any
    filename: str
    settings: dict[str, Any]
    toggles: dict[str, Any]
    attr_types: dict[tuple, str]
    arrays: dict[str, Any]
    history: list[tuple]
    _rng: Any = None

    @property
    def rng(self) -> np.random.Generator:
        """The random generator of ``random`` and ``j`` (seed 1; ``random_seed :=``
        reseeds it), made when first used: numpy.random's import is not part
        of a start-up that never draws a number."""
        if self._rng is None:
            self._rng = np.random.default_rng(1)
        return self._rng

    @rng.setter
    def rng(self, value: np.random.Generator) -> None:
        self._rng = value

    def export(self, path: str, fmt: str | None = None, data: bool = True) -> str:
        """Write the surface to ``path`` in a meshio format chosen by the
        extension (``.vtu``, ``.ply``, ``.obj``, ``.stl``, ``.off``,
        ``.xdmf``, ...; ``.fe`` is ``dump``) with the per-vertex and
        per-facet data arrays of :func:`pyevolver.io.fields.surface_fields`;
        returns the format name (:func:`pyevolver.io.export`)."""
        return meshio_plugin.export(self.surface, path, fmt, data,
                                    settings=DumpSettings(self.filename, self.settings,
                                                          self.toggles, self.attr_types))

    def snapshot(self, path: str, field: str | None = "auto", view: np.ndarray | None = None,
                 **kwargs: Any) -> str:
        """Render the surface to an image file, headless
        (:func:`pyevolver.io.render.snapshot`; the camera looks along the
        session's ``view_matrix``, turned oblique while it has no rotation,
        unless ``view`` is given; framed on the surface every time)."""
        from ..io import render            # (pictures: imported when first drawn)
        if view is None:
            view = render.oblique(self.arrays.get("view_matrix"))
        return render.snapshot(self.surface, path, field=field, view=view, **kwargs)

    def movie(self, path: str, steps: int, every: int = 1, commands: str | None = None,
              field: str | None = "auto", view: np.ndarray | None = None, size: int = 400,
              fps: float = 5.0) -> str:
        """Run ``steps`` iteration steps and write a movie of them to ``path``
        (``.gif``; ``.mp4`` with ffmpeg; a folder ending in ``/`` for the PNG
        frames): a picture before the run and after every ``every`` steps
        (or, with ``commands``, after each run of that command text instead
        of ``g every``, ``steps // every`` times).  Every frame has the same
        camera, framed on the whole run, and the same colour range
        (:class:`pyevolver.io.movie.Movie`).  Returns ``path``."""
        if every < 1 or steps < 0:
            raise ValueError(f"movie: every must be >= 1 and steps >= 0 (got {every}, {steps})")
        from ..io import render
        from ..io.movie import Movie
        Movie.check_path(path, fps)                   # refused before the run, not after
        if view is None:
            view = render.oblique(self.arrays.get("view_matrix"))
        m = Movie(field=field, view=view, size=size)
        m.add(self.surface, title="step 0")
        done = 0
        while done + every <= steps:
            if commands is None:
                self.g(every, echo=False)  # type: ignore[attr-defined]
            else:
                self.run(commands)  # type: ignore[attr-defined]
            done += every
            m.add(self.surface, title=f"step {done}")
        return m.write(path, fps=fps)

    def _repr_html_(self) -> str | None:
        """In a notebook a session shows its surface in the viewer of
        :mod:`pyevolver.io.viewer` (None where it has no facets to draw)."""
        surf = getattr(self, "surface", None)
        if surf is None or surf.nf == 0 or surf.X.shape[1] > 3:
            return None
        from ..io import viewer
        return viewer.notebook_html(surf, title=repr(self))

    def plot_history(self, path: str, **kwargs: Any) -> str:
        """Plot the energy of every ``g`` step so far
        (:func:`pyevolver.io.render.plot_history`)."""
        from ..io import render
        return render.plot_history(self.history, path, **kwargs)
