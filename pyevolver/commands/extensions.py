"""pyevolver's own commands, which the Evolver does not have, registered by
name: ``export``, ``snapshot`` and ``plot_history``.

A registered command runs as ``name "arg"`` or ``name("arg", ...)``; a
procedure or command of the user's with the same name wins, so Evolver
scripts that define their own ``export`` keep working.  Handlers get the
session and the list of evaluated arguments::

    from pyevolver.commands.extensions import register_command

    @register_command("hello", 'hello "name"', max_args=1)
    def hello(session, args):
        session.write(f"hello {args[0]}\\n")
"""
from __future__ import annotations

from ..errors import CommandError

#: name -> (handler(session, args), usage, max_args)
COMMANDS = {}


def register_command(name, usage, max_args=1):
    """Decorator: register ``fn(session, args)`` as the command ``name``."""
    def deco(fn):
        COMMANDS[name.lower()] = (fn, usage, max_args)
        return fn
    return deco


def run_command(session, name, args):
    """Run the registered command ``name`` with evaluated ``args``."""
    fn, usage, max_args = COMMANDS[name.lower()]
    if len(args) > max_args:
        raise CommandError(f"{name} takes at most {max_args} argument"
                           f"{'s' if max_args != 1 else ''} (usage: {usage})")
    fn(session, args)


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
    (path,) = _strings("export", COMMANDS["export"][1], args)
    fmt = session.export(path)
    session.write(f"Exported to {path} ({fmt}).\n")


@register_command("snapshot", 'snapshot "shape.png" or snapshot("shape.png", "area")',
                  max_args=2)
def _snapshot(session, args):
    path, *field = _strings("snapshot", COMMANDS["snapshot"][1], args)
    session.snapshot(path, field=field[0] if field else "mean_curvature")
    session.write(f"Snapshot written to {path}.\n")


@register_command("plot_history", 'plot_history "history.png"')
def _plot_history(session, args):
    (path,) = _strings("plot_history", COMMANDS["plot_history"][1], args)
    session.plot_history(path)
    session.write(f"Energy history written to {path}.\n")
