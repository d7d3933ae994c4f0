"""Run a named study: ``pyevolver study phase [options]``.

``phase`` is the discrete vesicle phase study (:mod:`pyevolver.studies.phase_study`):
the prolate, oblate and stomatocyte branches of the discrete bending energy at
``c0 = 0`` swept in the reduced volume, their stability and transitions,
written as ``phase.csv``, ``transitions.csv`` and a figure.
"""
from __future__ import annotations

from ...studies import phase_study

#: study name -> its module (with ``add_args(parser)`` and ``run_args(args)``)
STUDIES = {"phase": phase_study}


def add_args(parser):
    sub = parser.add_subparsers(dest="study", required=True, metavar="STUDY")
    for name, mod in STUDIES.items():
        p = sub.add_parser(name, help=mod.__doc__.split("\n")[0],
                           description=mod.__doc__.split("\n")[0])
        mod.add_args(p)
        p.set_defaults(_module=mod)


def run(args):
    """Returns the exit code (1 when a point did not converge)."""
    return args._module.run_args(args)
