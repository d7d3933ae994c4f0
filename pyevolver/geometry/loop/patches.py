"""Topology for Loop patches: half-edges, validation, the control points of
every triangle, and one global Loop subdivision step.

Half-edge ``h = 3 f + k`` of facet ``f`` runs from ``F[f, k]`` to
``F[f, (k + 1) % 3]``; facets are counter-clockwise seen from outside.
Rotating counter-clockwise about the tail of ``h``: ``rot(h) = twin(prev(h))``.

The control points of a triangle ``(a, b, c)`` whose corner ``a`` has valence
``N`` (``b`` and ``c`` valence 6) are the ``N + 6`` vertices of its 1-ring, in
the order used by :mod:`.stencils`::

    a, q_0 = b, q_1 = c, q_2, ..., q_{N-1}, r_1, r_2, y, s_1, s_2

with ``q_i`` the ring of ``a`` counter-clockwise from ``b``; ``b``'s ring
counter-clockwise from ``c`` is ``c, a, q_{N-1}, r_1, r_2, y`` and ``c``'s is
``a, b, y, s_1, s_2, q_2``.  For ``N = 6`` these are the 12 control points of
a regular (box-spline) patch.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ...errors import UnsupportedError

MAX_VALENCE = 12


def loop_beta(N):
    """Loop's vertex weight β(N) = (5/8 − (3/8 + cos(2π/N)/4)²)/N (Loop 1987):
    a vertex of valence N moves to (1 − Nβ) v + β Σ neighbours."""
    N = np.asarray(N, float)
    return (0.625 - (0.375 + 0.25 * np.cos(2 * np.pi / N)) ** 2) / N


def limit_weights(N):
    """Weights ``(centre, each neighbour)`` of the limit position of a vertex
    of valence N: the left eigenvector of Loop's vertex/edge rules for
    eigenvalue 1, ``centre = 1/(1 + 8Nβ/3)``, ``neighbour = 8β centre/3``."""
    b = loop_beta(N)
    c = 1.0 / (1.0 + 8.0 * N * b / 3.0)
    return c, 8.0 * b * c / 3.0


class HalfEdges:
    """Half-edge arrays of a triangle mesh ``F (nf, 3)`` with ``nv`` vertices.

    ``tail, head, twin`` are (3 nf,); ``twin`` is −1 on a boundary.  An
    oriented edge used twice (non-manifold edge or inconsistent orientation)
    raises :class:`UnsupportedError`.
    """

    def __init__(self, F, nv):
        F = np.asarray(F, np.int64)
        self.F = F
        self.nv = int(nv)
        self.tail = F.ravel()
        self.head = np.roll(F, -1, axis=1).ravel()
        key = self.tail * self.nv + self.head
        order = np.argsort(key, kind="stable")
        skey = key[order]
        if len(skey) > 1 and np.any(skey[1:] == skey[:-1]):
            raise UnsupportedError(
                "Loop subdivision surfaces on this mesh",
                "an edge is used twice in the same direction: the surface is not an "
                "oriented 2-manifold (non-manifold edge or inconsistently oriented facets)")
        rkey = self.head * self.nv + self.tail
        pos = np.clip(np.searchsorted(skey, rkey), 0, max(len(skey) - 1, 0))
        found = skey[pos] == rkey if len(skey) else np.zeros(0, bool)
        self.twin = np.where(found, order[pos], -1)
        self.valence = np.bincount(self.tail, minlength=self.nv)

    @staticmethod
    def next(h):
        return h - h % 3 + (h + 1) % 3

    @staticmethod
    def prev(h):
        return h - h % 3 + (h + 2) % 3

    def rot(self, h):
        """The next outgoing half-edge counter-clockwise about ``tail[h]``."""
        return self.twin[self.prev(h)]

    def boundary_vertices(self):
        b = np.zeros(self.nv, bool)
        open_ = self.twin < 0
        b[self.tail[open_]] = True
        b[self.head[open_]] = True
        return b


def check_closed_manifold(he, what="Loop subdivision surfaces"):
    """Raise :class:`UnsupportedError` unless the mesh is a closed oriented
    2-manifold whose vertices have valence 3..12 (one fan per vertex)."""
    if len(he.F) == 0:
        raise UnsupportedError(what, "the surface has no facets")
    if np.any(he.twin < 0):
        n = int(np.count_nonzero(he.twin < 0))
        raise UnsupportedError(what, f"the control mesh must be closed: {n} boundary edges")
    used = np.bincount(he.F.ravel(), minlength=he.nv) > 0
    val = he.valence
    if np.any(val[used] > MAX_VALENCE):
        raise UnsupportedError(what, f"vertex valence {int(val.max())} > {MAX_VALENCE}")
    if np.any(val[used] < 3):
        raise UnsupportedError(what, "a vertex has valence < 3")
    # one fan per vertex: rotating about v from one outgoing half-edge must
    # visit all val(v) outgoing half-edges before returning
    vs = np.nonzero(used)[0]
    first = np.full(he.nv, -1, np.int64)
    first[he.tail[::-1]] = np.arange(len(he.tail))[::-1]
    h = first[vs]
    start = h.copy()
    for step in range(1, MAX_VALENCE + 1):
        h = he.rot(h)
        early = (h == start) & (step < val[vs])
        if np.any(early):
            raise UnsupportedError(what, "a vertex is non-manifold (its facets form several fans)")
    return True


def gather_ring(he, h0, N):
    """Control points (len(h0), N + 6) of the triangles of half-edges ``h0``
    (from the corner ``a`` of valence ``N`` to ``b``), in the order of the
    module docstring.  Raises ``IndexError`` on a missing twin (boundary)."""
    h0 = np.asarray(h0, np.int64)
    out = np.empty((len(h0), N + 6), np.int64)
    out[:, 0] = he.tail[h0]
    h = h0
    for i in range(N):
        if np.any(h < 0):
            raise IndexError("boundary reached while gathering a 1-ring")
        out[:, 1 + i] = he.head[h]
        if i < N - 1:
            h = he.rot(h)
    for start, picks, col in ((he.next(h0), (3, 4, 5), N + 1), (he.prev(h0), (3, 4), N + 4)):
        h = start
        for step in range(1, max(picks) + 1):
            h = he.rot(h)
            if np.any(h < 0):
                raise IndexError("boundary reached while gathering a 1-ring")
            if step in picks:
                out[:, col] = he.head[h]
                col += 1
    return out


def template(N):
    """Triangles (N + 7, 3) of the 1-ring of a patch with an extraordinary
    corner of valence N, over vertices 0..N+5 numbered as in the module
    docstring; triangle 0 is the patch ``(a, b, c)``."""
    a = 0
    q = list(range(1, N + 1))
    r1, r2, y, s1, s2 = N + 1, N + 2, N + 3, N + 4, N + 5
    b, c = q[0], q[1]
    tris = [(a, q[i], q[(i + 1) % N]) for i in range(N)]
    tris += [(b, q[N - 1], r1), (b, r1, r2), (b, r2, y), (b, y, c)]
    tris += [(c, y, s1), (c, s1, s2), (c, s2, q[2])]
    return np.array(tris, np.int64)


def loop_subdivide(F, nv):
    """One Loop subdivision step (Loop 1987) of the mesh ``F (nf, 3)``.

    Returns ``(S, F1, ok)``: the sparse subdivision matrix ``S`` (nv + ne, nv)
    — new vertices ``S @ X``: vertex points first, then one edge point per
    edge —, the new facets ``F1 (4 nf, 3)`` (facet ``f = (a, b, c)`` becomes
    ``4f: (a, ab, ca), 4f+1: (b, bc, ab), 4f+2: (c, ca, bc), 4f+3: (ab, bc, ca)``,
    orientation kept), and ``ok`` (nv + ne,): False for new vertices whose
    rule needs facets the mesh lacks (near a boundary; closed meshes: all True).

    Rules: vertex ``(1 − Nβ) v + β Σ neighbours``; edge
    ``3/8 (ends) + 1/8 (opposite vertices)``.
    """
    F = np.asarray(F, np.int64)
    he = HalfEdges(F, nv)
    nh = len(he.tail)
    # one edge per half-edge pair: the half-edge with tail < head, or a lone one
    rep = (he.twin < 0) | (he.tail < he.head)
    eid = np.full(nh, -1, np.int64)
    reps = np.nonzero(rep)[0]
    eid[reps] = np.arange(len(reps))
    pair = ~rep
    eid[pair] = eid[he.twin[pair]]
    ne = len(reps)
    bnd = he.boundary_vertices()
    # vertex points
    val = he.valence
    beta = np.where(val > 0, loop_beta(np.maximum(val, 3)), 0.0)
    rows = [np.arange(nv), he.tail]
    cols = [np.arange(nv), he.head]
    vals = [1.0 - val * beta, beta[he.tail]]
    # edge points
    t = he.twin[reps]
    inner = t >= 0
    e = np.arange(ne)
    rows += [nv + e, nv + e]
    cols += [he.tail[reps], he.head[reps]]
    w_end = np.where(inner, 0.375, 0.5)
    vals += [w_end, w_end]
    opp1 = he.tail[he.prev(reps)]
    rows += [nv + e[inner], nv + e[inner]]
    cols += [opp1[inner], he.tail[he.prev(t[inner])]]
    vals += [np.full(inner.sum(), 0.125), np.full(inner.sum(), 0.125)]
    S = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(nv + ne, nv))
    ok = np.concatenate([~bnd, inner])
    E = nv + eid.reshape(-1, 3)            # E[f, k]: edge point of side k (F[f,k] -> F[f,k+1])
    a, b, c = F[:, 0], F[:, 1], F[:, 2]
    ab, bc, ca = E[:, 0], E[:, 1], E[:, 2]
    F1 = np.stack([np.stack([a, ab, ca], 1), np.stack([b, bc, ab], 1),
                   np.stack([c, ca, bc], 1), np.stack([ab, bc, ca], 1)], 1).reshape(-1, 3)
    return S, F1, ok


class LoopTopology:
    """The patches of a closed control mesh ``F (nf, 3)`` with ``nv`` vertices.

    If a triangle has two or more extraordinary corners, the mesh is
    Loop-subdivided once first (after one step extraordinary vertices are
    isolated): an exact re-parametrization of the same limit surface, with
    control points ``S @ X``.

    Attributes
    ----------
    S : sparse (nc, nv) or None
        Control points of the patches from the mesh's vertices.
    classes : dict
        ``N -> (ctrl (P, N+6) control-point indices, patch_facet (P,))``, the
        original facet each patch lies in.
    levels : int
        Number of global subdivision steps applied.
    """

    def __init__(self, F, nv, what="Loop subdivision surfaces"):
        F = np.asarray(F, np.int64)
        if F.ndim != 2 or F.shape[1] != 3:
            raise UnsupportedError(what, "the control mesh must be triangulated")
        self.nv = int(nv)
        self.nf = len(F)
        he = HalfEdges(F, nv)
        check_closed_manifold(he, what)
        S = None
        owner = np.arange(len(F))
        self.levels = 0
        while True:
            classes = self._classify(he)
            if classes is not None:
                break
            if self.levels == 3:
                raise UnsupportedError(what, "the control mesh could not be split into "
                                       "patches with one extraordinary vertex")
            S1, F, _ = loop_subdivide(F, he.nv)
            S = S1 if S is None else (S1 @ S).tocsr()
            owner = np.repeat(owner, 4)
            he = HalfEdges(F, S1.shape[0])
            self.levels += 1
        self.S = S
        self.Fc = F
        self.nc = he.nv
        self.classes = {N: (ctrl, owner[f]) for N, (ctrl, f) in classes.items()}

    @staticmethod
    def _classify(he):
        F = he.F
        val = he.valence[F]                      # (nf, 3)
        ext = val != 6
        if np.any(ext.sum(1) > 1):
            return None
        k0 = np.where(ext.any(1), np.argmax(ext, 1), 0)
        Nf = val[np.arange(len(F)), k0]
        out = {}
        for N in np.unique(Nf):
            f = np.nonzero(Nf == N)[0]
            # a 1-ring may list a vertex twice (a coarse mesh, or a valence-3
            # corner next to a valence-4 vertex): harmless, the stencils used
            # only involve the facets around a, b, c, which are distinct
            out[int(N)] = (gather_ring(he, 3 * f + k0[f], int(N)), f)
        return out
