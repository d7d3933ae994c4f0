"""``t``, ``K`` and ``n`` in the string model (surface dimension 1).

The rules, measured on ``evolver-nox-d`` with small hand-written strings,
popstr.fe, slidestr.fe and 100grain.fe:

* ``n θ`` (notching): a vertex is *sharp* when its ``dihedral``, the angle
  ``2 asin(|Σ u_e| / 2)`` (``u_e`` the unit vectors from the vertex along
  its edges, clamped to π; 0 with fewer than two edges; manual, vertex
  ``dihedral``), exceeds θ; every edge with a sharp end is bisected once
  (FIXED edges and vertices included), as ``r`` bisects, in edge order.
  REF reports "Edges refined: N" (nothing when N is 0) and sets
  ``notch_count`` and ``refine_count`` to N.
* ``K θ``: each facet (edge chain), in id order, is looked at as the
  triangle of the lengths of its first three edges (cyclically for a chain
  of two: a, b, a), angles by the law of cosines clipped to [0, π] (so
  lengths that make no triangle give a zero angle) and three equal sides
  counting as skinny, as in the soapfilm model; a skinny facet none of
  whose three edges was chosen already has the longest of them (the last of
  equal ones) bisected.  The edges are bisected in the order chosen (so
  the new elements are numbered that way).  A wrapped torus edge that the
  choosing facet runs backwards gets its midpoint as seen from its head
  while its halves take the wraps as seen from the tail (REF's placement:
  the halves then cross the cell, 100grain.fe).  Chains of one edge are
  refused: REF's choice there depends on its internal facet-edge lists.
* ``t L``: the edges are visited in id order and each that is shorter
  than ``L`` when it is visited and not FIXED is deleted, merging its head
  into its tail when the head may be eliminated (not FIXED, on exactly the
  edge's constraints), else the tail into the head; when both could go,
  the kept vertex moves to the edge's midpoint (projected back onto its
  constraints at the end).  The eliminated vertex's other edges move to
  the kept one (on a torus their wraps take the deleted edge's wrap, so
  every edge keeps its vector; a vertex moved to a midpoint outside the
  unit cell stays there, as in REF), parallel edges are not merged, and
  the deleted edge leaves the facet chains (a closed chain losing its first
  edge, run backwards, then starts at the edge before it).  A facet left
  with two sides is dissolved: the side at the eliminated vertex takes the
  other's place in the other chains; the kept vertex does not move when
  that facet had three edges when ``t`` began, nor when the deleted edge is
  such a merged side.  A deletion that would leave an edge from a vertex
  to itself leaves it there: REF deletes such an edge at its own visit,
  counted, the vertex unchanged, and a facet left without edges goes (one
  made after its own visit, and a facet left with two sides that do not
  meet at the eliminated vertex, are refused by name).  Matches REF on
  100grain.fe up to ``t 0.06``; from 0.07 on REF's cascades of dissolved
  cells differ (not measured further).
"""
from __future__ import annotations

import copy

import numpy as np

from ..constraints import project_to_constraints
from ..errors import UnsupportedError
from ..geometry.kernels import edge_vectors
from ..methods.attributes import string_vertex_dihedral
from .shrink import subset


# ---------------------------------------------------------------------------
# n: notching


def dihedral(s) -> np.ndarray:
    """(nv,) REF's vertex ``dihedral`` in the string model
    (:func:`pyevolver.methods.attributes.string_vertex_dihedral`)."""
    return string_vertex_dihedral(s, s.evaluate())


def notch_edges(s, angle: float) -> np.ndarray:
    """Indices of the edges ``n angle`` bisects: those with a sharp end."""
    sharp = dihedral(s) > angle
    return np.nonzero(sharp[s.E[:, 0]] | sharp[s.E[:, 1]])[0]


# ---------------------------------------------------------------------------
# K: skinny "triangles"


def _law_of_cosines_skinny(a, b, c, angle):
    """Whether the triangle of side lengths a, b, c has an angle below
    ``angle`` (law of cosines, clipped; three equal sides count)."""
    with np.errstate(all="ignore"):
        cos = [(a * a + c * c - b * b) / (2 * a * c), (a * a + b * b - c * c) / (2 * a * b),
               (b * b + c * c - a * a) / (2 * b * c)]
    ang = np.arccos(np.clip(np.array(cos, float), -1.0, 1.0))
    small = bool(np.nanmin(ang) < angle) if not np.all(np.isnan(ang)) else False
    return small or a == b == c


def skinny_edges(s, angle: float, shifts: list | None = None) -> list[int]:
    """Edges ``K angle`` bisects in the string model, in the order REF
    bisects them: facets in id order, each bisection done before the next
    facet is looked at (so a later facet sees the halves, and an edge can be
    bisected twice: its tail half keeps its index, the head half is the
    next new edge)."""
    nsf = len(s.sf_ptr) - 1
    n = np.diff(s.sf_ptr)
    if np.any(n == 1):
        f = int(s.ids("facet")[np.nonzero(n == 1)[0][0]])
        raise UnsupportedError("K on a facet of one edge in the string model",
                               f"facet {f}: the Evolver's choice there depends on its "
                               "internal lists")
    X = [row for row in s.X.copy()]
    E = [list(map(int, r)) for r in s.E]
    shift = s.wrap_shift()
    W = [row for row in shift] if shift is not None else None
    chains = [list(map(int, s.sf_enc[s.sf_ptr[f]:s.sf_ptr[f + 1]])) for f in range(nsf)]

    def vec(e):
        d = X[E[e][1]] - X[E[e][0]]
        return d + W[e] if W is not None else d

    chosen: list[int] = []
    for f in np.argsort(s.ids("facet"), kind="stable").tolist():
        ch = chains[f]
        if not ch:
            continue
        side = [(x if x >= 0 else ~x) for x in (ch[k % len(ch)] for k in range(3))]
        a, b, c = (float(np.linalg.norm(vec(e))) for e in side)
        if not _law_of_cosines_skinny(a, b, c, angle):
            continue
        L = [a, b, c]
        k = 2 - int(np.argmax(L[::-1]))
        e = side[k]
        # REF: a wrapped edge its facet runs backwards gets its midpoint as
        # seen from the head, the wraps as seen from the tail (measured)
        back = (ch[k % len(ch)] < 0) and W is not None and bool(np.any(W[e] != 0))
        shift = W[e].copy() if back else None
        chosen.append(e)
        if shifts is not None:
            shifts.append(shift)
        # bisect e: the tail half keeps e, the head half is a new edge
        d = vec(e)
        m = len(X)
        X.append(X[E[e][0]] + 0.5 * d - (shift if back else 0.0))
        h = len(E)
        E.append([m, E[e][1]])
        E[e] = [E[e][0], m]
        if W is not None:
            W.append(W[e])
            W[e] = np.zeros(3)
        for g, cg in enumerate(chains):
            if e in cg or ~e in cg:
                out = []
                for x in cg:
                    out.extend([x, h] if x == e else [~h, x] if x == ~e else [x])
                chains[g] = out
    return chosen


def split_in_order(s, edges, split, shifts=None):
    """Bisect ``edges`` one after the other in the given order (an index
    may repeat, or be a half made earlier) with ``split(surface, R)``,
    which bisects distinct existing edges ``R`` numbering the new elements
    in R's order; consecutive runs of such edges go in one call.
    ``shifts[k]`` (None or a vector) is taken off the k-th new vertex right
    after its run, before a later bisection can use it."""
    run: list[int] = []
    done = 0
    for e in list(edges) + [None]:
        if e is None or e in run or e >= s.ne:
            if run:
                nv = s.nv
                s = split(s, np.array(run, np.int64))
                for k in range(len(run)):
                    sh = shifts[done + k] if shifts is not None else None
                    if sh is not None:
                        s.X[nv + k] -= sh
                done += len(run)
                run = []
        if e is not None:
            run.append(int(e))
    return s


# ---------------------------------------------------------------------------
# t: edge weeding


def _signatures(s):
    cids = sorted(set(s.vcon) | set(s.econ))
    vsig = np.zeros((s.nv, len(cids) + 1), np.int64)
    esig = np.zeros((s.ne, len(cids) + 1), np.int64)
    for k, c in enumerate(cids):
        if c in s.vcon:
            vsig[:, k] = s.vcon[c]
        if c in s.econ:
            esig[:, k] = s.econ[c] != 0
    if "boundary" in s.vattr:
        vsig[:, -1] = s.vattr["boundary"]
    if "boundary" in s.eattr:
        esig[:, -1] = s.eattr["boundary"]
    return vsig, esig


def _facets_at(chains, e, E, ealive, v):
    """The facets through edge ``e`` (``v`` None) or through the live edges
    at vertex ``v``."""
    if v is None:
        return {f for f, ch in enumerate(chains) if e in ch or ~e in ch}
    at = set(np.nonzero(ealive & (E == v).any(axis=1))[0].tolist())
    return {f for f, ch in enumerate(chains)
            if any((x if x >= 0 else ~x) in at for x in ch)}


def _drop_edge(ch, e, E):
    """Chain ``ch`` without edge ``e``; REF starts a closed chain that loses
    its first edge, run backwards, at the edge before it (100grain.fe ``t``)."""
    if not ch or ch[0] != ~e:
        return [x for x in ch if (x if x >= 0 else ~x) != e]
    rest = [x for x in ch if (x if x >= 0 else ~x) != e]
    if len(rest) >= 2 and _closes(rest, E, -1, -1):
        rest = rest[-1:] + rest[:-1]
    return rest


def _closes(enc, E, elim, keep):
    """Whether the chain ``enc`` closes on itself once ``elim`` is ``keep``."""
    def end(x, k):
        v = int(E[x, k] if x >= 0 else E[~x, 1 - k])
        return keep if v == elim else v
    return end(enc[0], 0) == end(enc[-1], 1)


def delete_short_edges(s, length: float):
    """``t length`` on a string: ``(new surface, number deleted)``."""
    X = s.X.copy()
    E = s.E.copy()
    wrap = s.eattr["wrap"].copy() if ("wrap" in s.eattr and s.periods is not None) else None
    P = s.periods if wrap is not None else None
    vfixed, efixed = s.vattr["fixed"], s.eattr["fixed"]
    vsig, esig = _signatures(s)
    valive = np.ones(s.nv, bool)
    ealive = np.ones(s.ne, bool)
    chains = [list(s.sf_enc[s.sf_ptr[f]:s.sf_ptr[f + 1]]) for f in range(len(s.sf_ptr) - 1)]
    n0 = np.diff(s.sf_ptr)
    merged: set = set()          # sides that took a dissolved facet's other side
    rings = "ring_time" in s.eattr
    if rings:
        times = s.eattr["ring_time"].copy()
        head = s.vattr["ring_head"].copy()
        clock = int(times.max()) + 1 if len(times) else 0
    moved = []
    count = 0
    eids = s.ids("edge")

    def vec(e):
        d = X[E[e, 1]] - X[E[e, 0]]
        return d + wrap[e] @ P if wrap is not None else d

    def ok(v, e):
        return (not vfixed[v]) and np.array_equal(vsig[v], esig[e])

    for e in np.argsort(eids, kind="stable").tolist():
        if not ealive[e] or efixed[e]:
            continue
        d = vec(e)
        if not np.linalg.norm(d) < length:
            continue
        a, b = int(E[e, 0]), int(E[e, 1])
        if a == b:
            # REF (measured, tests/remesh/test_string_mesh.py): an edge from a
            # vertex to itself left by earlier merges goes at its visit, counted,
            # the vertex unchanged; a facet left without edges goes
            ealive[e] = False
            chains = [_drop_edge(ch, e, E) for ch in chains]
            if rings and head[a] == e:
                at = np.nonzero(ealive & (E == a).any(axis=1))[0]
                tt = np.where(E[at, 0] == a, times[at, 0], times[at, 1])
                head[a] = at[np.argmax(tt)] if len(at) else -1
            count += 1
            continue
        go_a, go_b = ok(a, e), ok(b, e)
        if go_a and go_b and any(chains):
            # REF (as autopop): an end on a facet the edge is not on stays and
            # absorbs the other (100grain.fe g 5; t 0.01: a junction keeps its
            # place, the chain vertex goes), where the edge is on two facets
            # (string_dissolve4.fe: an edge of one cell, the junction moves)
            fe_ = _facets_at(chains, e, E, ealive, None)
            sa, sb = _facets_at(chains, e, E, ealive, a), _facets_at(chains, e, E, ealive, b)
            stay_a, stay_b = not sa <= fe_, not sb <= fe_
            if len(fe_) >= 2 and stay_a != stay_b:
                go_a, go_b = not stay_a, not stay_b
        if go_b:
            keep, elim, sgn = a, b, 1.0       # elim = keep + the edge vector
        elif go_a:
            keep, elim, sgn = b, a, -1.0
        else:
            continue
        others = np.nonzero(ealive & (E == elim).any(axis=1))[0]
        others = others[others != e]
        collapse = []        # (facet, surviving side, removed side): REF dissolves it
        for f, ch in enumerate(chains):
            rest = [x for x in ch if (x if x >= 0 else ~x) != e]
            if len(rest) < len(ch) and len(rest) <= 2 and (
                    not rest or _closes(rest, E, elim, keep)):
                if len(rest) == 2:
                    r = [x if x >= 0 else ~x for x in rest]
                    at_elim = [bool((E[x] == elim).any()) for x in r]
                    if at_elim[0] != at_elim[1]:
                        collapse.append((f, r[0] if at_elim[0] else r[1],
                                         r[1] if at_elim[0] else r[0]))
                        continue
                if len(rest) < 2:
                    continue        # a loop edge left: deleted at its own visit
                raise UnsupportedError(
                    "t leaving a facet of two sides not met at the eliminated vertex in the "
                    "string model",
                    f"deleting edge {int(eids[e])} closes facet {int(s.ids('facet')[f])} on two "
                    "sides; which side REF keeps there was not measured")
        shift = None
        # REF (measured): the kept vertex stays put when the facet dissolved
        # had three edges when t began, or when the edge is a side merged by
        # an earlier dissolve of this t; else it moves as usual
        if go_a and go_b and not any(n0[f] == 3 for f, _, _ in collapse) and e not in merged:
            if wrap is not None and np.any(wrap[e] != 0):
                # REF: a tail outside the unit cell ends at the midpoint as
                # seen from the head (measured: tests/remesh/test_string_mesh.py)
                lat = np.linalg.solve(P.T, X[keep])
                nz = wrap[e] != 0
                if np.any((lat[nz] < 0) | (lat[nz] >= 1)):
                    shift = wrap[e].copy()
            if shift is None:
                X[keep] = X[keep] + 0.5 * d
            else:
                X[keep] = 0.5 * ((X[keep] - shift @ P) + X[elim])
            moved.append(keep)
        for o in others.tolist():
            for end in (0, 1):
                if E[o, end] == elim:
                    E[o, end] = keep
                    if wrap is not None:
                        # tail end moved: the edge starts sgn*w_e later
                        wrap[o] += (sgn if end == 0 else -sgn) * wrap[e]
                    if rings:
                        times[o, end] = clock
                        clock += 1
        if shift is not None:           # the kept vertex moved by -shift periods
            at = np.nonzero(ealive & (E == keep).any(axis=1))[0]
            at = at[at != e]
            wrap[at[E[at, 0] == keep]] -= shift
            wrap[at[E[at, 1] == keep]] += shift
        ealive[e] = False
        valive[elim] = False
        for f, keep_side, gone in collapse:
            # REF (measured): a facet left with two sides goes; the side at the
            # eliminated vertex stays and takes the other's place in the chains;
            # the kept vertex does not move
            same = E[gone, 0] == E[keep_side, 0]
            if wrap is not None and not np.array_equal(
                    wrap[gone], wrap[keep_side] if same else -wrap[keep_side]):
                raise UnsupportedError(
                    "t leaving a facet of two edges around the torus in the string model",
                    f"deleting edge {int(eids[e])}, facet {int(s.ids('facet')[f])}")
            new_fwd = keep_side if same else ~keep_side
            chains[f] = []
            chains = [[new_fwd if x == gone else ~new_fwd if x == ~gone else x for x in ch]
                      for ch in chains]
            ealive[gone] = False
            merged.add(int(keep_side))
            if rings:
                for v in E[gone].tolist():
                    if head[v] == gone:
                        at = np.nonzero(ealive & (E == v).any(axis=1))[0]
                        tt = np.where(E[at, 0] == v, times[at, 0], times[at, 1])
                        head[v] = at[np.argmax(tt)] if len(at) else -1
        chains = [_drop_edge(ch, e, E) for ch in chains]
        if rings and head[keep] == e:
            at = np.nonzero(ealive & (E == keep).any(axis=1))[0]
            if len(at):
                tt = np.where(E[at, 0] == keep, times[at, 0], times[at, 1])
                head[keep] = at[np.argmax(tt)]
            else:
                head[keep] = -1
        count += 1
    if not count:
        return s, 0
    if np.any(ealive & (E[:, 0] == E[:, 1])):
        loop = int(eids[np.nonzero(ealive & (E[:, 0] == E[:, 1]))[0][0]])
        raise UnsupportedError("t leaving an edge from a vertex to itself in the string model",
                               f"edge {loop} became one after its own visit; REF's handling "
                               "there was not measured")
    src = copy.copy(s)
    src.X = X
    src.eattr = dict(s.eattr)
    src.vattr = dict(s.vattr)
    if wrap is not None:
        src.eattr["wrap"] = wrap
    if rings:
        src.eattr["ring_time"] = times
        src.vattr["ring_head"] = head
    fkeep = np.array([len(ch) > 0 for ch in chains], bool)
    chains = [ch for ch in chains if ch]
    if not ealive.any():
        raise UnsupportedError("t deleting every edge of the string model",
                               "no surface would be left")
    keep_e = int(np.nonzero(ealive)[0][0])
    t = subset(src, E, np.full((len(fkeep), 3), keep_e, np.int64), valive, ealive, fkeep)
    t.FE = np.zeros((0, 3), np.int64)
    new = np.cumsum(ealive) - 1
    lens = [len(ch) for ch in chains]
    enc = np.array([x for ch in chains for x in ch], np.int64)
    fwd = enc >= 0
    ei = new[np.where(fwd, enc, ~enc)]
    t.sf_enc = np.where(fwd, ei, ~ei).astype(np.int64)
    t.sf_ptr = np.concatenate([[0], np.cumsum(lens)]).astype(np.int64)
    if rings:
        h = t.vattr["ring_head"]
        t.vattr["ring_head"] = np.where(h >= 0, new[np.maximum(h, 0)], -1)
    if moved:
        vnew = np.cumsum(valive) - 1
        mv = np.unique(np.array(moved, np.int64))
        mv = vnew[mv[valive[mv]]]
        if t.vcon and len(mv):
            project_to_constraints(t, mv)
    return t, count
