"""The Evolver's display commands without a display: ``s`` and ``show``
write the HTML viewer of the surface (:mod:`pyevolver.io.viewer`: rotate,
zoom, colour by a quantity in any web browser) and say where; ``P``
(the graphics output menu), ``geomview`` and the other external viewers are
refused by name, with the alternatives.

The viewer file is ``NAME.html`` for the datafile ``NAME.fe``, in the
current directory (``surface.html`` without a datafile); the variable
``viewer_file`` (a string) chooses another path.
"""
from __future__ import annotations

import os

from ..errors import UnsupportedError
from .registry import register

#: What to use instead of the Evolver's graphics output.
ALTERNATIVES = ('use snapshot "shape.png" for a picture, export "shape.vtu" for ParaView, '
                "s or show for a viewer in a web browser, or pyevolver show FILE.fe -o shape.png")


def viewer_path(session) -> str:
    """Where ``s``/``show`` write the viewer."""
    chosen = session.variables.get("viewer_file") if hasattr(session, "variables") else None
    if isinstance(chosen, str) and chosen:
        return chosen
    stem = os.path.splitext(os.path.basename(getattr(session, "filename", "") or ""))[0]
    return (stem or "surface") + ".html"


def _show(interp, raw, arg):
    s = interp.session
    path = viewer_path(s)
    title = os.path.basename(getattr(s, "filename", "") or "") or "pyevolver"
    from ..io.viewer import write_viewer     # (imported when first used)
    write_viewer(s.surface, path, title=title)
    s.write(f"Wrote the viewer {os.path.abspath(path)} (open it in a web browser).\n")


def _refused(interp, raw, arg):
    what = {"P": "P (the graphics output menu)",
            "geomview": "geomview (an external viewer)"}.get(raw, f"{raw} (graphics output)")
    raise UnsupportedError(what, ALTERNATIVES)


register("s", "show", usage="s | show", help="write the surface's viewer (HTML) and say where",
         family="display")(_show)
register("P", "geomview", "gv", "oogl", usage="(refused)",
         help="graphics output (refused: use snapshot, export or s)", family="display")(_refused)
