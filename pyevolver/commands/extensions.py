"""pyevolver's own commands, which the Evolver does not have, registered by
name: ``export``, ``snapshot``, ``movie`` and ``plot_history``.

A registered command runs as ``name "arg"`` or ``name("arg", ...)``; a
procedure or command of the user's with the same name wins, so Evolver
scripts that define their own ``export`` keep working.  Handlers get the
session and the list of evaluated arguments::

    from pyevolver.commands.extensions import register_command

    @register_command("hello", 'hello "name"', max_args=1)
    def hello(session, args):
        session.write(f"hello {args[0]}\\n")

They go into the one registry of commands (:mod:`pyevolver.commands.registry`).
"""
from __future__ import annotations

from typing import Callable

from ..errors import CommandError
from . import registry
from .registry import Command


def _bare(interp, raw, arg):
    """``name`` or ``name expr``: the extension with its one argument."""
    registry.call(interp.session, raw.lower(), [] if arg is None else [interp.value(arg)])


def register_command(name: str, usage: str, max_args: int = 1) -> Callable:
    """Decorator: register ``fn(session, args)`` as the command ``name``."""
    def deco(fn):
        registry.add(Command((name.lower(),), _bare, usage, usage, "extensions",
                             call=fn, max_args=max_args))
        return fn
    return deco


def run_command(session, name: str, args: list) -> None:
    """Run the registered command ``name`` with evaluated ``args``."""
    registry.call(session, name, args)


def _usage(name):
    return registry.COMMANDS[name].usage


def _strings(name, usage, args):
    """Arguments that must be non-empty strings, the first (a file name) required."""
    if not args or not isinstance(args[0], str) or not args[0]:
        raise CommandError(f"{name} needs a file name in quotes (usage: {usage})")
    for a in args[1:]:
        if not isinstance(a, str):
            raise CommandError(f"{name}: the arguments are strings in quotes (usage: {usage})")
    return args


@register_command("export", 'export "out.vtu" (vtu, ply, obj, stl, off, xdmf, ...)')
def _export(session, args):
    (path,) = _strings("export", _usage("export"), args)
    fmt = session.export(path)
    session.write(f"Exported to {path} ({fmt}).\n")


@register_command("snapshot", 'snapshot "shape.png" or snapshot("shape.png", "area")',
                  max_args=2)
def _snapshot(session, args):
    path, *field = _strings("snapshot", _usage("snapshot"), args)
    session.snapshot(path, field=field[0] if field else "auto")
    session.write(f"Snapshot written to {path}.\n")


@register_command("plot_history", 'plot_history "history.png"')
def _plot_history(session, args):
    (path,) = _strings("plot_history", _usage("plot_history"), args)
    session.plot_history(path)
    session.write(f"Energy history written to {path}.\n")


@register_command("movie", 'movie("run.gif", steps, every) or movie("run.gif", steps, every, '
                           '"area") (.gif, .mp4 with ffmpeg)', max_args=4)
def _movie(session, args):
    usage = _usage("movie")
    if len(args) < 3 or not isinstance(args[0], str) or not args[0] or \
            any(isinstance(a, str) or float(a) != int(a) for a in args[1:3]) or \
            (len(args) == 4 and not isinstance(args[3], str)):
        raise CommandError(f"movie needs a file name in quotes, the number of steps and the "
                           f"steps between pictures (usage: {usage})")
    steps, every = int(args[1]), int(args[2])
    if steps < 0 or every < 1:
        raise CommandError(f"movie: steps must be >= 0 and every >= 1 (usage: {usage})")
    session.movie(args[0], steps, every, field=args[3] if len(args) == 4 else "auto")
    session.write(f"Movie written to {args[0]} ({steps // every + 1} frames).\n")
