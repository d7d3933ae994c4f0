"""Render a datafile's surface to an image: ``pyevolver show FILE.fe -o shape.png``.

The datafile is loaded as ``pyevolver FILE.fe`` loads it (its ``read``
section runs), ``-c`` commands run next (for example ``-c "gogo"``), and
the picture is drawn headless (PyVista/VTK off-screen when installed, else
matplotlib's Agg canvas), framed on the surface, looking along the session's
view matrix (oblique while it has no rotation) or turned by ``--azimuth`` and
``--elevation``.
"""
from __future__ import annotations

import argparse
import io
import os
import sys

import numpy as np

from ...errors import PyEvolverError
from ...io.render import camera
from ...session.core import Session


def add_args(parser):
    parser.add_argument("datafile", help="Surface Evolver datafile (.fe)")
    parser.add_argument("-o", "--output", required=True, help="image file (.png, .pdf, .svg)")
    parser.add_argument("-c", "--commands", default="", help="commands to run first")
    parser.add_argument("--field", default="auto",
                        help="colour by this vertex or facet field, 'colors' (the "
                             "datafile's facet colours) or 'none' (default: the facet "
                             "colours when the datafile sets them, else mean_curvature)")
    parser.add_argument("--edges", action=argparse.BooleanOptionalAction, default=None,
                        help="draw the facet edges (default: up to 5000 facets)")
    parser.add_argument("--azimuth", type=float, default=0.0,
                        help="turn the view about the vertical z axis (degrees)")
    parser.add_argument("--elevation", type=float, default=0.0,
                        help="tip the view to look from above (degrees)")
    parser.add_argument("--size", type=int, default=600, help="width in pixels")


def run(args):
    if not os.path.isfile(args.datafile):
        raise PyEvolverError(f"show: cannot open datafile '{args.datafile}': no such file")
    sess = Session.load(args.datafile, out=io.StringIO(), err=sys.stderr)
    if args.commands:
        sess.run(args.commands, where="<-c>")
    view = None
    if args.azimuth or args.elevation:
        R = camera(np.zeros((0, 3)), args.azimuth, args.elevation)
        view = R @ sess.arrays["view_matrix"]
    sess.snapshot(args.output, field=args.field, view=view, size=args.size, edges=args.edges)
    print(f"wrote {args.output}")
    return 0
