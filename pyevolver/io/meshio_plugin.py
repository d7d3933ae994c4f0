"""The Evolver datafile as a meshio format, and ``export`` to meshio formats.

:func:`register` (run on ``import pyevolver``) registers the format
``"evolver"`` for the extension ``.fe``, so that::

    import meshio, pyevolver
    mesh = meshio.read("cube.fe")      # the datafile's surface, with data arrays
    meshio.write("out.fe", mesh)       # a triangle mesh as a datafile

work like any other meshio format (meshio's own ``register_format``).
Reading loads the datafile without running its ``read`` section and
returns the triangles with the data of :func:`pyevolver.io.fields.surface_fields`;
writing turns triangles into vertices, edges and faces (point data
``fixed`` and cell data ``tension`` are kept, nothing else: no bodies) and
writes them with the ``dump`` writer.

:func:`export` (the ``export "file"`` command, ``Session.export``) writes
the current surface in any meshio format chosen by the file's extension,
with the per-vertex and per-facet data arrays where the format can hold
them: vtu, vtk, xdmf (XML data; meshio needs h5py for it) keep point and
cell data, ply keeps point data; obj, stl and off hold the mesh alone.
Files are written atomically (:mod:`pyevolver.atomic`).
"""
from __future__ import annotations

import io
import os

import numpy as np

from ..atomic import atomic_path
from ..errors import CommandError, PyEvolverError, UnsupportedError

FORMAT = "evolver"

#: Writer options per meshio format: one file per export (xdmf's data
#: inline, not in a sidecar .h5), binary STL.
WRITE_OPTIONS = {"xdmf": {"data_format": "XML"}, "stl": {"binary": True}}

#: Formats the tests round-trip, by extension.
EXPORT_FORMATS = {".vtu": "vtu", ".xdmf": "xdmf", ".ply": "ply", ".obj": "obj",
                  ".stl": "stl", ".off": "off"}


def _split(obj):
    from ..session.core import Session
    if isinstance(obj, Session):
        return obj, obj.surface
    return None, obj


def surface_mesh(obj, data=True):
    """A :class:`meshio.Mesh` of a surface (or of a :class:`Session`'s):
    points ``X`` (nv, 3), one ``"triangle"`` block ``F`` (nf, 3) and, with
    ``data``, the point and cell data of
    :func:`pyevolver.io.fields.surface_fields`."""
    import meshio
    from .fields import surface_fields
    _, s = _split(obj)
    if s is None:
        raise CommandError("export: no surface is loaded")
    if s.nf == 0:
        raise UnsupportedError("export of a surface without facets (the string model)")
    if s.periods is not None:
        raise UnsupportedError("export of a torus-model surface",
                               "facets across the periodic wrap would need copies of "
                               "their vertices; dump writes it")
    point_data, cell_data = {}, {}
    if data:
        v, f = surface_fields(s)             # evaluated afresh: X may have been set by hand
        point_data = v
        cell_data = {k: [a] for k, a in f.items()}
    itype = np.int32 if s.nv < 2 ** 31 else np.int64      # PLY has no 64-bit integers
    return meshio.Mesh(np.array(s.X, float), [("triangle", np.array(s.F, itype))],
                       point_data=point_data, cell_data=cell_data)


def read_fe(filename):
    """meshio reader: the datafile's surface (its ``read`` section not run)."""
    from ..session.core import Session
    sess = Session.load(os.fspath(filename), out=io.StringIO(), err=io.StringIO(),
                        run_read=False)
    return surface_mesh(sess)


def _mesh_surface(mesh, filename):
    """Build a Surface from a meshio triangle mesh (through the datafile reader)."""
    from ..datafile.reader import read_datafile
    from ..studies.meshes import fe_text
    from ..model.build import build_surface
    tris = []
    for block in mesh.cells:
        if block.type != "triangle":
            raise UnsupportedError(f"writing {block.type} cells to a datafile",
                                   "only triangles become facets")
        tris.append(np.asarray(block.data, np.int64))
    if not tris:
        raise UnsupportedError("writing a mesh without triangles to a datafile")
    F = np.concatenate(tris)
    X = np.asarray(mesh.points, float)
    if X.ndim != 2 or X.shape[1] not in (2, 3):
        raise UnsupportedError(f"writing {X.shape[-1]}-dimensional points to a datafile")
    if X.shape[1] == 2:
        X = np.hstack([X, np.zeros((len(X), 1))])
    if len(F) and (F.min() < 0 or F.max() >= len(X)):
        raise PyEvolverError(f"{filename}: a triangle refers to a point that does not exist")
    bad = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 0] == F[:, 2])
    if bad.any():
        raise PyEvolverError(f"{filename}: triangle {int(np.argmax(bad))} repeats a vertex")
    s = build_surface(read_datafile(os.fspath(filename), fe_text(X, F)))
    fixed = mesh.point_data.get("fixed")
    if fixed is not None:
        s.vattr["fixed"] = np.asarray(fixed).reshape(-1) != 0
    tension = mesh.cell_data.get("tension")
    if tension is not None and len(tension) == len(tris):
        s.fattr["tension"] = np.concatenate([np.asarray(a, float).reshape(-1)
                                             for a in tension])
    return s


def write_fe(filename, mesh, **kwargs):
    """meshio writer: a triangle mesh as a datafile (by the ``dump`` writer)."""
    write_mesh(filename, mesh, FORMAT)


def file_format(path):
    """The meshio format of ``path``, from its extension."""
    import meshio
    name = os.path.basename(os.fspath(path)).lower()
    parts = name.split(".")
    for k in range(1, len(parts)):
        ext = "." + ".".join(parts[k:])
        fmts = meshio.extension_to_filetypes.get(ext)
        if fmts:
            return fmts[0]
    raise CommandError(f"export: cannot tell the format of '{path}' from its extension "
                       f"(for example .vtu, .ply, .obj, .stl, .off, .xdmf)")


def export(obj, path, fmt=None, data=True):
    """Write the surface of ``obj`` (a Session or a Surface) to ``path`` in
    the meshio format ``fmt`` (default: from the extension); returns the
    format name.  ``.fe`` is the ``dump`` datafile.  Atomic: on any error
    ``path`` is left as it was."""
    fmt = fmt or file_format(path)
    if fmt == FORMAT:
        from ..datafile.writer import dump
        try:
            with atomic_path(path, ".fe") as tmp:
                dump(obj, tmp)
        except OSError as exc:
            raise CommandError(f"cannot write '{path}': {exc.strerror or exc}") from None
        return fmt
    write_mesh(path, surface_mesh(obj, data), fmt)
    return fmt


def write_mesh(path, mesh, fmt=None):
    """Write a meshio mesh atomically in ``fmt`` (default: by the extension;
    ``evolver`` for ``.fe``) with :data:`WRITE_OPTIONS`."""
    import meshio
    from ..datafile.writer import write_fe as dump_fe
    fmt = fmt or file_format(path)
    if fmt == "xdmf":
        try:
            import h5py  # noqa: F401  (meshio's xdmf writer imports it)
        except ImportError:
            raise UnsupportedError("xdmf files without h5py",
                                   "pip install h5py (or pyevolver[xdmf])") from None
    ext = os.path.splitext(os.fspath(path))[1]
    try:
        with atomic_path(path, ext) as tmp:
            if fmt == FORMAT:
                dump_fe(_mesh_surface(mesh, path), tmp)
            else:
                meshio.write(tmp, mesh, file_format=fmt, **WRITE_OPTIONS.get(fmt, {}))
    except OSError as exc:
        raise CommandError(f"cannot write '{path}': {exc.strerror or exc}") from None
    except (ValueError, TypeError, KeyError, meshio.WriteError) as exc:
        raise CommandError(f"meshio could not write '{path}' as {fmt}: {exc}") from None
    return fmt


def register():
    """Register the ``.fe`` reader and writer with meshio (idempotent)."""
    import meshio
    if FORMAT not in meshio.extension_to_filetypes.get(".fe", []):
        meshio.register_format(FORMAT, [".fe"], read_fe, {FORMAT: write_fe})
