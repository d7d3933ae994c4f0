"""Commands refused by name in a symmetry group other than the torus
(pyevolver.model.groups): those whose mesh operations or second
derivatives would need the group elements and do not know them yet.

``g`` (constraints, the iteration toggles, fixed body volumes and
pressures), ``r``, ``u``, ``V``, ``rawv``, ``rawestv`` (not next to an axial
point), ``j``, the listings, ``dump``, ``print`` / ``printf`` (``wrap_compose``,
``wrap_inverse``, the ``wrap`` edge attribute) and the settings work; the
rest below is refused as '`t` in SYMMETRY_GROUP "rotate" ...'.
"""
from __future__ import annotations

import re

from ..errors import UnsupportedError
from ..model.groups import group_of

#: words and letters, with why
WORDS = {
    **{w: "a mesh operation whose new edges would need the group elements"
       for w in ("o", "n", "O", "notch")},
    **{w: "weeding facets: REF's choice of facets after a merge is not the one the areas "
          "across the wrapped sides give (measured on xyz.fe, `w 0.03`)"
       for w in ("w", "areaweed")},
    **{w: "the quadratic and Lagrange models" for w in ("M", "quadratic", "lagrange")},
}
#: statements (parse-tree tags) with why
STATEMENTS = {
    "pop": "popping (the new elements would need the group elements)",
}


#: quarter_turn: REF's products add the second z power modulo 4 (its
#: facets with z powers are "not consistent", WARNING 2000); `g` and `U`
#: match it (its forces leave out the corners with nonzero codes:
#: methods.group_geometry.quarter_turn_pullback), the rest below not yet
_QT_MESH = ("after `r` REF places three of the refined corner facets from their third "
            "edge (its areas there differ), and its `u`, `V` move and swap by rules not "
            "measured at the inconsistent facets")
QUARTER_TURN = {
    **{w: _QT_MESH for w in ("r", "u", "V", "rawv", "rawestv", "K", "l", "edge_divide", "t",
                             "edgeweed")},
    **{w: "REF's Hessian at its inconsistent facets was not measured"
       for w in ("hessian", "hessian_seek", "saddle", "ritz", "lanczos", "eigenprobe", "newton",
                 "bfgs", "optimise", "optimize")},
    "j": "jiggling (pyevolver's random numbers are not REF's anyway)",
}
QUARTER_TURN_STATEMENTS = {"refine": _QT_MESH, "delete": _QT_MESH}


def check(session, raw: str, statement: bool = False) -> None:
    """Refuse ``raw`` (a word or a statement tag) by name when the session's
    surface is in a group of pyevolver.model.groups and the command is not
    group-aware."""
    s = session.surface
    if s is None or group_of(s) is None:
        return
    table = STATEMENTS if statement else WORDS
    key = raw if len(raw) == 1 else raw.lower()
    if re.fullmatch(r"g\d+", key):
        key = "g"
    why = table.get(key)
    axial = "axial_point" in s.vattr and s.vattr["axial_point"].any()
    if why is None and key in ("V", "rawv", "rawestv") and not statement and axial:
        why = "vertex averaging next to an axial point, whose moves REF takes by rules " \
              "not measured"
    if why is None and axial and key in (("refine", "delete") if statement
                                         else ("K", "l", "edge_divide", "t", "edgeweed")):
        why = "bisecting or deleting edges next to an axial point: REF orders and places " \
              "the new elements there by rules not measured"
    if why is None and s.symmetry_group == "quarter_turn":
        why = (QUARTER_TURN_STATEMENTS if statement else QUARTER_TURN).get(key)
    if why is not None:
        name = key.rstrip("_")
        raise UnsupportedError(f'`{name}` in SYMMETRY_GROUP "{s.symmetry_group}" ({why})')
