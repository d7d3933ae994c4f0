"""Headless pictures of a surface and of its energy history (matplotlib,
imported only when a picture is drawn; the Agg canvas, no pyplot and no
display).

The camera is the Evolver's view matrix (manual, "The View Matrix"): a
homogeneous (4, 4) matrix applied to the coordinates; after it the first
coordinate points towards the viewer, the second to the right and the third
up (as in the Evolver's ``povray.cmd``: camera on the +x axis, z up), and
the picture shows the square [-1.4, 1.4]² of the other two, projected
orthographically.  A session's ``view_matrix`` starts by fitting the
surface's bounding box into [-1, 1]³ at load and then stays fixed: pictures
taken along an evolution share one camera.  ``view_matrix[i][j] := ...``
moves it from the command language, :func:`camera` builds one from angles.
"""
from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from ..atomic import atomic_path
from ..errors import CommandError, UnsupportedError, dimension_error
from ..model.surface import Surface
from .fields import curvature_method, surface_fields

#: Half-width of the picture in view coordinates: the initial view's
#: [-1, 1] with a margin for a surface that grows.
HALF_WIDTH = 1.4


def _matplotlib():
    try:
        import matplotlib
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError:
        raise UnsupportedError("pictures without matplotlib", "pip install matplotlib") from None
    return matplotlib, Figure, FigureCanvasAgg


def camera(X: np.ndarray, azimuth: float = 0.0, elevation: float = 0.0,
           zoom: float = 1.0) -> np.ndarray:
    """A (4, 4) view matrix: the bounding box of ``X`` (n, 3) centred and
    scaled into [-zoom, zoom]³ (the session's initial view), then turned by
    ``azimuth`` degrees about the vertical z axis and tipped by
    ``elevation`` degrees towards the viewer (positive: seen from above)."""
    X = np.asarray(X, float)
    M = np.eye(4)
    if len(X):
        lo, hi = X.min(axis=0), X.max(axis=0)
        size = float(np.max(hi - lo))
        sc = 2.0 * zoom / size if size > 0 else 1.0
        M[:3, :3] *= sc
        M[:3, 3] = -sc * (lo + hi) / 2
    a, e = np.radians(azimuth), np.radians(elevation)
    Rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    Ry = np.array([[np.cos(e), 0, np.sin(e)], [0, 1, 0], [-np.sin(e), 0, np.cos(e)]])
    R = np.eye(4)
    R[:3, :3] = Ry @ Rz
    return R @ M


def _facet_values(s, field):
    """Per-facet values of ``field`` (a facet field, or a vertex field
    averaged over each facet's corners) and its label."""
    v, f = surface_fields(s)
    if field in f:
        return np.asarray(f[field], float), f"facet {field}"
    if field in v:
        label = f"vertex {field}"
        if field == "mean_curvature":
            label = f"mean curvature ({curvature_method(s)})"
        return np.asarray(v[field], float)[s.F].mean(axis=1), label
    names = sorted(set(v) | set(f))
    raise CommandError(f"snapshot: no field '{field}' (known: {', '.join(names)}, none)")


def snapshot(surface: Surface | None, path: str, field: str | None = "mean_curvature",
             view: np.ndarray | None = None, size: int = 600, cmap: str = "viridis",
             edges: bool | None = None, clim: tuple | None = None,
             title: str | None = None) -> str:
    """Draw ``surface`` into an image file (png, pdf, svg: by the
    extension), written atomically.

    Parameters
    ----------
    surface : Surface
        Its vertices ``X`` (nv, 3) and triangles ``F`` (nf, 3) are drawn.
    field : str or None
        Colour facets by this field of :func:`pyevolver.io.fields.surface_fields`
        (vertex fields averaged over each facet) with a colour bar; ``None``
        or ``"none"`` for a plain grey surface.  Facets are shaded by the
        angle of their normal to the viewing direction.
    view : (4, 4) array, optional
        The view matrix (a session passes its ``view_matrix``); default
        :func:`camera` of the vertices.
    size : int
        Width of the picture in pixels (the height is the same).
    edges : bool, optional
        Draw facet edges (default: when there are at most 5000 facets).
    clim : (lo, hi), optional
        Colour range (default: the field's range).

    Returns
    -------
    str
        ``path``.
    """
    if surface is not None and surface.X.shape[1] > 3:
        raise dimension_error(surface.sdim, "pictures", "need")
    mpl, Figure, FigureCanvasAgg = _matplotlib()
    from matplotlib.collections import PolyCollection
    s = surface
    if s is None or s.nf == 0:
        raise CommandError("snapshot: no facets to draw")
    if view is None:
        view = camera(s.X)
    M = np.asarray(view, float)
    if M.shape != (4, 4):
        raise CommandError(f"snapshot: the view matrix must be 4x4, not {M.shape}")
    P = s.X @ M[:3, :3].T + M[:3, 3]                    # (nv, 3) view coordinates
    w = s.X @ M[3, :3] + M[3, 3]
    with np.errstate(all="ignore"):
        P = P / np.where(w == 0, 1.0, w)[:, None]
    C = P[s.F]                                          # (nf, 3 corners, 3)
    order = np.argsort(C[:, :, 0].mean(axis=1), kind="stable")   # far (small x) first
    n = np.cross(C[:, 1] - C[:, 0], C[:, 2] - C[:, 0])
    with np.errstate(all="ignore"):
        lam = np.nan_to_num(np.abs(n[:, 0]) / np.linalg.norm(n, axis=1))
    shade = 0.45 + 0.55 * lam
    fig = Figure(figsize=(size / 100.0, size / 100.0), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_axes([0.0, 0.0, 0.8 if field not in (None, "none") else 1.0, 1.0])
    if field in (None, "none"):
        rgb = np.tile([0.78, 0.80, 0.84], (s.nf, 1))
    else:
        vals, label = _facet_values(s, field)
        lo, hi = clim if clim is not None else (np.nanmin(vals), np.nanmax(vals))
        if not np.isfinite(lo) or not np.isfinite(hi):
            lo, hi = 0.0, 1.0
        if hi <= lo:
            lo, hi = lo - 0.5, hi + 0.5
        norm = mpl.colors.Normalize(lo, hi)
        cm = mpl.colormaps[cmap]
        rgb = cm(norm(np.nan_to_num(vals)))[:, :3]
        cax = fig.add_axes([0.8, 0.1, 0.03, 0.8])
        cb = fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=cm), cax=cax,
                          format=mpl.ticker.FormatStrFormatter("%.6g"))
        cb.set_label(label)
    rgb = np.clip(rgb * shade[:, None], 0.0, 1.0)
    draw_edges = s.nf <= 5000 if edges is None else edges
    pc = PolyCollection(C[order][:, :, 1:], facecolors=rgb[order],
                        edgecolors=(0.1, 0.1, 0.1, 0.6) if draw_edges else "face",
                        linewidths=0.3 if draw_edges else 0.0)
    ax.add_collection(pc)
    ax.set_xlim(-HALF_WIDTH, HALF_WIDTH)
    ax.set_ylim(-HALF_WIDTH, HALF_WIDTH)
    ax.set_aspect("equal")
    ax.set_axis_off()
    if title:
        ax.set_title(title)
    _save(fig, path)
    return path


def _save(fig, path):
    ext = os.path.splitext(os.fspath(path))[1].lower().lstrip(".") or "png"
    if ext not in fig.canvas.get_supported_filetypes():
        raise CommandError(f"cannot write a picture as '.{ext}' "
                           f"(use .png, .pdf or .svg): {path}")
    try:
        with atomic_path(path, "." + ext) as tmp:
            fig.savefig(tmp, format=ext)
    except OSError as exc:
        raise CommandError(f"cannot write '{path}': {exc.strerror or exc}") from None


def plot_history(history: Sequence, path: str, size: tuple = (6.4, 4.0),
                 log: bool | None = None) -> str:
    """Plot the energy of each ``g`` step against the iteration number;
    written atomically.

    Parameters
    ----------
    history : sequence of (iteration, energy, area)
        A session's ``history``.
    log : bool, optional
        Plot E − min E on a log scale (default: when the energy fell by
        more than a factor 100 of its final decrease).
    """
    _, Figure, FigureCanvasAgg = _matplotlib()
    hist = history
    if not hist:
        raise CommandError("plot_history: no iterations yet (run g first)")
    H = np.asarray(hist, float)
    it, E = H[:, 0], H[:, 1]
    fig = Figure(figsize=size, dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    gap = E - E.min()
    if log is None:
        log = len(E) > 2 and gap[-2] > 0 and gap[0] > 100 * gap[-2]
    if log:
        ax.semilogy(it, np.where(gap > 0, gap, np.nan), ".-", lw=1, ms=3)
        ax.set_ylabel("energy − min energy")
    else:
        ax.plot(it, E, ".-", lw=1, ms=3)
        ax.set_ylabel("energy")
    ax.set_xlabel("iteration")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    _save(fig, path)
    return path
