"""File commands: ``load``, ``addload``, ``replace_load`` (datafiles) and
``read`` (command files, found in the current directory or EVOLVERPATH).
The session is duck-typed: ``surface``, ``variables``, ``run``,
``_install``, ``recalc``.
"""
from __future__ import annotations

import copy
import os

from ..datafile.reader import read_datafile
from ..errors import CommandError, PyEvolverError, UnsupportedError
from ..limits import MAX_NESTING
from ..model.surface import build_surface
from ..remesh.merge import append_surface
from .registry import register
from .values import Loaded, Quit


def _read_new(session, cmd, name):
    if not os.path.isfile(name):
        if os.path.exists(name):
            raise CommandError(f"{cmd}: '{name}' is not a regular file (a directory, "
                               f"device or pipe)")
        raise CommandError(f"{cmd}: cannot find datafile '{name}'")
    scene = read_datafile(name)
    return scene, build_surface(scene)


def load_command(session, name):
    """``load "file"``: a fresh start on another datafile (variables,
    commands and toggles forgotten; its read section runs)."""
    scene, surface = _read_new(session, "load", name)
    out, err, limit = session.out, session.err, session.time_limit
    session.__init__(out, err)
    session.time_limit = limit
    session._install(name, scene, surface, True)


def replace_load(session, name):
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
    session._scene_settings(scene)
    session.recalc()


def addload(session, name):
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


def read_file(session, name):
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
