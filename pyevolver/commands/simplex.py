"""The commands in the simplex model (:mod:`pyevolver.model.simplex`): REF's
answers where REF refuses, reports nothing done, or does what pyevolver
refuses by name.

The manual ("Simplex model"): "No changing of surface topology or
combinatorics is allowed except global refining with the r command".
Measured on evolver-nox-d with simplex3.fe after ``r`` (REF crashes on ``g``
before ``r`` when run with ``-p1``; without it it evolves as pyevolver):

========================  ====================================================
``t L``                   "Deleted edges: 0", nothing changes (there are no edges)
``w A``                   ERROR 1339 "Can only do area weed on soapfilm model."
``n A`` / ``notch``       ERROR 1224 "Notching not implemented for simplex representation."
``V``                     ERROR 1380 "Vertex averaging mode V not implemented ..."
``o`` / ``O``             "Vertex (Edge) popping not implemented ...", no error
``hessian``               ERROR 1606 "Pressures invalid ..." before any ``g``,
                          ERROR 1454 "Use Lagrange model for simplex volumes." after
                          (with a body; REF crashes on a surface without one)
``u``, ``K``, ``l``       REF reports changes that break the surface (``u``: "Edges
                          switched: 3" and 43 facets from 40; ``l 0.5``: 444 facets,
                          area 1 -> 1.45; ``K``: "New edges: 40", nothing changes):
                          refused by name
``rawv``, ``rawestv``     REF moves the vertices (area 1 -> 0.086): refused
``delete``, ``j``, ...    refused by name
``refine edges``          nothing (there are no edges), as REF
========================  ====================================================
"""
from __future__ import annotations

import math

from ..errors import CommandError, UnsupportedError
from . import elements

_ERRORS = {
    "w": "Can only do area weed on soapfilm model.",
    "areaweed": "Can only do area weed on soapfilm model.",
    "n": "Notching not implemented for simplex representation.",
    "notch": "Notching not implemented for simplex representation.",
    "V": "Vertex averaging mode V not implemented for simplex model. Use rawv.",
}
_NOTES = {
    "o": "Vertex popping not implemented for simplex representation.\n",
    "O": "Edge popping not implemented for simplex representation.\n",
    "t": "Deleted edges: 0\n",
    "edgeweed": "Deleted edges: 0\n",
}
_REFUSED = {
    "u": "REF 2.70 switches 'edges' of a simplex surface and changes its facet count",
    "equiangulate": "REF 2.70 switches 'edges' of a simplex surface and changes its facet count",
    "K": "REF 2.70 reports new edges and changes nothing",
    "l": "REF 2.70's edge division breaks a simplex surface",
    "edge_divide": "REF 2.70's edge division breaks a simplex surface",
    "rawv": "REF 2.70's averaging of simplex vertices was not reproduced",
    "rawestv": "REF 2.70's averaging of simplex vertices was not reproduced",
    "j": "REF's jiggle amplitude without edges was not measured",
    "jiggle": "REF's jiggle amplitude without edges was not measured",
    "bfgs": "pyevolver's BFGS works on triangulated surfaces",
}
_HESSIAN_WORDS = {"newton", "ritz", "saddle", "eigenprobe", "lanczos", "hessian_menu"}
_MOTION = {
    "diffusion": "diffusion between bodies is not implemented for simplex facets",
    "jiggle": "REF's jiggle amplitude without edges was not measured",
    "approximate_curvature": "the mass matrix of simplex facets is not implemented",
}
#: statements with REF's answer in the simplex model
STATEMENTS = {"delete", "edgeswap", "equiangulate", "refine"}


def answer(interp, raw: str) -> bool:
    """REF's answer to the command word ``raw`` on a simplex surface: True
    when it is given here (the command is done), False to run the command
    as usual.  Raises CommandError where REF fails and UnsupportedError
    where pyevolver refuses."""
    s = interp.session
    word = raw if len(raw) == 1 else raw.lower()
    if word in _ERRORS:
        raise CommandError(_ERRORS[word])
    if word in _NOTES:
        s.note(_NOTES[word])
        return True
    if word in _REFUSED:
        raise UnsupportedError(f"{raw} in the simplex model", _REFUSED[word])
    if word in ("hessian", "hessian_seek"):
        hessian_answer(s)
    if word in _HESSIAN_WORDS:
        raise UnsupportedError(f"{raw} in the simplex model", "it needs the Hessian, which "
                               "REF 2.70 does not have for simplex volumes")
    if word == "g":
        for opt, why in _MOTION.items():
            if s.toggles.get(opt):
                raise UnsupportedError(f"g with {opt} in the simplex model", why)
        b = s.surface.bodies
        if s.toggles.get("area_normalization") and b.n and not all(map(math.isnan, b.target)):
            raise UnsupportedError(
                "g with area_normalization and fixed volumes in the simplex model",
                "REF's restoring of the volumes there was not reproduced (simplex3.fe r; g 3: "
                "0.7812 against 0.7763; the velocities agree)")
    return False


def hessian_answer(session) -> None:
    """REF's hessian in the simplex model: an error (volumes), a crash (none)."""
    b = session.surface.bodies
    if b.n:
        fixed = any(not math.isnan(v) for v in b.target)
        if fixed and not session.iterator.pressures_valid:
            raise CommandError("Pressures invalid. Do regular iteration before Hessian "
                               "to set pressures.")
        raise CommandError("Use Lagrange model for simplex volumes.")
    raise UnsupportedError("hessian in the simplex model",
                           "REF 2.70 crashes there (simplex surfaces without volumes)")


def statement(interp, node) -> bool:
    """REF's answer to a statement (``delete``, ``refine``, ...) on a simplex
    surface: True when done here (``refine edges``: nothing, there are no
    edges), else refused by name."""
    kind = node[0]
    if kind == "refine":
        els = elements.generate(interp.session, node[1], interp.env)
        if not els:
            return True
    raise UnsupportedError(f"{kind} in the simplex model",
                           "the manual: no changes of the combinatorics but r")
