"""``r`` in the simplex model: every 1-edge of every simplex is halved and
each k-simplex becomes 2^k (the manual, "Simplex model").

The rule, measured on evolver-nox-d (REF) with one-facet datafiles:

* each facet's vertices are sorted by the key ``a · x``, ``a`` a fixed
  vector (:data:`SORT_KEY`, REF's in its first six coordinates, measured by
  bisection: the order of two points flips where their keys meet, whatever
  the other corners, in 2 to 6 dimensions);
* the midpoints of the facet's edges are made in the lexicographic order of
  the sorted corner pairs (01, 02, …, 12, …); an edge shared with an earlier
  facet keeps its midpoint; new vertices are numbered in that order;
* the children come from a template in sorted corner pairs (``ij`` the
  midpoint of corners i and j, ``ii`` corner i) (:data:`TEMPLATES`, k = 2,
  3, 4); when the sort is an odd permutation of the facet's own order, the
  first two vertices of every child are swapped (so each child keeps the
  facet's orientation);
* the facet itself becomes the first child; the others are appended, facet
  after facet, with the facet's attributes (``original`` is the facet's).

A new vertex is FIXED when both ends of its edge are, and on the level-set
constraints of both (the manual: the midpoint inherits the common attributes
of the edge's endpoints); it is projected on them.
"""
from __future__ import annotations

import copy

import numpy as np
import scipy.sparse as sp

from ..constraints import constrained_vertices, project_to_constraints
from ..errors import CommandError, UnsupportedError
from .. import limits

#: REF's sort direction (first coordinate 1; measured, see the module doc)
SORT_KEY = np.array([1.0, 0.2679521823599665, -1.3375437838758464, 0.4785552790557894,
                     0.16722259765071507, -0.6224911333566231])

#: the children of a k-simplex in sorted corner pairs, in REF's order
TEMPLATES = {
    2: ["00 01 02", "11 12 01", "22 02 12", "01 12 02"],
    3: ["00 01 02 03", "11 01 13 12", "22 02 12 23", "33 03 23 13",
        "01 02 13 12", "01 13 02 03", "03 13 02 23", "02 13 12 23"],
    4: ["01 02 03 04 00", "12 01 13 14 11", "02 12 23 24 22", "13 03 23 34 33",
        "04 14 24 34 44", "12 02 23 24 01", "03 13 23 34 01", "14 04 24 34 01",
        "13 23 34 12 01", "24 14 34 12 01", "24 34 23 12 01", "34 14 13 12 01",
        "23 03 34 02 01", "04 24 34 02 01", "34 24 23 02 01", "04 34 03 02 01"],
}


def _columns(k):
    """Template children as column indices into ``[corners | midpoints]``."""
    pairs = [(i, j) for i in range(k + 1) for j in range(i + 1, k + 1)]
    col = {(i, i): i for i in range(k + 1)}
    col.update({p: k + 1 + n for n, p in enumerate(pairs)})
    kids = np.array([[col[(int(c[0]), int(c[1]))] for c in child.split()]
                     for child in TEMPLATES[k]], np.int64)
    return np.array(pairs, np.int64), kids


def _odd(perm):
    """(n,) True where the rows of ``perm (n, m)`` are odd permutations."""
    m = perm.shape[1]
    inv = np.zeros(len(perm), np.int64)
    for i in range(m):
        for j in range(i + 1, m):
            inv += perm[:, i] > perm[:, j]
    return inv % 2 == 1


def refine(s):
    """The simplex surface ``s`` refined (a new Surface; ``s`` is unchanged)."""
    k = s.simplex
    if k not in TEMPLATES:
        raise UnsupportedError(f"r in the simplex model of dimension {k}",
                               f"REF's refinement is known for dimensions "
                               f"{min(TEMPLATES)} to {max(TEMPLATES)}")
    d = s.X.shape[1]
    if d > len(SORT_KEY):
        raise UnsupportedError(f"r in the simplex model in {d} dimensions",
                               f"REF's sort key is known in up to {len(SORT_KEY)}")
    nf, nv = s.n_facets, s.nv
    pairs, kids = _columns(k)
    nkid = len(kids)
    if nf * nkid > limits.MAX_ELEMENTS:
        raise CommandError(f"the surface would grow to {nf * nkid} facets, beyond the "
                           f"{limits.MAX_ELEMENTS} elements allowed; the surface is unchanged")
    key = s.X @ SORT_KEY[:d]
    perm = np.argsort(key[s.SF], axis=1, kind="stable")
    V = np.take_along_axis(s.SF, perm, axis=1)                  # sorted corners
    a, b = V[:, pairs[:, 0]], V[:, pairs[:, 1]]                 # (nf, m) edge ends
    lo, hi = np.minimum(a, b).ravel(), np.maximum(a, b).ravel()
    code = lo * nv + hi
    uniq, first, inv = np.unique(code, return_index=True, return_inverse=True)
    rank = np.empty(len(uniq), np.int64)
    rank[np.argsort(first, kind="stable")] = np.arange(len(uniq))
    M = nv + rank[inv].reshape(a.shape)                         # midpoint vertex per pair
    ends = np.empty((len(uniq), 2), np.int64)
    ends[rank] = np.stack([lo[first], hi[first]], axis=1)
    C = np.concatenate([V, M], axis=1)
    child = C[:, kids]                                          # (nf, nkid, k+1)
    odd = _odd(perm)
    child[odd, :, 0], child[odd, :, 1] = child[odd, :, 1].copy(), child[odd, :, 0].copy()

    t = copy.copy(s)
    nmid = len(ends)
    t.X = np.concatenate([s.X, 0.5 * (s.X[ends[:, 0]] + s.X[ends[:, 1]])])
    va = {}
    for name, arr in s.vattr.items():
        rows = np.zeros((nmid,) + arr.shape[1:], arr.dtype)
        if name == "fixed":
            rows = arr[ends[:, 0]] & arr[ends[:, 1]]
        elif name == "id":
            top = int(arr.max()) if len(arr) else 0
            rows = np.arange(top + 1, top + 1 + nmid)
        va[name] = np.concatenate([arr, rows])
    t.vattr = va
    # a midpoint is on the constraints common to its edge's ends (REF)
    t.vcon = {cid: np.concatenate([on, on[ends[:, 0]] & on[ends[:, 1]]])
              for cid, on in s.vcon.items()}
    parent = np.repeat(np.arange(nf), nkid - 1)                 # of the appended facets
    t.SF = np.concatenate([child[:, 0], child[:, 1:].reshape(-1, k + 1)])
    fa = {}
    for name, arr in s.fattr.items():
        rows = arr[parent].copy()
        if name == "id":
            top = int(arr.max()) if len(arr) else 0
            rows = np.arange(top + 1, top + 1 + len(parent))
        fa[name] = np.concatenate([arr, rows])
    t.fattr = fa
    extra = {}
    for (etype, name), arr in s.extra.items():
        if etype == "vertex":
            arr = np.concatenate([arr, np.zeros((nmid,) + arr.shape[1:], arr.dtype)])
        elif etype == "facet":
            arr = np.concatenate([arr, arr[parent]])
        extra[(etype, name)] = arr
    t.extra = extra
    b = copy.copy(s.bodies)
    if b.n:
        Mb = s.bodies.facet_matrix.tocsc()
        b.facet_matrix = sp.hstack([Mb, Mb[:, parent]]).tocsr()
        ob, of, osg = s.bodies.occurrences
        # each occurrence of a facet gains its children, in facet order
        rep = np.repeat(np.arange(len(of)), nkid - 1)
        kid = nf + of[rep] * (nkid - 1) + np.tile(np.arange(nkid - 1), len(of))
        order = np.lexsort((kid, ob[rep]))
        b.occurrences = (np.concatenate([ob, ob[rep][order]]),
                         np.concatenate([of, kid[order]]),
                         np.concatenate([osg, osg[rep][order]]))
        b.volume = None
    t.bodies = b
    t.topology_version = getattr(s, "topology_version", 0) + 1
    new = np.arange(nv, nv + nmid)
    if t.vcon and len(project_to_constraints(t, new[constrained_vertices(t)[new]])):
        raise CommandError("r: new vertices could not be projected on their constraints; "
                           "the surface is unchanged")
    return t
