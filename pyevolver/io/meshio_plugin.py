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
``fixed`` and cell data ``tension`` are kept, and the bodies: cell data
``frontbody``/``backbody``, the body each facet bounds with its front or
back, 0 for none, and that body's ``frontbody_volume`` /
``backbody_volume`` (prescribed volume, NaN for none), ``..._density`` and
``..._pressure``: per facet, since meshio's VTU writer drops field data)
and writes them with the ``dump`` writer.  :func:`export` writes those
arrays for a surface with bodies, so ``.fe`` → ``.vtu`` → ``.fe`` keeps
them.

:func:`export` (the ``export "file"`` command, ``Session.export``) writes
the current surface in any meshio format chosen by the file's extension,
with the per-vertex and per-facet data arrays where the format can hold
them: vtu, vtk, xdmf (XML data; meshio needs h5py for it) keep point and
cell data, ply keeps point data; obj, stl and off hold the mesh alone.
Files are written atomically (:mod:`pyevolver.atomic`).
"""
from __future__ import annotations

import importlib.abc
import importlib.util
import os
import sys
from typing import TYPE_CHECKING

import numpy as np

from ..atomic import atomic_path
from ..datafile.reader import read_datafile
from ..datafile import writer
from ..datafile.writer import DumpSettings
from ..errors import CommandError, PyEvolverError, UnsupportedError, dimension_error
from ..model.arrays import surface_from_arrays
from ..model.build import build_surface
from ..model.surface import Surface
from .fields import surface_fields

if TYPE_CHECKING:
    import meshio

FORMAT = "evolver"

#: Writer options per meshio format: one file per export (xdmf's data
#: inline, not in a sidecar .h5), binary STL.
WRITE_OPTIONS: dict[str, dict] = {"xdmf": {"data_format": "XML"}, "stl": {"binary": True}}

#: Formats the tests round-trip, by extension.
EXPORT_FORMATS = {".vtu": "vtu", ".xdmf": "xdmf", ".ply": "ply", ".obj": "obj",
                  ".stl": "stl", ".off": "off"}


def _surface(obj):
    """A Surface, or the ``.surface`` of an object holding one (a session)."""
    if obj is None or isinstance(obj, Surface):
        return obj
    return obj.surface


def surface_mesh(surface, data: bool = True):
    """A :class:`meshio.Mesh` of ``surface`` (a Surface, or an object
    holding one in ``.surface``): points ``X`` (nv, 3), one ``"triangle"``
    block ``F`` (nf, 3) and, with ``data``, the point and cell data of
    :func:`pyevolver.io.fields.surface_fields`.  Refused in SPACE_DIMENSION
    > 3 (``dump`` writes such a surface)."""
    import meshio
    s = _surface(surface)
    if s is None:
        raise CommandError("export: no surface is loaded")
    if s.nf == 0:
        raise UnsupportedError("export of a surface without facets (the string model)")
    if s.X.shape[1] > 3:
        raise dimension_error(s.sdim, "mesh exports", "need")
    if s.periods is not None:
        raise UnsupportedError("export of a torus-model surface",
                               "facets across the periodic wrap would need copies of "
                               "their vertices; dump writes it")
    point_data, cell_data = {}, {}
    if data:
        v, f = surface_fields(s)             # evaluated afresh: X may have been set by hand
        point_data = v
        cell_data = {k: [a] for k, a in f.items()}
        if s.bodies.n:
            cell_data.update({k: [a] for k, a in body_arrays(s).items()})
    itype = np.int32 if s.nv < 2 ** 31 else np.int64      # PLY has no 64-bit integers
    return meshio.Mesh(np.array(s.X, float), [("triangle", np.array(s.F, itype))],
                       point_data=point_data, cell_data=cell_data)


BODY_ATTRS = ("volume", "density", "pressure")


def body_arrays(surface) -> dict[str, np.ndarray]:
    """The bodies as cell data: per facet the body it bounds with its front
    and with its back (``frontbody``, ``backbody``: 1-based, 0 for none;
    int32), and those bodies' ``frontbody_volume`` / ``backbody_volume``
    (prescribed, NaN where free or no body), ``..._density`` and
    ``..._pressure`` (NaN where not prescribed)."""
    b = surface.bodies
    M = b.facet_matrix.tocoo()
    out = {}
    for side, pick in (("frontbody", M.data > 0), ("backbody", M.data < 0)):
        which = np.zeros(surface.n_facets, np.int32)
        which[M.col[pick]] = M.row[pick] + 1
        out[side] = which
        for kw, vals in zip(BODY_ATTRS, (b.target, b.density, b.pressure)):
            per = np.full(surface.n_facets, np.nan)
            per[which > 0] = np.asarray(vals, float)[which[which > 0] - 1]
            out[f"{side}_{kw}"] = per
    return out


def _mesh_bodies(mesh, nf: int) -> list | None:
    """Bodies for :func:`surface_from_arrays` from the cell data of
    :func:`body_arrays` (None without ``frontbody``/``backbody``)."""
    def cells(name):
        blocks = mesh.cell_data.get(name)
        if blocks is None:
            return None
        a = np.concatenate([np.asarray(x, float).reshape(-1) for x in blocks])
        return a if len(a) == nf else None
    sides = {k: cells(k) for k in ("frontbody", "backbody")}
    if all(v is None for v in sides.values()):
        return None
    idx = {k: np.nan_to_num(v if v is not None else np.zeros(nf)).astype(np.int64)
           for k, v in sides.items()}
    nb = int(max(a.max(initial=0) for a in idx.values()))
    facets = np.arange(1, nf + 1)
    out = []
    for k in range(1, nb + 1):
        signed = np.concatenate([facets[idx["frontbody"] == k], -facets[idx["backbody"] == k]])
        signed = signed[np.argsort(np.abs(signed), kind="stable")]
        attrs = []
        for kw in BODY_ATTRS:
            parts = [a[idx[side] == k] for side in idx
                     if (a := cells(f"{side}_{kw}")) is not None]
            vals = np.concatenate(parts) if parts else np.zeros(0)
            vals = vals[np.isfinite(vals)]
            if len(vals) and not (kw == "density" and vals[0] == 0):
                attrs.append((kw, [float(vals[0])]))
        out.append((signed.tolist(), attrs))
    return out


def load_surface(filename: str) -> Surface:
    """The surface of a datafile as a session loads it, its ``read``
    section and top-section commands not run: the curvature and gravity
    toggles of its top section applied."""
    scene = read_datafile(os.fspath(filename))
    s = build_surface(scene)
    b = s.bodies
    s.gravity_on = bool(scene.values.get("gravity_constant", 0) != 0 or
                        bool(b.n and np.any(b.density)))
    s.curvature_mode = ("norm" if "normal_curvature" in scene.flags else
                        "eff" if "effective_area" in scene.flags else "plain")
    return s


def read_fe(filename: str):
    """meshio reader: the datafile's surface (its ``read`` section not run)."""
    return surface_mesh(load_surface(filename))


def _mesh_surface(mesh, filename) -> Surface:
    """Build a Surface from a meshio triangle mesh (:func:`surface_from_arrays`)."""
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
    if len(F) and (F.min() < 0 or F.max() >= len(X)):
        raise PyEvolverError(f"{filename}: a triangle refers to a point that does not exist")
    bad = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 0] == F[:, 2])
    if bad.any():
        raise PyEvolverError(f"{filename}: triangle {int(np.argmax(bad))} repeats a vertex")
    tension = mesh.cell_data.get("tension")
    if tension is not None and len(tension) == len(tris):
        tension = np.concatenate([np.asarray(a, float).reshape(-1) for a in tension])
    else:
        tension = None
    return surface_from_arrays(X, F, fixed=mesh.point_data.get("fixed"), tension=tension,
                               bodies=_mesh_bodies(mesh, len(F)),
                               filename=os.fspath(filename))


def write_fe(filename: str, mesh, **kwargs) -> None:
    """meshio writer: a triangle mesh as a datafile (by the ``dump`` writer)."""
    write_mesh(filename, mesh, FORMAT)


def file_format(path) -> str:
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


def export(surface, path: str, fmt: str | None = None, data: bool = True,
           settings: DumpSettings | None = None) -> str:
    """Write ``surface`` to ``path`` in the meshio format ``fmt`` (default:
    from the extension); returns the format name.  ``.fe`` is the ``dump``
    datafile, with the session ``settings``.  ``surface`` may also be an
    object holding one in ``.surface`` (a session).  Atomic: on any error
    ``path`` is left as it was."""
    fmt = fmt or file_format(path)
    if fmt == FORMAT:
        try:
            with atomic_path(path, ".fe") as tmp:
                writer.dump(surface, tmp, settings=settings)
        except OSError as exc:
            raise CommandError(f"cannot write '{path}': {exc.strerror or exc}") from None
        return fmt
    write_mesh(path, surface_mesh(surface, data), fmt)
    return fmt


def write_mesh(path, mesh, fmt: str | None = None) -> str:
    """Write a meshio mesh atomically in ``fmt`` (default: by the extension;
    ``evolver`` for ``.fe``) with :data:`WRITE_OPTIONS`."""
    import meshio
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
                writer.write_fe(_mesh_surface(mesh, path), tmp)
            else:
                meshio.write(tmp, mesh, file_format=fmt, **WRITE_OPTIONS.get(fmt, {}))
    except OSError as exc:
        raise CommandError(f"cannot write '{path}': {exc.strerror or exc}") from None
    except (ValueError, TypeError, KeyError, meshio.WriteError) as exc:
        raise CommandError(f"meshio could not write '{path}' as {fmt}: {exc}") from None
    return fmt


def register() -> None:
    """Register the ``.fe`` reader and writer with meshio (idempotent).

    ``import pyevolver`` calls :func:`register_when_imported` instead:
    importing meshio takes about 0.1 s, which the start-up of the
    ``pyevolver`` command does not pay."""
    import meshio
    if FORMAT not in meshio.extension_to_filetypes.get(".fe", []):
        meshio.register_format(FORMAT, [".fe"], read_fe, {FORMAT: write_fe})


class _RegisteringLoader(importlib.abc.Loader):
    """meshio's own loader, then :func:`register` once meshio is imported."""

    def __init__(self, loader):
        self.loader = loader

    def create_module(self, spec):
        return self.loader.create_module(spec)

    def exec_module(self, module):
        self.loader.exec_module(module)
        register()

    def __getattr__(self, name):            # get_resource_reader, is_package, ...
        return getattr(self.loader, name)


class _MeshioHook(importlib.abc.MetaPathFinder):
    """Finds nothing itself: wraps meshio's loader when meshio is imported."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname != "meshio":
            return None
        _remove_hook()
        spec = importlib.util.find_spec(fullname)
        if spec is not None and spec.loader is not None:
            spec.loader = _RegisteringLoader(spec.loader)
        return spec


def _remove_hook() -> None:
    sys.meta_path[:] = [f for f in sys.meta_path if not isinstance(f, _MeshioHook)]


def register_when_imported() -> None:
    """Register the ``.fe`` format now when meshio is imported, else as soon
    as it is (``import meshio, pyevolver`` and ``import pyevolver, meshio``
    both give ``meshio.read("cube.fe")``)."""
    if "meshio" in sys.modules:
        register()
    elif not any(isinstance(f, _MeshioHook) for f in sys.meta_path):
        sys.meta_path.insert(0, _MeshioHook())
