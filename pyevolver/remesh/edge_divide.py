"""Bisect chosen edges (``refine edges where ...``, ``l``; spec §8)."""
from __future__ import annotations

import numpy as np

from ..model.groups import group_of
from ..model.records import torus_lift_shifts
from .refine import split_edges


def edge_divide(s, edges, choosers=None):
    """Bisect ``edges`` (indices) of surface ``s``, ignoring NO_REFINE.

    Each facet on a bisected edge is cut from the midpoint to its opposite
    corner.  Edges are taken in increasing index order; when two chosen
    edges share a facet, the second is bisected after the first split (in
    a later round), as the Evolver does one edge after the other.
    ``choosers`` (``K``: per edge the facet that chose it): the edges are
    taken (and their new elements numbered) in the order given instead,
    and the midpoint placed from the chooser's side (:func:`pyevolver.remesh.refine.split_edges`).

    Returns
    -------
    (Surface, int)
        The new surface and the number of edges bisected.
    """
    todo = np.asarray(edges, np.int64)
    ordered = choosers is not None
    if ordered:
        by = np.asarray(choosers, np.int64)
        first = np.sort(np.unique(todo, return_index=True)[1])
        todo, by = todo[first], by[first]
    else:
        todo = np.unique(todo)
    count = len(todo)
    moved, shift = [], []
    while len(todo):
        idx = s.topology()[0]
        if ordered:
            # the longest prefix of the order whose edges share no facet:
            # bisecting them at once is bisecting them one after the other
            n = _free_prefix(idx, todo, s.ne)
            now, now_by = todo[:n], by[:n]
            todo, by = todo[n:], by[n:]
            wv = s.wrap_shift()
            group = group_of(s)
            if wv is not None or group is not None:
                idx_, sgn_, _ = s.topology()
                back = (sgn_[now_by] * (idx_[now_by] == now[:, None])).sum(axis=1) < 0
                moved.append(s.nv + np.nonzero(back)[0])
                if group is not None:       # the codes: the head's frame is g⁻¹'s
                    shift.append(s.eattr["wrap_code"][now[back]])
                else:
                    shift.append(-wv[now[back]])
        else:
            sel = np.zeros(s.ne, bool)
            sel[todo] = True
            # each facet is claimed by its lowest-numbered chosen side
            cand = np.where(sel[idx], idx, np.iinfo(np.int64).max)
            claim = cand.min(axis=1)
            ok = np.ones(s.ne, bool)
            bad = sel[idx] & (idx != claim[:, None])
            ok[idx[bad]] = False
            now = todo[ok[todo]]
            todo = todo[~ok[todo]]
        mask = np.zeros(s.ne, bool)
        mask[now] = True
        s = split_edges(s, mask, one_by_one=True, order=now if ordered else None,
                        choosers=now_by if ordered else None)
    if moved and sum(len(m) for m in moved):
        # REF's K puts the midpoint at the start of the chooser's side plus
        # half the side: when the chooser runs along the edge backwards, in
        # the edge's head cell (the midpoint minus the edge's period shift),
        # while the new edges keep the wraps of a midpoint in the tail's
        # cell (measured on twointor.fe and a two-vertex torus sheet:
        # ``list vertices`` / ``list edges`` after ``K``; twointor.fe's area
        # jumps from 3.35 to 15.12 after ``K 0.2``).  The bodies' lifts
        # (which pair a body's facets at an edge by their angles there) are
        # taken before the move, on the untangled surface: the move keeps
        # the topology and the wraps, and REF's volumes are those.
        # In a symmetry group (pyevolver.model.groups) REF puts it alike in
        # the head's frame, g⁻¹(midpoint), the new edges' codes as for a
        # midpoint in the tail's frame (measured on rotate.fe: ``K 0.9``).
        s.X = s.X.copy()
        v = np.concatenate(moved)
        group = group_of(s)
        if group is not None:
            A, b = group.affine(np.concatenate(shift))
            s.X[v] = np.einsum("nji,nj->ni", A, s.X[v] - b)       # (A orthogonal)
            return s, count
        if s.bodies.n:
            torus_lift_shifts(s)
        s.X[v] += np.concatenate(shift)
    return s, count


def _free_prefix(idx, order, ne):
    """Length of the longest prefix of ``order`` (edge indices) in which no
    two edges lie on one facet of ``idx`` (nf, 3)."""
    pos = np.full(ne, len(order))
    pos[order] = np.arange(len(order))
    p = np.sort(pos[idx], axis=1)               # per facet its chosen sides' places
    clash = p[:, 1] < len(order)                # two chosen sides: the later one waits
    return int(p[clash, 1].min()) if clash.any() else len(order)


def long_edges(s, length):
    """``l L``: indices of the edges longer than ``length``."""
    return np.nonzero(s.evaluate().edge_length > length)[0]


def skinny_edges(s, angle, choosers=False):
    """``K θ``: the longest edge of every facet whose smallest angle is below
    ``angle`` (radians), as edge indices.

    As evolver-nox-d does (measured on single triangles, sphere.fe and
    twointor.fe): facets are taken in id order and a facet one of whose
    sides was already chosen is passed over (the bisection has cut it); of
    equally long sides the last is the longest; and a facet with three
    exactly equal sides counts as skinny whatever ``θ`` (REF finds its
    smallest angle 0: the symmetric equilateral triangles of sphere.fe and
    twointor.fe's hexagons are cut by any ``K``).  The edges come in the
    order of the facets that chose them (REF numbers the new elements so).
    ``choosers``: also return, per edge, the facet that chose it.
    """
    if s.nf == 0:
        none = np.zeros(0, np.int64)
        return (none, none) if choosers else none
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
    chosen: list[int] = []
    by: list[int] = []
    seen: set[int] = set()
    for f in cand.tolist():                     # the skinny facets only
        if not seen.intersection(idx[f].tolist()):
            chosen.append(int(longest[f]))
            by.append(f)
            seen.add(chosen[-1])
    out = np.array(chosen, np.int64)
    return (out, np.array(by, np.int64)) if choosers else out
