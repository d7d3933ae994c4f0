"""Fill-reducing elimination order for the Hessian's sparse factorization.

The unknowns of a ``hessian`` step sit at the surface's vertices, so a
geometric nested dissection (George 1973; Gilbert, Miller & Teng, "Geometric
mesh partitioning", SIAM J. Sci. Comput. 19, 1998) orders them in a few
vectorized passes: every part is cut at the median of its widest coordinate,
the unknowns of one side that are coupled (in the matrix) to the other side
form the separator, and separators are eliminated after the parts they
separate, the first cut last.  On an 81,920-facet sphere this order gives
CHOLMOD's simplicial LDLᵀ about half the fill of its default AMD order;
METIS's nested dissection (pymetis, measured on the Hessians of
benchmarks/bench_hessian.py) leaves 15% fewer factor entries but takes 2.5–3
times as long to compute (0.20 s against 0.08 s), more than SuperLU gains.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


def _dissect(points, pattern, leaf):
    """(part, key) of each unknown: the part id after its last cut and the
    depth of the cut that made it a separator (the deepest depth for the
    unknowns of the leaf parts)."""
    P = np.asarray(points, float)
    n = len(P)
    C = sp.coo_matrix(pattern)
    upper = C.row < C.col
    lower = C.row > C.col
    ei = np.concatenate([C.row[upper], C.col[lower]]).astype(np.intp)
    ej = np.concatenate([C.col[upper], C.row[lower]]).astype(np.intp)
    # ei, ej: each coupling once, as intp (take() on 32-bit indices copies them)
    PT = np.ascontiguousarray(P.T)
    # code: an active unknown's part id at this depth (2 × its part's id + its
    # side after each cut), -1 for a separator; an edge joins two unknowns of
    # one part cut in two when its codes differ in the last bit only
    code = np.zeros(n, np.int32)
    level = np.full(n, -1, np.int32)      # cut at which an unknown became separator
    final = np.zeros(n, np.int32)         # a separator's part id just after its cut
    depth = 0
    while True:
        idx = np.flatnonzero(code >= 0)
        pid = code.take(idx)
        nparts = 1 << depth
        size = np.bincount(pid, minlength=nparts)
        cut = size > leaf
        if not cut.any():
            break
        into = cut[pid]                   # (parts not cut keep their unknowns on side 0)
        idx, pid = idx[into], pid[into]
        # each part's bounding box; its widest axis; the rank along it
        lo = np.full((3, nparts), np.inf)
        hi = np.full((3, nparts), -np.inf)
        X = PT.take(idx, axis=1)
        for a in range(3):
            np.minimum.at(lo[a], pid, X[a])
            np.maximum.at(hi[a], pid, X[a])
        ext = hi - lo
        ext[:, ~cut] = 0.0
        axis = np.argmax(ext, axis=0)
        span = ext[axis, np.arange(nparts)]
        span[span <= 0] = 1.0
        ax = axis[pid]
        t = X[ax, np.arange(len(idx))]
        t -= lo[ax, pid]
        t /= span[pid]
        t *= 0.5
        t += pid
        order = np.argsort(t)
        first = np.zeros(nparts, np.int64)
        np.cumsum(np.where(cut, size, 0)[:-1], out=first[1:])
        rank = np.empty(len(idx), np.int64)
        po = pid[order]
        rank[order] = np.arange(len(idx)) - first[po]
        right = rank >= size[pid] // 2
        active = code >= 0
        code[active] *= 2
        code[idx] += right
        # separator: the side-0 end of each edge across a cut (edges that
        # no longer join one part, or touch a separator, never match again:
        # they are dropped when a fifth of the list is such)
        ci = code.take(ei)
        cj = code.take(ej)
        x = ci ^ cj
        cross = np.flatnonzero(x == 1)
        a, b = ei[cross], ej[cross]
        left = np.where(ci[cross] & 1 == 0, a, b)
        final[left] = code[left]
        level[left] = depth
        code[left] = -1
        keep = x == 0
        keep &= ci >= 0
        if keep.sum() < 0.8 * len(keep):
            ei, ej = ei[keep], ej[keep]
        depth += 1
    part = np.where(level < 0, code, final)
    key = np.where(level < 0, depth, level)
    return part, key


def nested_dissection(points, pattern, leaf=16):
    """Elimination order of the unknowns.

    Parameters
    ----------
    points : (n, 3) array
        A position for each unknown (its vertex).
    pattern : sparse (n, n) matrix
        The couplings; only its nonzero pattern is used (symmetrized).
    leaf : int
        Parts of at most this many unknowns are not cut further (16: on the
        81,920-facet spheres 7–12% less fill than 64, deeper cuts gain nothing).

    Returns
    -------
    perm : (n,) int array
        ``A[perm][:, perm]`` is the reordered matrix.
    """
    return dissection(points, pattern, leaf)[0]


def dissection(points, pattern, leaf=16):
    """:func:`nested_dissection`'s order and its fronts: ``(perm, front)``,
    ``front`` (n,) int64 the same number for the unknowns of one separator
    or one leaf part (benchmarks/bench_frontal.py)."""
    n = len(points)
    if n <= leaf:
        return np.arange(n), np.zeros(n, np.int64)
    part, key = _dissect(points, pattern, leaf)
    perm = np.lexsort((np.arange(n), part, -key)).astype(np.int64)
    return perm, (key.astype(np.int64) << 32) | part.astype(np.int64)
