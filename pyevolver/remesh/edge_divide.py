"""Bisect chosen edges (``refine edges where ...``, ``l``; spec §8)."""
from __future__ import annotations

import numpy as np

from .refine import split_edges


def edge_divide(s, edges, head_frame=()):
    """Bisect ``edges`` (indices) of surface ``s``, ignoring NO_REFINE.

    Each facet on a bisected edge is cut from the midpoint to its opposite
    corner.  Edges are taken in increasing index order; when two chosen
    edges share a facet, the second is bisected after the first split (in
    a later round), as the Evolver does one edge after the other.

    ``head_frame`` (``K`` in the torus model): edges whose midpoint is put
    at the head's side of the cell (``head - vector/2``) while the new edges
    keep the wraps of the tail-side midpoint, as REF's ``K`` does with an
    edge its skinny facet runs against (measured on twointor.fe and
    symtest.fe, where REF's energy after ``K`` jumps, and on a sheared
    wavy sheet, where the facet runs along the wrapping edge and the
    midpoint is right; ``l`` and ``refine edges`` put it right).

    Returns
    -------
    (Surface, int)
        The new surface and the number of edges bisected.
    """
    todo = np.unique(np.asarray(edges, np.int64))
    count = len(todo)
    while len(todo):
        idx = s.topology()[0]
        sel = np.zeros(s.ne, bool)
        sel[todo] = True
        # each facet is claimed by its lowest-numbered chosen side
        cand = np.where(sel[idx], idx, np.iinfo(np.int64).max)
        claim = cand.min(axis=1)
        ok = np.ones(s.ne, bool)
        bad = sel[idx] & (idx != claim[:, None])
        ok[idx[bad]] = False
        now = todo[ok[todo]]
        mask = np.zeros(s.ne, bool)
        mask[now] = True
        nv0, shift = s.nv, None
        if len(head_frame) and s.periods is not None:
            now_s = np.sort(now)
            shift = (s.eattr["wrap"][now_s] @ s.periods) * np.isin(now_s, head_frame)[:, None]
        s = split_edges(s, mask, one_by_one=True)
        if shift is not None:
            s.X[nv0:nv0 + len(shift)] -= shift
        todo = todo[~ok[todo]]
    return s, count


def long_edges(s, length):
    """``l L``: indices of the edges longer than ``length``."""
    return np.nonzero(s.evaluate().edge_length > length)[0]


def skinny_edges(s, angle, against=None):
    """``K θ``: the longest edge of every facet whose smallest angle is below
    ``angle`` (radians), as edge indices.

    As evolver-nox-d does (measured on single triangles, sphere.fe and
    twointor.fe): facets are taken in id order and a facet one of whose
    sides was already chosen is passed over (the bisection has cut it); of
    equally long sides the last is the longest; and a facet with three
    exactly equal sides counts as skinny whatever ``θ`` (REF finds its
    smallest angle 0: the symmetric equilateral triangles of sphere.fe and
    twointor.fe's hexagons are cut by any ``K``).
    """
    if s.nf == 0:
        return np.zeros(0, np.int64)
    t = s.evaluate()
    idx = s.topology()[0]                       # side k of facet joins corner k, k+1
    L = t.edge_length[idx]                      # (nf, 3)
    # the angle at corner k lies opposite side k+1 (mod 3): law of cosines
    a, b, c = L[:, 0], L[:, 1], L[:, 2]
    with np.errstate(all="ignore"):
        cos = np.stack([(a * a + c * c - b * b) / (2 * a * c),
                        (a * a + b * b - c * c) / (2 * a * b),
                        (b * b + c * c - a * a) / (2 * b * c)], axis=1)
    ang = np.arccos(np.clip(cos, -1.0, 1.0))
    skinny = (np.nanmin(ang, axis=1) < angle) | ((a == b) & (b == c))
    longest = idx[np.arange(s.nf), 2 - np.argmax(L[:, ::-1], axis=1)]
    cand = np.nonzero(skinny)[0]
    cand = cand[np.argsort(s.ids("facet")[cand], kind="stable")]
    chosen = set()
    col = 2 - np.argmax(L[:, ::-1], axis=1)
    sgn = s.topology()[1]
    for f in cand.tolist():                     # the skinny facets only
        if not chosen.intersection(idx[f].tolist()):
            chosen.add(int(longest[f]))
            if against is not None and sgn[f, col[f]] < 0:
                against.append(int(longest[f]))     # (the facet runs against it)
    return np.array(sorted(chosen), np.int64)
