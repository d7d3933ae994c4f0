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
    if group.name == "quarter_turn":
        _local_codes(group, W, oriented, FW, new_edges)
        return
    for eidx, f, p, q in new_edges:
        op = (off if p[0] == "c" else offm)[f, p[1]]
        oq = (off if q[0] == "c" else offm)[f, q[1]]
        W[eidx] = group.compose(group.inverse(op), oq)


def _local_codes(group, W, oriented, FW, new_edges) -> None:
    """quarter_turn: a new edge's code composed along the facet's rim from
    its start to its end the short way (corner i -> midpoint i -> corner
    i+1: the halves' codes, 0 on the tail's side), not through corner 0:
    REF's product there is not associative (the second z power taken
    modulo 4), and REF's codes after `r` are these (quarter_turn.fe:
    ``r; list edges``)."""
    zero = np.zeros_like(oriented)
    a = np.where(FW, zero, oriented)             # corner i -> midpoint i
    b = np.where(FW, oriented, zero)             # midpoint i -> corner i+1
    steps = np.stack([a[:, 0], b[:, 0], a[:, 1], b[:, 1], a[:, 2], b[:, 2]], 1)
    for eidx, f, p, q in new_edges:
        i = 2 * p[1] + (p[0] != "c")             # places on the rim: c0 m0 c1 m1 c2 m2
        j = 2 * q[1] + (q[0] != "c")
        fwd = (j - i) % 6
        lo, n = (i, fwd) if fwd <= 3 else (j, 6 - fwd)
        code = np.zeros(len(np.atleast_1d(f)), np.int64)
        st = steps[f]
        for k in range(n):
            code = group.compose(code, st[:, (lo + k) % 6])
        W[eidx] = code if fwd <= 3 else group.inverse(code)
