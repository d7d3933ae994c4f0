"""The subcommands of ``pyevolver`` besides running a datafile:
``pyevolver convert IN OUT``, ``pyevolver show FILE.fe -o shape.png`` and
``pyevolver sweep SPEC.toml`` and
``pyevolver study NAME``.  One module each, with ``add_args(parser)``
and ``run(args)`` returning the exit code."""
from __future__ import annotations

import argparse
import importlib
import sys

from ...errors import PyEvolverError

#: subcommand -> module (under pyevolver.cli.tools) and one-line help
SUBCOMMANDS = {
    "convert": ("convert", "convert a surface between .fe and meshio formats"),
    "show": ("show", "render a datafile's surface to an image, headless"),
    "sweep": ("sweep", "run a datafile over a grid of parameter values"),
    "study": ("study", "run a named study (phase: the discrete vesicle phase diagram)"),
}


def main(argv):
    """Run ``pyevolver NAME ...`` for a subcommand NAME; returns the exit code."""
    name = argv[0]
    mod = importlib.import_module(f".{SUBCOMMANDS[name][0]}", __name__)
    parser = argparse.ArgumentParser(prog=f"pyevolver {name}",
                                     description=mod.__doc__.split("\n\n")[0])
    mod.add_args(parser)
    args = parser.parse_args(argv[1:])
    try:
        return mod.run(args)
    except PyEvolverError as exc:
        sys.stderr.write(f"{exc}\n")
        return 1
    except (ValueError, OSError) as exc:     # bad options the tool found itself, unreadable files
        sys.stderr.write(f"pyevolver {name}: {exc}\n")
        return 1
