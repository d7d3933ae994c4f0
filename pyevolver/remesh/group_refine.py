"""`r` in a symmetry group other than the torus (pyevolver.model.groups):
the new edges' group elements.

A refined edge's tail half keeps the tail's frame (code 0) and its head half
the whole element; the new vertex is the midpoint of ``x_tail`` and
``g(x_head)``.  Inside a facet, corner 0 has the identity, corner 1 the
element of its first oriented edge ``c0`` (``wrap_inverse`` of the code for a
reversed edge) and corner 2 ``wrap_compose(c0, c1)``; a midpoint has the
element of its edge's tail corner (the third edge's tail reached around
the facet: the element of all three edges, not the identity at an axial
point).  A new edge from p to q gets
``wrap_compose(wrap_inverse(e_p), e_q)`` (REF's codes after `r`, checked
against its `list edges`).
"""
from __future__ import annotations

import numpy as np

from ..methods.group_geometry import element_maps


def edge_vectors(s, group) -> np.ndarray:
    """(ne, 3) ``g(x_head) - x_tail`` of every edge."""
    A, b = element_maps(s, group)
    return np.einsum("eij,ej->ei", A, s.X[s.E[:, 1]]) + b - s.X[s.E[:, 0]]


def new_edge_codes(s, t, group, R, I, FW, new_edges) -> None:
    """Set ``t.eattr["wrap_code"]`` of the refined edges' tail halves ``R``
    and of the facets' new edges ``new_edges`` ((edges, facets, (kind, j),
    (kind, j)) as refine builds them; ``I``, ``FW`` the facets' rotated edge
    indices and orientations)."""
    W = t.eattr["wrap_code"]
    W[R] = 0
    codes = s.eattr["wrap_code"][I]
    oriented = np.where(FW, codes, group.inverse(codes))
    nf = len(I)
    off = np.zeros((nf, 4), np.int64)
    off[:, 1] = oriented[:, 0]
    off[:, 2] = group.compose(oriented[:, 0], oriented[:, 1])
    # back at corner 0 after the third edge: not the identity around an
    # axial point (its facets' edges need not close up)
    off[:, 3] = group.compose(off[:, 2], oriented[:, 2])
    offm = np.where(FW, off[:, :3], off[:, 1:])
    off = off[:, :3]
    for eidx, f, p, q in new_edges:
        op = (off if p[0] == "c" else offm)[f, p[1]]
        oq = (off if q[0] == "c" else offm)[f, q[1]]
        W[eidx] = group.compose(group.inverse(op), oq)
