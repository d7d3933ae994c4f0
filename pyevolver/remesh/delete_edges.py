"""Edge deletion: ``t`` (tiny edges), ``w`` (weed small triangles), ``delete``.

Spec §8.4 and the manual's ``t`` / ``w`` / ``delete`` entries.  Deleting an
edge ``e = (a, b)`` merges one endpoint into the other.  The head is
eliminated if it may be, else the tail: a vertex may be eliminated when it
is not FIXED and lies on exactly the edge's constraints and boundary (so the
kept vertex carries at least as many).  When the kept vertex could have been
eliminated too, it moves to the edge's midpoint (projected back onto the
edge's constraints), as the Evolver shrinks the edge to zero length;
otherwise it stays where it is.  The
facets on ``e`` disappear, and in each of them the side at the eliminated
vertex merges into the side at the kept one (the merged edge keeps the
id and attributes of the side at the eliminated vertex, unless only the
other is FIXED or constrained).  A deletion is refused (the edge is
skipped) when the edge is FIXED or neither endpoint may be eliminated.
A common neighbour of the endpoints outside the
facets on ``e`` makes two more edges merge; facets left sharing all three
edges with another ("pillows") are removed in pairs with their then bare
edges and isolated vertices, as the Evolver does (checked on mound.fe with
two short edges: same counts, ids and coordinates).

Edges are visited one at a time in the given order (edge id order for
``t``), so that each deletion sees the surface the previous ones left; the
per-deletion work is vectorized over the arrays.
"""
from __future__ import annotations

import heapq

import numpy as np

from ..constraints import project_to_constraints
from ..errors import UnsupportedError
from ..geometry.kernels import edge_index, gram_facet_areas
from ..methods import metric as MT
from ..model.groups import group_of
from . import group_delete as GD
from .shrink import subset


def _dec(x):
    return x if x >= 0 else ~x


class _Deleter:
    def __init__(self, s):
        self.s = s
        # the torus model: per-edge period shifts, kept up to date as ends merge
        self.P = s.periods
        self.W = s.eattr["wrap"].copy() if s.periods is not None else None
        # a symmetry group (model.groups): per-edge codes, composed as ends merge
        self.group = group_of(s)
        self.C = s.eattr["wrap_code"].copy() if self.group is not None else None
        self.X = s.X.copy()
        self.moved = []
        self.E = s.E.copy()
        self.FE = s.FE.copy()
        self.FEabs = np.where(self.FE >= 0, self.FE, ~self.FE)
        self.valive = np.ones(s.nv, bool)
        self.ealive = np.ones(s.ne, bool)
        self.falive = np.ones(s.nf, bool)
        self.vfixed = s.vattr["fixed"]
        self.efixed = s.eattr["fixed"]
        cids = sorted(set(s.vcon) | set(s.econ))
        self.vsig = np.zeros((s.nv, len(cids) + 1), np.int64)
        self.esig = np.zeros((s.ne, len(cids) + 1), np.int64)
        for k, c in enumerate(cids):
            if c in s.vcon:
                self.vsig[:, k] = s.vcon[c]
            if c in s.econ:
                self.esig[:, k] = s.econ[c] != 0
        if "boundary" in s.vattr:
            self.vsig[:, -1] = s.vattr["boundary"]
        if "boundary" in s.eattr:
            self.esig[:, -1] = s.eattr["boundary"]
        self.count = 0

    def vec(self, e):
        """Edge ``e``'s vector head - tail (across the torus wrap)."""
        a, b = self.E[e]
        if self.C is not None:
            return GD.edge_vector(self, e)
        d = self.X[b] - self.X[a]
        return d if self.W is None else d + self.W[e] @ self.P

    def length(self, e):
        if self.s.metric is not None:       # REF weeds by the metric's lengths
            a, b = self.E[e]
            return float(MT.segment_lengths(self.s, self.X[a], self.X[b])[0])
        return float(np.linalg.norm(self.vec(e)))

    def facets_of(self, e):
        return np.nonzero(self.falive & (self.FEabs == e).any(axis=1))[0]

    def edges_at(self, v):
        """Indices of the live edges with an end at vertex ``v``."""
        return np.nonzero(self.ealive & (self.E == v).any(axis=1))[0]

    def facets_at(self, v):
        """Indices of the live facets with a corner at vertex ``v``."""
        return np.nonzero(self.falive & np.isin(self.FEabs, self.edges_at(v)).any(axis=1))[0]

    def neighbours(self, v, shift=None):
        """``{(w, offset): edge}`` of the vertices joined to ``v``, with the
        period offset of that copy of ``w`` from ``v`` (plus ``shift``; the
        offsets are all zero outside the torus model)."""
        at = self.edges_at(v)
        out = {}
        for x in at.tolist():
            a, b = (int(y) for y in self.E[x])
            if self.C is not None:
                off = GD.offset(self, x, v, shift)
            elif self.W is None:
                off = ()
            else:
                off = self.W[x] if a == v else -self.W[x]
                off = tuple((off + shift).tolist()) if shift is not None else tuple(off.tolist())
            out[(b if a == v else a, off)] = x
        return out

    def _eliminable(self, v, e):
        return (not self.vfixed[v]) and np.array_equal(self.vsig[v], self.esig[e])

    def delete(self, e, reverse=False):
        """Try to delete edge ``e``; True when it was deleted.  ``reverse``
        takes the edge against its orientation (``w`` deletes the edge as
        its facet runs along it)."""
        if not self.ealive[e] or self.efixed[e]:
            return False
        a, b = (int(x) for x in self.E[e])
        if reverse:
            a, b = b, a
        if a == b:
            return False
        if self._eliminable(b, e):
            keep, elim = a, b
        elif self._eliminable(a, e):
            keep, elim = b, a
        else:
            return False
        if self.C is not None and GD.parallel_edge(self, e, a, b):
            return False
        merges = []          # (facet, side at elim, side at keep, third vertex)
        for f in self.facets_of(e):
            sides = [int(x) for x in self.FEabs[f] if x != e]
            if len(sides) != 2:
                return False
            ends = [tuple(self.E[x]) for x in sides]
            if elim in ends[0]:
                eb, ea = sides
            else:
                ea, eb = sides
            c = [v for v in self.E[eb] if v != elim][0]
            merges.append((f, *self._survivor(eb, ea), int(c)))
        # the offset (in periods) of the eliminated vertex from the kept one
        delta = None
        if self.C is not None:
            delta = GD.delta(self, e, keep)
        elif self.W is not None:
            delta = self.W[e].copy() if int(self.E[e, 0]) == keep else -self.W[e]
        # a common neighbour outside those facets: its two edges become one
        nk, ne_ = self.neighbours(keep), self.neighbours(elim, delta)
        done = {x for m in merges for x in m[1:3]}
        for key in sorted(set(nk) & set(ne_)):
            eb, ea = ne_[key], nk[key]
            if eb in done or ea in done:
                continue
            merges.append((None, *self._survivor(eb, ea), key[0]))
        E, FE = self.E, self.FE
        head = int(E[e, 1])
        if self.C is not None:
            GD.carry(self, elim, delta)
        elif delta is not None:
            self._inside = self._in_cell(np.array([keep, elim]))
            self.W[E[:, 0] == elim] += delta
            self.W[E[:, 1] == elim] -= delta
            self.X[elim] = self.X[elim] + delta @ self.P    # its copy next to keep
        E[E == elim] = keep
        for f, eb, ea, c in merges:
            # the two sides now join the same vertices; eb is kept, ea dropped
            same = tuple(E[ea]) == tuple(E[eb])
            fwd, bwd = FE == ea, FE == ~ea
            FE[fwd] = eb if same else ~eb
            FE[bwd] = ~eb if same else eb
            self.FEabs[fwd | bwd] = eb
            self.ealive[ea] = False
            if f is not None:
                self.falive[f] = False
        if self._eliminable(keep, e) and self.vsig[keep, -1] == 0:
            # both ends as free as the edge: the edge shrinks to its midpoint
            # (not on a parametric boundary, where the kept vertex stays put)
            self.X[keep] = 0.5 * (self.X[keep] + self.X[elim])
            self.moved.append(keep)
            if self.W is not None and self._frame_at_elim(keep, elim, head, delta):
                self._shift(keep, -delta)
        self.valive[elim] = False
        self.ealive[e] = False
        self._drop_pillows(keep)
        self.count += 1
        return True

    def _in_cell(self, v):
        c = np.linalg.solve(self.P.T, self.X[v].T).T
        return np.all((c > -1e-9) & (c < 1 + 1e-9), axis=1)

    def _frame_at_elim(self, keep, elim, head, delta):
        """Whether the merged vertex takes the eliminated vertex's copy of
        the torus: REF puts the midpoint in the frame of the edge's tail when
        the tail lies in the unit cell, else of the head when that does
        (measured on twointor.fe ``r; g 5; t 0.15``)."""
        if not delta.any() or self.s.symmetry_group is not None:
            return False        # (SYMMETRY_GROUP "torus": the kept vertex's frame, as REF)
        k_in, e_in = self._inside
        tail_in, head_in = (k_in, e_in) if head == elim else (e_in, k_in)
        frame = head if (not tail_in and head_in) else (elim if head == keep else keep)
        return frame == elim

    def _shift(self, v, s):
        """Move vertex ``v`` by the periods ``s`` (the same point of the
        torus): its edges' wraps follow."""
        self.X[v] = self.X[v] + s @ self.P
        self.W[self.ealive & (self.E[:, 0] == v)] += s
        self.W[self.ealive & (self.E[:, 1] == v)] -= s

    def _survivor(self, eb, ea):
        """``(kept, dropped)`` of two sides that merge: the Evolver keeps the
        one from the eliminated vertex (``eb``), unless only the other is
        FIXED or on constraints or a boundary (measured on column.fe,
        ``g 5; t 0.1``: a free spoke merging into a fixed boundary edge
        leaves the boundary edge)."""
        def held(x):
            return bool(self.efixed[x]) or bool(self.esig[x].any())
        if held(ea) and not held(eb):
            return ea, eb
        if not held(eb) and len(self.facets_of(ea)) > len(self.facets_of(eb)):
            return ea, eb
        return eb, ea

    def _drop_pillows(self, v):
        """Facets at ``v`` that now share all three edges come in pairs (a
        flat "pillow"): both go, then their edges left without facets and
        vertices left without edges (the Evolver's cleanup after a merge)."""
        at = self.facets_at(v)
        if len(at) < 2:
            return
        keys = np.sort(self.FEabs[at], axis=1)
        _, inv, cnt = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
        dead = at[cnt[inv.ravel()] >= 2]
        if not len(dead):
            return
        self.falive[dead] = False
        edges = np.unique(self.FEabs[dead])
        still = np.isin(edges, self.FEabs[self.falive])
        gone = edges[~still]
        self.ealive[gone] = False
        verts = np.unique(self.E[gone])
        used = np.isin(verts, self.E[self.ealive])
        self.valive[verts[~used]] = False

    def result(self):
        if not self.count:
            return self.s
        t = subset(self.s, self.E, self.FE, self.valive, self.ealive, self.falive)
        t.X = self.X[self.valive].copy()
        if self.W is not None:
            t.eattr["wrap"] = self.W[self.ealive].copy()
        if self.C is not None:
            t.eattr["wrap_code"] = self.C[self.ealive].copy()
        moved = np.unique(np.array(self.moved, np.int64))
        moved = moved[self.valive[moved]] if len(moved) else moved
        if len(moved):
            new = np.cumsum(self.valive) - 1
            project_to_constraints(t, new[moved])
        return t


def _in_id_order(first, visit):
    """Visit ids in increasing order, starting from ``first``; ``visit(i)``
    returns ids to visit as well (those not above ``i`` were passed already,
    as in the Evolver's single pass over its element list)."""
    heap = sorted({int(i) for i in first})
    last = -1
    while heap:
        i = heapq.heappop(heap)
        if i == last:
            continue
        last = i
        for j in visit(i):
            if j > i:
                heapq.heappush(heap, int(j))


def _edge_vectors(s):
    group = group_of(s)
    if group is not None:
        return GD.edge_vectors(s, group)
    D = s.X[s.E[:, 1]] - s.X[s.E[:, 0]]
    return D if s.periods is None else D + s.eattr["wrap"] @ s.periods


def delete_short_edges(s, length):
    """``t length``: visit the edges in id order and delete each that is
    shorter than ``length`` when it is visited (as the Evolver's ``delete
    edges where length < L``: an edge shortened by an earlier merge counts).

    Returns ``(new surface, number deleted)``.
    """
    d = _Deleter(s)
    L = np.linalg.norm(_edge_vectors(s), axis=1) if s.metric is None else \
        MT.segment_lengths(s, s.X[s.E[:, 0]], s.X[s.E[:, 1]])

    def visit(e):
        if not d.ealive[e] or d.length(e) >= length or not d.delete(e) or not d.moved:
            return ()
        # edges at the moved vertex may now be short
        return [x for x in d.edges_at(d.moved[-1]).tolist() if d.length(x) < length]
    _in_id_order(np.nonzero(L < length)[0], visit)
    return d.result(), d.count


def weed_small_facets(s, area):
    """``w area``: for each facet of area below ``area`` (id order), delete
    its shortest deletable edge (edges tried shortest first).

    Returns ``(new surface, number of facets weeded)``.
    """
    if s.metric is not None:
        F = s.F
        A = MT.triangle_areas(s, s.X[F[:, 0]], s.X[F[:, 1]], s.X[F[:, 2]])
    else:
        D = _edge_vectors(s)
        idx, sgn = edge_index(s.FE)
        A = gram_facet_areas(np.stack([D[idx[:, 0]] * sgn[:, 0, None],
                                       D[idx[:, 1]] * sgn[:, 1, None]], 1))
    return _weed(s, np.nonzero(A < area)[0], area)


def _facet_area(d, f):
    if d.s.metric is not None:
        P = d.X[[d.E[_dec(x)][0] if x >= 0 else d.E[_dec(x)][1] for x in d.FE[f]]]
        return float(MT.triangle_areas(d.s, P[0], P[1], P[2])[0])
    sides = [d.vec(_dec(x)) * (1 if x >= 0 else -1) for x in d.FE[f][:2]]
    return float(gram_facet_areas(np.stack(sides)[None])[0])


def _weed(s, facets, area):
    """Visit ``facets`` in id order (with ``area``: also facets that a merge
    made smaller than ``area``, and only while they still are)."""
    if group_of(s) is not None:
        raise UnsupportedError(f'weeding or deleting facets in SYMMETRY_GROUP '
                               f'"{s.symmetry_group}" (REF\'s choice of facets after a '
                               f'merge is not the one the areas across the wrapped sides '
                               f'give: xyz.fe, `w 0.03`)')
    d = _Deleter(s)
    weeded = [0]

    def visit(f):
        if not d.falive[f] or (area is not None and _facet_area(d, f) >= area):
            return ()
        for x in sorted((int(x) for x in d.FE[f]), key=lambda x: d.length(_dec(x))):
            if d.delete(_dec(x), reverse=x < 0):
                weeded[0] += 1
                if area is None or not d.moved:
                    return ()
                return [g for g in d.facets_at(d.moved[-1]).tolist()
                        if _facet_area(d, g) < area]
        return ()
    _in_id_order(facets, visit)
    return d.result(), weeded[0]


def delete_facets(s, facets):
    """``delete facets``: for each listed facet, its shortest deletable side
    goes (as in ``w``); returns ``(new surface, number of facets)``."""
    return _weed(s, facets, None)


def delete_edges(s, edges):
    """``delete edges``: try each listed edge in order; returns
    ``(new surface, number deleted)``."""
    d = _Deleter(s)
    for e in edges:
        d.delete(int(e))
    return d.result(), d.count
