"""The string model: a one-dimensional surface (spec §3.2, §4, Tier 2).

The Evolver's ``STRING`` (or ``SURFACE_DIMENSION 1``) datafiles describe
curves: edges carry the energy (tension 1 unless given), and a *facet* is a
chain of edges, not necessarily closed, that exists to give a body its
"volume", the area of the facet (manual, "The string model").  Such files
are two-dimensional (``SPACE_DIMENSION 2``: slidestr.fe) when they have
bodies, or curves in space without facets (popstr.fe, knotty.fe).

pyevolver keeps the coordinates of a two-dimensional surface in the same
``(nv, 3)`` array as any other, with a z column that stays zero: no
energy or constraint of a two-dimensional file can depend on z, so no force
has a z component.

Facet area and gravity use one-dimensional divergence theorems over the
facet's edges, as REF does (the values below agree with ``evolver-nox-d``
to round-off on slidestr.fe and test files):

* area of the region left of a chain: ``A = Σ_e -∫ y dx``, per edge
  ``-(x_h - x_t)(y_t + y_h)/2`` (t, h: the edge's tail and head as the
  facet traverses it);
* gravity of a body of density ρ: ``G ρ ∬ y dA = Σ_e -G ρ ∫ y²/2 dx``, per
  edge ``-(x_h - x_t)(y_t² + y_t y_h + y_h²)/6``;
* constraint CONTENT and ENERGY integrands are single functions of the
  point, evaluated at the vertices on the constraint (manual, "Constraints");
  energy adds ``E(v)`` for every such vertex, content adds ``C(head) -
  C(tail)`` for each edge of a facet whose head or tail is on the
  constraint (so only the ends of an open chain count: the content is the
  integral along the constraint that closes the chain).  FIXED vertices
  count too (REF).

The facets are stored as one ragged array: ``s.sf_enc`` holds every
facet's edges in chain order (edge index ``e`` forwards, ``~e`` backwards)
and facet ``f`` is ``sf_enc[sf_ptr[f]:sf_ptr[f + 1]]``.
"""
from __future__ import annotations

import numpy as np

from ..errors import CommandError, UnsupportedError
from ..geometry.kernels import edge_vectors

# quantity methods that make sense without facets
STRING_METHODS = {"edge_length", "edge_tension", "edge_area", "vertex_scalar_integral",
                  "edge_scalar_integral", "edge_vector_integral", "harmonic_energy",
                  "metric_edge_length"}


# ---------------------------------------------------------------------------
# facets as chains


def chain_points(s, t=None):
    """``(Pt, Ph)`` (m, 3): the tail and head points of every (facet, edge)
    incidence as the facet traverses them.  On a torus the chain is unwrapped
    from the tail of its first edge (edge vectors with their period shifts
    added up along the chain), so areas and gravity see one connected curve."""
    owner, e, sgn, tail, head = facet_entries(s)
    if s.periods is None:
        return s.X[tail], s.X[head]
    ev = t.edge_vec if t is not None else edge_vectors(s.X, s.E, s.wrap_shift())
    d = ev[e] * sgn[:, None]
    if not len(d):
        return s.X[tail], s.X[head]
    cs = np.cumsum(d, axis=0) - d               # sum of the edges before each one
    start = s.sf_ptr[:-1]
    Pt = s.X[tail[start]][owner] + cs - cs[start][owner]
    return Pt, Pt + d


def facet_entries(s):
    """``(owner, edge, sign, tail, head)`` for every (facet, edge) incidence,
    arrays of shape (m,): the facet, the edge index, +1/-1 for the direction
    of traversal, and the vertices the facet goes from and to."""
    enc = s.sf_enc
    owner = np.repeat(np.arange(len(s.sf_ptr) - 1), np.diff(s.sf_ptr))
    fwd = enc >= 0
    e = np.where(fwd, enc, ~enc)
    tail = np.where(fwd, s.E[e, 0], s.E[e, 1])
    head = np.where(fwd, s.E[e, 1], s.E[e, 0])
    return owner, e, np.where(fwd, 1.0, -1.0), tail, head


def chain(s, f):
    """Encoded edges of facet ``f`` in chain order."""
    return s.sf_enc[s.sf_ptr[f]:s.sf_ptr[f + 1]]


def chain_vertices(s, f, sign=1):
    """Vertices of facet ``f`` along its chain: n + 1 for an open chain of n
    edges, n for a closed one (manual, facet ``vertices``); ``sign`` -1
    walks it backwards."""
    enc = chain(s, f)
    if sign < 0:
        enc = ~enc[::-1]
    fwd = enc >= 0
    e = np.where(fwd, enc, ~enc)
    tails = np.where(fwd, s.E[e, 0], s.E[e, 1])
    last = s.E[e[-1], 1] if fwd[-1] else s.E[e[-1], 0]
    vs = list(tails)
    if last != tails[0]:
        vs.append(last)
    return [int(v) for v in vs]


def facets_of_edge(s, e):
    """``[(facet, sign)]`` of the facets whose chain contains edge ``e``."""
    owner, ee, sgn, _, _ = facet_entries(s)
    hit = np.nonzero(ee == e)[0]
    return [(int(owner[k]), int(sgn[k])) for k in hit]


def facetedge_count(s):
    """REF's facet-edge count: one per (facet, edge) incidence, and one for
    each edge on no facet."""
    on = np.bincount(facet_entries(s)[1], minlength=s.ne)
    return int(np.maximum(on, 1).sum())




def init_rings(s):
    """REF keeps the edges at a vertex in a ring with a first edge; a new
    edge goes in right after the first, and when the first goes the next one
    takes its place, so ``vv.edge`` lists the first edge, then the others
    newest first.  ``eattr["ring_time"]`` (ne, 2) holds when each end of an
    edge joined its vertex's ring, ``vattr["ring_head"]`` each vertex's
    first edge.  On load edges join in datafile order."""
    ne, nv = s.ne, s.nv
    s.eattr["ring_time"] = np.repeat(np.arange(ne, dtype=np.int64)[:, None], 2, axis=1)
    head = np.full(nv, ne, np.int64)
    np.minimum.at(head, s.E[:, 0], np.arange(ne))
    np.minimum.at(head, s.E[:, 1], np.arange(ne))
    s.vattr["ring_head"] = np.where(head == ne, -1, head)


def vertex_edges(s, v):
    """Edges at vertex ``v`` in REF's order: ``[(edge, +1 if v is its tail
    else -1)]``."""
    ends = np.nonzero(s.E == v)
    e, end = ends[0], ends[1]
    t = s.eattr["ring_time"][e, end]
    head = s.vattr["ring_head"][v]
    key = np.where(e == head, np.iinfo(np.int64).max, t)
    order = np.argsort(-key, kind="stable")
    return [(int(e[k]), 1 if end[k] == 0 else -1) for k in order]


def refuse(what):
    """Commands that are not available in the string model."""
    raise UnsupportedError(f"{what} in the string model")


def check_no_facets_needed(s, what: str) -> None:
    """Refuse ``what`` (a command needing facets) in the string model."""
    if s.string:
        raise CommandError(f"{what} needs facets: not available in the string model")


