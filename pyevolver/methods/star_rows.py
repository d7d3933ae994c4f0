"""The star-sum Jacobian of the curvature Hessians assembled straight into CSR.

:func:`.curvature_hessian.star_hessian` writes the Jacobian ``J`` of the
per-vertex star sums (``r`` rows per vertex) from per-facet blocks: facet
``f`` adds to the rows of each corner ``v`` entries in the columns of its
three corners.  As COO triplets that is ``9 r`` entries per facet, each
``(row, column)`` pair coming from the two facets of an edge (six or so for
the vertex's own column): at 81,920 facets 5.2 million triplets, 125 MB,
that a conversion to CSR then sums to 2 million.

:class:`StarRows` computes the CSR pattern once from the facets — the
columns of vertex ``v``'s rows are the free motions of the vertices of its
star, the same for its ``r`` rows — and the position of every facet
corner pair in it; :meth:`StarRows.add` adds a chunk of facets' blocks with
one ``np.bincount`` into the data array.  Only the one-free-direction case
(``hessian_normal``: a basis with one column per vertex, or none for a
fixed vertex) takes this path.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

#: numpy 1.25 made ``np.add.at`` fast (at 81,920 facets 1.8 ms a chunk against
#: 5.3 ms for a bincount as long as the data); older ones take the bincount
_FAST_ADD_AT = np.lib.NumpyVersion(np.__version__) >= "1.25.0"


def applies(basis) -> bool:
    """Whether :class:`StarRows` handles ``basis`` (one free direction per
    vertex at most)."""
    return basis is not None and basis.B.shape[2] == 1


class StarRows:
    """CSR pattern of a (r·nv, basis.n) Jacobian whose rows of vertex ``v``
    couple the free motions of the vertices of ``v``'s facets.

    F : (nf, 3) facet corners; basis : a :class:`~pyevolver.evolve.hessian.Basis`
    with ``applies(basis)``; r : rows per vertex.
    """

    def __init__(self, F, basis, r):
        # (32-bit indices and temporaries dropped as soon as used: the
        # pattern's construction peaked at 100 MB at 81,920 facets)
        F = np.asarray(F, np.int32)
        nv = len(basis.ndof)
        self.r, self.nv, self.ncols = r, nv, basis.n
        col = np.where(basis.ndof > 0, basis.start, -1).astype(np.int32)   # (nv,) column or -1
        v = np.repeat(F, 3, axis=1)                                  # (nf, 9): row corner a
        u = np.tile(F, (1, 3))                                       #          column corner b
        ok = col[u] >= 0
        A = sp.csr_matrix((np.ones(int(ok.sum()), bool), (v[ok], u[ok])), shape=(nv, nv))
        A.sum_duplicates()                                           # sorted, unique
        cnt = np.diff(A.indptr)
        # the position of every (v, u) pair in A: A's entries numbered 1, 2, ...
        # and read back (scipy's lookup, five times faster than a search)
        at = sp.csr_matrix((np.arange(1.0, A.nnz + 1.0), A.indices, A.indptr), shape=A.shape)
        found = np.asarray(at[v.ravel(), u.ravel()]).reshape(v.shape)
        del at, u
        slot = (found.astype(np.int64) - 1 - A.indptr[v]).astype(np.int32)   # (nf, 9)
        del found, v
        slot[~ok] = -1
        self.slot = slot
        rows = np.repeat(cnt, r)                                     # entries of each row
        self.indptr = np.zeros(r * nv + 1, np.int64)
        np.cumsum(rows, out=self.indptr[1:])
        nnz = int(self.indptr[-1])
        # entry e of row ρ (vertex ρ // r) is A's entry indptr_A[ρ // r] + e − indptr[ρ]
        first = np.repeat((A.indptr[:-1].astype(np.int64)[:, None]
                           - self.indptr[:-1].reshape(nv, r)).ravel(), rows)
        del rows
        first += np.arange(nnz)
        self.indices = col[A.indices[first]]
        del first
        self.data = np.zeros(nnz)

    def add_chunk(self, lo, Fc, vals):
        """Add the blocks ``vals`` (m, 3, r, 3) of facets ``lo .. lo + m``
        (corners ``Fc``): row ``r·Fc[:, a] + i``, the column of vertex
        ``Fc[:, b]`` gets ``vals[:, a, i, b]``; pairs with a fixed column
        vertex are dropped."""
        m = len(Fc)
        r = self.r
        slot = self.slot[lo:lo + m].reshape(m, 3, 1, 3)
        start = self.indptr[:-1][r * Fc[:, :, None] + np.arange(r)]  # (m, 3, r)
        pos = start[:, :, :, None] + slot                            # (m, 3, r, 3)
        keep = np.broadcast_to(slot >= 0, pos.shape)
        if keep.all():
            pos, w = pos.ravel(), np.asarray(vals).ravel()
        else:
            pos, w = pos[keep], np.asarray(vals)[keep]
        if _FAST_ADD_AT:     # (in place: no array as long as the data per chunk)
            np.add.at(self.data, pos, w)
        else:
            self.data += np.bincount(pos, weights=w, minlength=len(self.data))

    def matrix(self):
        """The CSR matrix (its arrays, not copies)."""
        return sp.csr_matrix((self.data, self.indices, self.indptr),
                             shape=(self.r * self.nv, self.ncols))

    def block_product(self, M):
        """``diag(M) J`` (CSR, J's pattern) for per-vertex blocks M (nv, r, r).

        The r rows of vertex v share their columns (the free motions of v's
        star), so they are one dense (r, c_v) block of the data array and
        ``M_v`` multiplies it in place of a sparse product: at 81,920
        facets 16 MB of new data where ``Md @ J`` built a block-diagonal
        matrix and a product of 24 MB each."""
        r = self.r
        start = self.indptr[:-1:r]                                   # (nv,) first entry
        width = (self.indptr[r::r] - start) // r                     # c_v
        out = np.zeros_like(self.data)
        for c in np.unique(width[width > 0]):
            group = np.flatnonzero(width == c)
            for lo in range(0, len(group), 4096):        # (temporaries of a few MB)
                vs = group[lo:lo + 4096]
                idx = start[vs][:, None] + np.arange(r * c)          # (k, r c)
                D = self.data[idx].reshape(len(vs), r, c)
                out[idx] = np.matmul(M[vs], D).reshape(len(vs), r * c)
        return sp.csr_matrix((out, self.indices, self.indptr),
                             shape=(self.r * self.nv, self.ncols))
