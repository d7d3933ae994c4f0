"""Edge deletion (``t``, ``delete edges``) in a symmetry group other than
the torus (pyevolver.model.groups): the edges' codes as ends merge.

Deleting edge ``e`` from the kept vertex ``k`` to the eliminated one ``x``
(``delta``: the code of ``x`` seen from ``k``, the edge's code or its
inverse) moves ``x`` to its copy next to ``k``, ``g_delta(x)``: an edge
``x -> w`` with code ``c`` becomes ``k -> w`` with ``wrap_compose(delta,
c)``, an edge ``w -> x`` becomes ``w -> k`` with ``wrap_compose(c,
wrap_inverse(delta))``; the merged vertex stays in the kept vertex's frame
(as REF's SYMMETRY_GROUP "torus").  Used by remesh.delete_edges._Deleter.
"""
from __future__ import annotations

import numpy as np

from .group_refine import edge_vectors  # noqa: F401  (re-exported)


def _map(group, code):
    A, b = group.affine(np.array([code], np.int64))
    return A[0], b[0]


def edge_vector(d, e) -> np.ndarray:
    """``g(x_head) - x_tail`` of edge ``e`` of the deleter ``d``."""
    a, b = d.E[e]
    A, t = _map(d.group, int(d.C[e]))
    return A @ d.X[b] + t - d.X[a]


def offset(d, x, v, shift=None) -> tuple:
    """The code of edge ``x``'s other end seen from its end ``v`` (composed
    after ``shift``, a code, when given), as a neighbour key."""
    g = d.group
    c = int(d.C[x]) if int(d.E[x, 0]) == v else int(g.inverse(np.array([d.C[x]]))[0])
    if shift is not None:
        c = int(g.compose(np.array([shift]), np.array([c]))[0])
    return (c,)


def delta(d, e, keep) -> int:
    """The code of the eliminated end of ``e`` seen from ``keep``."""
    c = int(d.C[e])
    return c if int(d.E[e, 0]) == keep else int(d.group.inverse(np.array([c]))[0])


def carry(d, elim, delta_) -> None:
    """Move ``elim`` to its copy next to the kept vertex; its edges' codes
    follow."""
    g = d.group
    A, t = _map(g, delta_)
    d.X[elim] = A @ d.X[elim] + t
    live = d.ealive
    tail = np.nonzero(live & (d.E[:, 0] == elim))[0]
    head = np.nonzero(live & (d.E[:, 1] == elim))[0]
    if len(tail):
        d.C[tail] = g.compose(np.full(len(tail), delta_), d.C[tail])
    if len(head):
        inv = g.inverse(np.array([delta_]))[0]
        d.C[head] = g.compose(d.C[head], np.full(len(head), inv))


def parallel_edge(d, e, a, b) -> bool:
    """Whether another live edge joins ``a`` and ``b`` (another copy of one
    across the group): REF leaves ``e`` then (measured on a tube closed by
    the rotate group, rotate_body.fe: ``delete edge[23]; delete edge[47]``)."""
    ends = d.E
    same = ((ends[:, 0] == a) & (ends[:, 1] == b)) | ((ends[:, 0] == b) & (ends[:, 1] == a))
    same &= d.ealive
    same[e] = False
    return bool(same.any())
