"""Convert a surface between formats: ``pyevolver convert IN OUT``.

Either side may be an Evolver datafile (``.fe``: read without running its
``read`` section; written by the ``dump`` writer) or any format meshio
knows by its extension (vtu, ply, obj, stl, off, xdmf, ...).  A datafile's
surface carries its data arrays (mean curvature, areas, constraint flags)
into the formats that hold them.
"""
from __future__ import annotations

import os

import meshio

from ...errors import PyEvolverError
from ...io.meshio_plugin import file_format, write_mesh


def add_args(parser):
    parser.add_argument("input", help="file to read (.fe or a meshio format)")
    parser.add_argument("output", help="file to write; the format from its extension")


def run(args):
    if not os.path.isfile(args.input):
        raise PyEvolverError(f"convert: cannot open '{args.input}': no such file")
    fmt = file_format(args.output)
    try:
        mesh = meshio.read(args.input)
    except (meshio.ReadError, ValueError, KeyError) as exc:
        raise PyEvolverError(f"convert: meshio cannot read '{args.input}': {exc}") from None
    except SystemExit:          # meshio exits on some unreadable files (e.g. a broken .vtu)
        raise PyEvolverError(f"convert: meshio cannot read '{args.input}'") from None
    write_mesh(args.output, mesh, fmt)
    nf = sum(len(c.data) for c in mesh.cells)
    print(f"{args.input} -> {args.output} ({fmt}): {len(mesh.points)} vertices, {nf} cells")
    return 0
