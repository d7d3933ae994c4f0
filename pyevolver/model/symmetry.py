"""Symmetry groups (``SYMMETRY_GROUP "name"``): the quotient-space domains.

The manual ("Symmetry groups and quotient spaces") lists the built-in groups;
an edge's group element is an integer, its ``wrap`` code.  pyevolver has the
``torus`` group: the translations by integer combinations of the periods
(the ``PERIODS`` of the datafile, the unit cube without them), its element
coded as one 6-bit field per coordinate, low bits for x, each a 5-bit two's
complement number (+1 is 1, -1 is 31: ``+x`` 1, ``-x`` 31, ``+y`` 64,
``-y`` 1984, ``+z`` 4096, ``-z`` 126976).  A surface in the torus group is
the torus model's (``Surface.periods`` and the per-edge integer shifts
``eattr["wrap"]``) with ``Surface.symmetry_group = "torus"``; what differs
from ``TORUS`` (REF's rules, measured on symtest.fe against twointor.fe):

* body volumes are the plain sums of the facets' contents, corners unwrapped
  from the facet's first vertex (REF: "for other symmetry groups ... the
  Euclidean volume calculation"), without the torus model's lift across
  the cell and its choice of the cell multiple;
* ``list edges`` and ``dump`` write ``wrap code`` instead of ``* + -``.

The other Euclidean groups (rotations, reflections, screw motions) are
``pyevolver.model.groups``; the hyperbolic ones are refused by name.
"""
from __future__ import annotations

import numpy as np

from ..geometry.kernels import edge_index

#: the built-in groups of the manual and of REF 2.70, with why pyevolver has
#: not got them (the torus group is supported)
GROUPS = {
    "torus": None,
    "rotate": None, "flip_rotate": None, "cubocta": None, "cubelat": None, "xyz": None,
    "central_symmetry": None, "screw_symmetry": None, "quarter_turn": None,  # model/groups.py
    "genus2": "a hyperbolic quotient in the Klein metric whose element encoding REF "
              "does not document",
    "dodecahedron": "a hyperbolic quotient in the Klein metric; the manual documents no "
                    "encoding",
}

_FIELD = 6


def refusal(name: str) -> str | None:
    """None when pyevolver has the group ``name``, else the refusal's text."""
    if name in GROUPS and GROUPS[name] is None:
        return None
    why = GROUPS.get(name, "not one of the Evolver's built-in groups")
    return f'SYMMETRY_GROUP "{name}" ({why})'


def decode_torus(codes: np.ndarray, sdim: int = 3) -> np.ndarray:
    """(n, 3) integer shifts of the torus group's codes ``(n,)``."""
    c = np.asarray(codes, dtype=np.int64)
    out = np.zeros((len(c), 3))
    for d in range(min(sdim, 3)):
        f = (c >> (_FIELD * d)) & 31
        out[:, d] = np.where(f >= 16, f - 32, f)
    return out


def encode_torus(wrap: np.ndarray) -> np.ndarray:
    """(n,) torus-group codes of the integer shifts ``wrap (n, 3)``."""
    w = np.rint(np.asarray(wrap)).astype(np.int64)
    code = np.zeros(len(w), np.int64)
    for d in range(w.shape[1]):
        code |= (w[:, d] & 31) << (_FIELD * d)
    return code


def declared(scene, surface, error) -> str | None:
    """The surface's group from the datafile's ``SYMMETRY_GROUP`` (None
    without one); ``error(message, line)`` builds the refusal of a group
    pyevolver has not got."""
    name = scene.symmetry_group
    if name is None:
        return None
    why = refusal(name)
    if why is None and (scene.torus or surface.string or surface.sdim != 3):
        why = f'SYMMETRY_GROUP "{name}" with TORUS, in the string model or in ' \
              f'{surface.sdim} dimensions'
    if why is None and name == "quarter_turn" and "quarter_turn_period" not in scene.parameters:
        raise error('SYMMETRY_GROUP "quarter_turn" needs the parameter quarter_turn_period '
                    '(REF: ERROR 4008)', scene.decl_lines.get("symmetry_group"))
    if why is not None:
        raise error(f"not supported in pyevolver: {why}", scene.decl_lines.get("symmetry_group"))
    return name


def torus_face_centers(s, big, starts, lengths, enc) -> None:
    """The torus model at load: the centre of each face of more than three
    edges (``big``, its loop ``enc[starts[k]:starts[k] + lengths[k]]``) is
    the mean of the rim unwrapped from its first vertex; the spokes (the
    last edges, in face order) get the wraps from rim to centre."""
    P = s.periods
    wrap = s.eattr["wrap"]
    nv0 = s.nv - len(big)
    ne_spoke = s.ne - int(lengths[big].sum())
    for j, k in enumerate(big):
        st, n = starts[k], lengths[k]
        loop = enc[st:st + n]
        idx, sgn = edge_index(loop)
        # unwrapped offsets (in periods) of rim vertices relative to the first
        offs = np.zeros((n, 3))
        for m in range(1, n):
            offs[m] = offs[m - 1] + wrap[idx[m - 1]] * sgn[m - 1]
        rim = np.where(sgn > 0, s.E[idx, 0], s.E[idx, 1])
        pts = s.X[rim] + offs @ P
        s.X[nv0 + j] = pts.mean(axis=0)
        for m in range(n):
            # spoke from rim m (at offset offs[m]) to centre (offset 0)
            wrap[ne_spoke + m] = -offs[m]
        ne_spoke += n


def group_face_check(s, big, starts, lengths, eidx, blk, error) -> None:
    """A face of more than three edges in a group of pyevolver.model.groups
    is split about the mean of its rim, which needs every rim edge unwrapped
    (code 0): refuse the others by name."""
    codes = s.eattr["wrap_code"]
    for k in big:
        if np.any(codes[eidx[starts[k]:starts[k] + lengths[k]]] != 0):
            raise error(f"not supported in pyevolver: a face of more than three edges with "
                        f'wrapped edges in SYMMETRY_GROUP "{s.symmetry_group}"', blk.lines[k])
