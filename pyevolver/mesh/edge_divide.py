"""Bisect chosen edges (``refine edges where ...``, ``l``; spec §8)."""
from __future__ import annotations

import numpy as np

from .refine import split_edges


def edge_divide(s, edges):
    """Bisect ``edges`` (indices) of surface ``s``, ignoring NO_REFINE.

    Each facet on a bisected edge is cut from the midpoint to its opposite
    corner.  Edges are taken in increasing index order; when two chosen
    edges share a facet, the second is bisected after the first split (in
    a later round), as the Evolver does one edge after the other.

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
        s = split_edges(s, mask)
        todo = todo[~ok[todo]]
    return s, count
