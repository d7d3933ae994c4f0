"""Headless pictures of a surface and of its energy history.

Surfaces are drawn with PyVista/VTK off-screen when it is installed (the
``view`` extra: smooth shading, :mod:`.render_vtk`) for PNG and JPEG files,
else with matplotlib (imported only when a picture is drawn; the Agg canvas,
no pyplot and no display; also for PDF and SVG).

The camera is the Evolver's view matrix (manual, "The View Matrix"): a
homogeneous (4, 4) matrix applied to the coordinates; after it the first
coordinate points towards the viewer, the second to the right and the third
up (as in the Evolver's ``povray.cmd``: camera on the +x axis, z up),
projected orthographically.  Only its direction is used: every picture is
framed on the surface's projected extent, so a surface that moves or grows
stays in the picture.  A view matrix without rotation (the Evolver's
initial one) is turned to the oblique :data:`OBLIQUE` view;
``view_matrix[i][j] := ...`` sets another from the command language,
:func:`camera` builds one from angles.  Colour ranges are clipped at
percentiles (:func:`pyevolver.io.fields.clipped_range`); the datafile's
facet colours are drawn when it sets them (``field="auto"``).
"""
from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from ..atomic import atomic_path
from ..errors import CommandError, UnsupportedError, dimension_error
from ..model.surface import Surface
from . import render_vtk
from .fields import clipped_range, curvature_method, facet_colors, surface_fields

#: The default direction of a picture: (azimuth, elevation) in degrees.
OBLIQUE = (-35.0, 25.0)


def oblique(view: np.ndarray | None) -> np.ndarray | None:
    """``view`` turned to the :data:`OBLIQUE` direction when it has no
    rotation (a diagonal 3×3 part: the Evolver's initial view matrix)."""
    if view is None:
        return None
    M = np.asarray(view, float)
    if M.shape == (4, 4) and np.count_nonzero(M[:3, :3] - np.diag(np.diag(M[:3, :3]))) == 0:
        return camera(np.zeros((0, 3)), *OBLIQUE) @ M
    return M


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


def _field_values(s, field):
    """``(vertex values or None, facet values, label)`` of ``field`` (a
    facet field, or a vertex field and its facet averages)."""
    v, f = surface_fields(s)
    if field in f:
        return None, np.asarray(f[field], float), f"facet {field}"
    if field in v:
        label = f"vertex {field}"
        if field == "mean_curvature":
            label = f"mean curvature ({curvature_method(s)})"
        vals = np.asarray(v[field], float)
        return vals, vals[s.F].mean(axis=1), label
    names = sorted(set(v) | set(f))
    raise CommandError(f"snapshot: no field '{field}' (known: {', '.join(names)}, "
                       f"colors, auto, none)")


def snapshot(surface: Surface | None, path: str, field: str | None = "auto",
             view: np.ndarray | None = None, size: int = 600, cmap: str = "viridis",
             edges: bool | None = None, clim: tuple | None = None,
             title: str | None = None, backend: str | None = None,
             frame: np.ndarray | None = None) -> str:
    """Draw ``surface`` into an image file (png, jpg, pdf, svg: by the
    extension), written atomically.

    Parameters
    ----------
    surface : Surface
        Its vertices ``X`` (nv, 3) and triangles ``F`` (nf, 3) are drawn.
    field : str or None
        Colour by this field of :func:`pyevolver.io.fields.surface_fields`
        with a labelled colour bar; ``"colors"`` for the datafile's facet
        colours; ``"auto"`` (default) for the facet colours when the datafile
        sets them, else the mean curvature; ``None`` or ``"none"`` for a
        plain grey surface.
    view : (4, 4) array, optional
        The view matrix (its direction; a session passes its
        ``view_matrix``); default the :data:`OBLIQUE` view.
    size : int
        Width and height of the picture in pixels (a colour bar takes the
        right fifth).
    edges : bool, optional
        Draw facet edges (default: when there are at most 5000 facets).
    clim : (lo, hi), optional
        Colour range (default: the field's range clipped at percentiles,
        :func:`pyevolver.io.fields.clipped_range`).
    backend : "vtk" or "matplotlib", optional
        Default: VTK when PyVista is installed and the file is .png or .jpg.
    frame : (k, 3) array, optional
        Frame the picture on these points instead of the surface's
        (:mod:`pyevolver.io.movie` passes every frame's points).

    Returns
    -------
    str
        ``path``.
    """
    if surface is not None and surface.X.shape[1] > 3:
        raise dimension_error(surface.sdim, "pictures", "need")
    s = surface
    if s is None or s.nf == 0:
        raise CommandError("snapshot: no facets to draw")
    M = camera(s.X, *OBLIQUE) if view is None else np.asarray(view, float)
    if M.shape != (4, 4):
        raise CommandError(f"snapshot: the view matrix must be 4x4, not {M.shape}")
    rgb = None
    if field == "auto":
        rgb = facet_colors(s)
        field = "mean_curvature" if rgb is None else "colors"
    if field == "colors":
        rgb = facet_colors(s)
        if rgb is None:
            rgb = np.tile([0.78, 0.80, 0.84], (s.nf, 1))
    vvals = fvals = None
    label = ""
    if field not in (None, "none", "colors"):
        vvals, fvals, label = _field_values(s, field)
        if clim is None:
            clim = clipped_range(vvals if vvals is not None else fvals)
        lo, hi = clim
        if not np.isfinite(lo) or not np.isfinite(hi):
            lo, hi = 0.0, 1.0
        if hi <= lo:
            lo, hi = lo - 0.5, hi + 0.5
        clim = (float(lo), float(hi))
    draw_edges = s.nf <= 5000 if edges is None else edges
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if backend is None:
        backend = "vtk" if ext in (".png", ".jpg", ".jpeg") and render_vtk.available() \
            else "matplotlib"
    if backend == "vtk":
        X3 = np.zeros((s.nv, 3))
        X3[:, :s.X.shape[1]] = s.X
        return render_vtk.render_png(path, X3, s.F, M, size, point_values=vvals,
                                     cell_values=fvals if vvals is None else None, clim=clim,
                                     label=label, cmap=cmap, rgb=rgb, edges=draw_edges,
                                     title=title, frame=frame)
    if backend != "matplotlib":
        raise CommandError(f"snapshot: no renderer '{backend}' (vtk or matplotlib)")
    return _snapshot_mpl(s, path, M, size, cmap, fvals, clim, label, rgb, draw_edges, title,
                         frame)


def _snapshot_mpl(s, path, M, size, cmap, fvals, clim, label, rgb, draw_edges, title,
                  frame=None, colorbar=True):
    """matplotlib: facets in painter's order, flat shading."""
    mpl, Figure, FigureCanvasAgg = _matplotlib()
    from matplotlib.collections import PolyCollection
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
    bar = fvals is not None and colorbar
    ax = fig.add_axes([0.0, 0.0, 0.8 if bar else 1.0, 1.0])
    if fvals is not None:
        norm = mpl.colors.Normalize(*clim)
        cm = mpl.colormaps[cmap]
        rgb = cm(norm(np.nan_to_num(fvals)))[:, :3]
    if bar:
        cax = fig.add_axes([0.82, 0.1, 0.03, 0.8])
        cb = fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=cm), cax=cax,
                          format=mpl.ticker.FormatStrFormatter("%.4g"))
        cb.set_label(label)
    elif rgb is None:
        rgb = np.tile([0.78, 0.80, 0.84], (s.nf, 1))
    rgb = np.clip(rgb * shade[:, None], 0.0, 1.0)
    pc = PolyCollection(C[order][:, :, 1:], facecolors=rgb[order],
                        edgecolors=(0.1, 0.1, 0.1, 0.6) if draw_edges else "face",
                        linewidths=0.3 if draw_edges else 0.0)
    ax.add_collection(pc)
    # framed on the surface (or on ``frame``), every picture
    if frame is not None:
        Q = np.asarray(frame, float)
        wq = Q @ M[3, :3] + M[3, 3]
        with np.errstate(all="ignore"):
            P = (Q @ M[:3, :3].T + M[:3, 3]) / np.where(wq == 0, 1.0, wq)[:, None]
    lo, hi = P[:, 1:].min(axis=0), P[:, 1:].max(axis=0)
    mid, half = (lo + hi) / 2, 0.53 * max(float(np.max(hi - lo)), 1e-12)
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
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
