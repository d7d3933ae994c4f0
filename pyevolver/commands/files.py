"""File commands: ``load``, ``addload``, ``replace_load`` (datafiles) and
``read`` (command files, found in the current directory or EVOLVERPATH).
The session is duck-typed: ``surface``, ``variables``, ``run``,
``_install``, ``recalc``.
"""
from __future__ import annotations

import copy
import os

import numpy as np

from ..datafile.reader import read_datafile
from ..errors import CommandError, PyEvolverError, UnsupportedError
from ..limits import MAX_NESTING
from ..model.build import build_surface
from ..remesh.merge import append_surface
from .registry import register
from .values import Loaded, Quit, SessionLike


def _read_new(session: SessionLike, cmd, name):
    if not os.path.isfile(name):
        if os.path.exists(name):
            raise CommandError(f"{cmd}: '{name}' is not a regular file (a directory, "
                               f"device or pipe)")
        raise CommandError(f"{cmd}: cannot find datafile '{name}'")
    scene = read_datafile(name)
    return scene, build_surface(scene)


def load_command(session: SessionLike, name):
    """``load "file"``: a fresh start on another datafile (variables,
    commands and toggles forgotten; its read section runs)."""
    scene, surface = _read_new(session, "load", name)
    out, err, limit = session.out, session.err, session.time_limit
    session.__init__(out, err)
    session.time_limit = limit
    session._install(name, scene, surface, True)


def replace_load(session: SessionLike, name):
    """``replace_load "file"``: the surface of another datafile replaces
    the current one; variables, commands and toggles are kept, the new
    file's parameters and settings override, its read section is not run."""
    scene, surface = _read_new(session, "replace_load", name)
    old = session.surface
    if old is not None:
        for qname in old.quantities:
            if qname not in surface.quantities:
                raise UnsupportedError(
                    f"replace_load: the quantity or method instance '{qname}' of the "
                    f"current surface is not declared in {name}",
                    "the Evolver would keep it for the new surface")
        for cid, c in old.constraints.items():
            if cid not in surface.constraints:
                raise UnsupportedError(
                    f"replace_load: constraint {cid} of the current surface is not "
                    f"declared in {name}", "the Evolver would keep it")
    params = session.variables
    params.update(surface.params)
    surface.params = params
    session.surface = surface
    session.filename = name
    session._iterator = None
    scene_settings(session, scene)
    session.recalc()


def addload(session: SessionLike, name):
    """``addload "file"``: the file's elements added to the surface,
    numbered after the existing ones; its declarations override, its
    read section is not run."""
    scene, new = _read_new(session, "addload", name)
    if session.surface is None:
        raise CommandError("addload: no surface is loaded")
    if new.string:
        session.no_string("addload", new)
    session.no_string("addload")
    merged = append_surface(copy.deepcopy(session.surface), new)
    session.variables.update(merged.params)
    merged.params = session.variables
    if "gravity_constant" in scene.values:
        merged.gravity_constant = scene.values["gravity_constant"]
    session.surface = merged
    session._iterator = None
    session.recalc()


def read_file(session: SessionLike, name):
    """``read "file"``: run a command file (the current directory first,
    then the directories of EVOLVERPATH).  An error stops the file."""
    cands = [name]
    if not os.path.isabs(name):
        for d in os.environ.get("EVOLVERPATH", "").split(os.pathsep):
            if d:
                cands.append(os.path.join(d, name))
    path = next((c for c in cands if os.path.exists(c)), None)
    if path is None:
        raise CommandError(f"read: cannot find file '{name}' (looked in the current "
                           f"directory and EVOLVERPATH)")
    if not os.path.isfile(path):       # /dev/zero, a FIFO, a directory: never read
        raise CommandError(f"read: '{path}' is not a regular file (a directory, "
                           f"device or pipe)")
    if len(session.interp.env.scopes) > MAX_NESTING:
        raise CommandError(f"read \"{name}\": files read each other too deeply")
    try:
        with open(path, encoding="latin-1") as fh:
            text = fh.read()
    except OSError as exc:
        raise CommandError(f"read: cannot read '{name}': {exc.strerror}") from None
    try:
        session.run(text, where=path, line=1, stop_on_error=True)
    except Quit:
        raise
    except PyEvolverError as exc:
        # like the Evolver, an error abandons the rest of the file; what
        # ran before it stays done
        session.write_err(f"{exc}\n")


# -- loading: warnings, settings, the view ------------------------------------------
def warn_bare_edges(session: SessionLike, filename, scene, s):
    """REF warns at load about each edge of a soapfilm surface that is on
    no facet and not marked BARE ("Edge 19 has no facets, and is not
    marked "bare".")."""
    if s.string or not s.nf or not s.ne or len(scene.edges.ids) > s.ne:
        return
    FE = np.asarray(s.FE)
    used = np.zeros(s.ne, bool)
    used[np.where(FE >= 0, FE, ~FE).ravel()] = True
    blk = scene.edges
    for i in np.nonzero(~used[:len(blk.ids)])[0].tolist():
        attrs = blk.attrs.get(i, ())
        if any(kw == "bare" for kw, _ in attrs):
            continue
        session.write_err(f"{filename}:{blk.lines[i]}: warning: edge {blk.ids[i]} has no "
                       f"facets and is not marked bare\n")


def scene_settings(session: SessionLike, scene):
    """Settings a datafile gives (scale, scale_limit, constraint_tolerance, total_time)."""
    for k in ("scale_limit", "constraint_tolerance", "integral_order_1d", "integral_order_2d"):
        if k in scene.values:
            session.settings[k] = scene.values[k]
    if "total_time" in scene.values:        # TOTAL_TIME: a dump goes on with its clock
        session.total_time = float(scene.values["total_time"])
    if "diffusion" in scene.values:            # DIFFUSION: the constant, and the toggle on
        session.settings["diffusion_coeff"] = float(scene.values["diffusion"])
        session.toggles["diffusion"] = 1
    if "scale" in scene.values:
        session.settings["scale"] = scene.values["scale"]
        if scene.values.get("scale_fixed"):
            session.toggles["_fixed_scale"] = 1      # SCALE x FIXED: the m command

# -- dump and load (commands) --------------------------------------------------


def init_view_matrix(session: SessionLike):
    """The graphics view matrix (exporters read it): the Evolver's initial
    view fits the bounding box into [-1, 1]^3."""
    s = session.surface
    d = s.sdim
    M = np.eye(d + 1)
    if s.nv:
        lo, hi = s.X.min(axis=0), s.X.max(axis=0)
        size = float(np.max(hi - lo))
        if size > 0:
            sc = 2.0 / size
            for k in range(d):
                M[k, k] = sc
                M[k, d] = -sc * (lo[k] + hi[k]) / 2
    session.arrays["view_matrix"] = M
    session.array_types["view_matrix"] = "real"

# -- output -----------------------------------------------------------------


# -- the commands -------------------------------------------------------------------
FAMILY = "files"


@register("read", usage='read "file.cmd"', statement="read",
          help="run a command file", family=FAMILY)
def _x_read(interp, node):
    if node[1] is None:
        raise UnsupportedError("read without a file name", "use read \"file\"")
    name = interp.value(node[1])
    if not isinstance(name, str):
        raise CommandError("read needs a file name in quotes (for example: read \"off.cmd\")")
    read_file(interp.session, name)


@register("exec", usage='exec "commands"', statement="exec",
          help="run a string (or string expression) as commands", family=FAMILY)
def _x_exec(interp, node):
    text = interp.value(node[1])
    if not isinstance(text, str):
        raise CommandError("exec needs a quoted string or string expression (for example: "
                           "exec sprintf \"print %d\", 3)")
    short = text if len(text) <= 60 else text[:57] + "..."
    interp.run_string(text, 'exec "' + short.replace("\n", " ") + '"')


@register("dump", usage='dump ["file"]', statement="dump",
          help="write the surface as a datafile", family=FAMILY)
def _x_dump(interp, node):
    name = None
    if node[1] is not None:
        name = interp.value(node[1])
        if not isinstance(name, str):
            raise CommandError("dump needs a file name in quotes (for example: "
                               "dump \"out.fe\")")
    interp.session.dump(name)


@register("load", "addload", "replace_load", usage='load "file.fe" (addload, replace_load)',
          statement="load", help="load, add or replace a datafile", family=FAMILY)
def _x_load(interp, node):
    kw = node[1]
    name = interp.value(node[2])
    if not isinstance(name, str):
        raise CommandError(f"{kw} needs a datafile name in quotes (for example: "
                           f"{kw} \"cube.fe\")")
    if kw == "load":
        load_command(interp.session, name)
        raise Loaded()              # the Evolver: the current command ends
    elif kw == "addload":
        addload(interp.session, name)
    else:
        replace_load(interp.session, name)
