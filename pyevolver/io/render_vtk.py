"""Pictures on PyVista/VTK, off-screen (the optional ``view`` extra; the
``test`` extra installs it too).  :func:`pyevolver.io.render.snapshot` uses
it for PNG and JPEG files when PyVista imports, and matplotlib otherwise.

Smooth (Phong) shading with vertex normals, optional edges, vertex fields
interpolated over the facets and facet fields constant on them, the colour
range given by the caller (clipped at percentiles) with a labelled colour
bar, or the datafile's facet colours.  The camera looks along the view
matrix's first row (towards the viewer), with its third row up, in parallel
projection, and is framed on the surface's projected extent for every
picture.

Without a display VTK renders through EGL (Mesa's ``libegl1`` and
``libgl1-mesa-dri`` on Debian; ``.ci/run`` installs them).
"""
from __future__ import annotations

import os

import numpy as np

from ..atomic import atomic_path
from ..errors import CommandError


def available() -> bool:
    """True when PyVista (and VTK) import."""
    try:
        _pyvista()
    except ImportError:
        return False
    return True


def _pyvista():
    if not os.environ.get("DISPLAY"):
        # headless: EGL (VTK would try X first and print a warning)
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista
    return pyvista


def render_png(path: str, X: np.ndarray, F: np.ndarray, view: np.ndarray, size: int = 600,
               point_values: np.ndarray | None = None,
               cell_values: np.ndarray | None = None, clim: tuple | None = None,
               label: str = "", cmap: str = "viridis", rgb: np.ndarray | None = None,
               edges: bool = False, title: str | None = None,
               frame: np.ndarray | None = None, colorbar: bool = True) -> str:
    """Draw the triangles ``F`` on the points ``X`` (n, 3) into ``path``
    (.png or .jpg), written atomically; returns ``path``.

    ``view``: the (4, 4) view matrix (its rows 0 and 2: towards the viewer
    and up).  Colours: ``point_values`` or ``cell_values`` over ``clim``
    with the colour bar ``label``, else ``rgb`` (nf, 3) per facet, else
    plain grey.  ``frame``: the points (k, 3) to frame the camera on
    (default ``X``; a movie passes every frame's points, so that the camera
    stays put and the whole run is in the picture).  ``colorbar`` False:
    the values coloured over ``clim`` without a bar (a figure of several
    pictures draws one bar for all)."""
    pv = _pyvista()
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if ext not in (".png", ".jpg", ".jpeg"):
        raise CommandError(f"the VTK renderer writes .png or .jpg, not '{ext}': {path}")
    X = np.asarray(X, float)
    F = np.asarray(F, np.int64)
    faces = np.hstack([np.full((len(F), 1), 3, np.int64), F]).ravel()
    mesh = pv.PolyData(X, faces)
    coloured = point_values is not None or cell_values is not None
    bar = coloured and colorbar
    width = int(size)
    pl = pv.Plotter(off_screen=True, window_size=(width, size))
    pl.set_background("white")
    kw = dict(smooth_shading=True, show_edges=bool(edges), edge_color=(0.15, 0.15, 0.15),
              line_width=0.5, specular=0.25, specular_power=20.0, diffuse=0.8, ambient=0.2)
    note = ""
    if " (" in label:                     # a short bar title, the rest as a note
        label, note = label.split(" (", 1)
        note = note.rstrip(")")
    if coloured:
        vals = point_values if point_values is not None else cell_values
        if point_values is not None:
            mesh.point_data["value"] = np.asarray(vals, float)
        else:
            mesh.cell_data["value"] = np.asarray(vals, float)
        pl.add_mesh(mesh, scalars="value", cmap=cmap, clim=list(clim) if clim else None,
                    preference="point" if point_values is not None else "cell",
                    scalar_bar_args=dict(title=label, vertical=True, color="black",
                                         position_x=0.83, position_y=0.1, width=0.06,
                                         height=0.8, title_font_size=14,
                                         label_font_size=12, fmt="%.4g"),
                    show_scalar_bar=bar, **kw)
    elif rgb is not None:
        mesh.cell_data["rgb"] = np.clip(np.asarray(rgb, float) * 255, 0, 255).astype(np.uint8)
        pl.add_mesh(mesh, scalars="rgb", rgb=True, **kw)
    else:
        pl.add_mesh(mesh, color=(0.78, 0.80, 0.84), **kw)
    _frame(pl, X if frame is None else np.asarray(frame, float), np.asarray(view, float),
           width / size, bar)
    if title:
        pl.add_text(title, position="upper_left", font_size=12, color="black")
    if note:
        pl.add_text(note, position="lower_right", font_size=8, color="black")
    try:
        with atomic_path(path, ext) as tmp:
            pl.screenshot(tmp)
    except OSError as exc:
        raise CommandError(f"cannot write '{path}': {exc.strerror or exc}") from None
    finally:
        pl.close()
    return os.fspath(path)


def _frame(pl, X, M, aspect, bar):
    """Parallel camera along the view matrix, framed on the projected extent."""
    A = M[:3, :3]
    toward, right, up = (A[i] / (np.linalg.norm(A[i]) or 1.0) for i in range(3))
    r = X @ right
    u = X @ up
    centre_r, centre_u = (r.min() + r.max()) / 2, (u.min() + u.max()) / 2
    depth = X @ toward
    centre = centre_r * right + centre_u * up + depth.mean() * toward
    half_u = (u.max() - u.min()) / 2
    half_r = (r.max() - r.min()) / 2
    avail = aspect * (0.8 if bar else 1.0)         # the colour bar takes the right fifth
    scale = 1.06 * max(half_u, half_r / avail, 1e-12)
    span = float(np.ptp(depth)) + 4 * scale + 1.0
    cam = pl.camera
    cam.focal_point = tuple(centre)
    cam.position = tuple(centre + span * toward)
    cam.up = tuple(up)
    pl.enable_parallel_projection()
    cam.parallel_scale = scale
    if bar:                                           # shift the surface left of the bar
        cam.SetWindowCenter(0.2, 0.0)
    pl.renderer.ResetCameraClippingRange()
