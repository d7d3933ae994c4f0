"""The bodies' facet matrix built without scipy until it is used as a matrix.

A body's volume is a signed sum of its facets' cone volumes: the product of
the (bodies × facets) matrix of ±1 occurrences with the facets' volumes,
which :func:`pyevolver.methods._common.csr_matvec` computes from the CSR
arrays alone.  Loading a datafile and evaluating it therefore needs no
sparse-matrix library, and ``import scipy.sparse`` (45 ms and 8 MB at
start-up, pyevolver.startup) waits until a command needs the matrix itself
(a gradient, a Hessian, a remesh).

:func:`canonical_csr` makes the arrays that ``scipy.sparse.csr_matrix((vals,
(rows, cols)), shape)`` holds (duplicates summed, columns sorted in each
row, the index type scipy chooses), and :class:`PendingCSR` carries them
with the attributes ``csr_matvec`` reads; ``Bodies.facet_matrix`` turns it
into the scipy matrix on first use (pyevolver.model.surface).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp       # (a placeholder until used: pyevolver.startup)

_INT32_MAX = np.iinfo(np.int32).max


class PendingCSR:
    """The CSR arrays of a matrix not yet made (``format``, ``dtype``,
    ``shape``, ``data``, ``indices``, ``indptr`` as a scipy CSR matrix has
    them)."""

    format = "csr"

    def __init__(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray,
                 shape: tuple):
        self.data, self.indices, self.indptr = data, indices, indptr
        self.shape = (int(shape[0]), int(shape[1]))

    @property
    def dtype(self):
        return self.data.dtype

    def to_scipy(self):
        """The scipy CSR matrix of these arrays (sharing them)."""
        M = sp.csr_matrix((self.data, self.indices, self.indptr), shape=self.shape, copy=False)
        M.has_canonical_format = True
        return M


def canonical_csr(vals, rows, cols, shape: tuple) -> PendingCSR:
    """The CSR arrays of the COO triplets ``(vals, (rows, cols))`` as scipy
    stores them after ``csr_matrix((vals, (rows, cols)), shape)``."""
    vals = np.asarray(vals)
    if vals.dtype.kind in "biu":
        vals = vals.astype(np.int64) if vals.dtype.kind != "b" else vals
    rows = np.asarray(rows, dtype=np.int64).ravel()
    cols = np.asarray(cols, dtype=np.int64).ravel()
    vals = vals.ravel()
    nrow, ncol = int(shape[0]), int(shape[1])
    order = np.lexsort((cols, rows))
    r, c = rows[order], cols[order]
    if len(r):
        first = np.ones(len(r), bool)
        first[1:] = (r[1:] != r[:-1]) | (c[1:] != c[:-1])
        starts = np.flatnonzero(first)
        data = np.add.reduceat(vals[order], starts) if len(starts) < len(r) else vals[order]
        r, c = r[starts], c[starts]
    else:
        data = vals[:0]
    idx = np.int32 if max(nrow, ncol, len(c)) <= _INT32_MAX else np.int64
    indptr = np.zeros(nrow + 1, dtype=idx)
    np.cumsum(np.bincount(r, minlength=nrow), out=indptr[1:])
    return PendingCSR(np.ascontiguousarray(data), c.astype(idx), indptr, (nrow, ncol))


def with_copied_columns(M, cols: np.ndarray) -> PendingCSR:
    """The CSR arrays of ``[M, M[:, cols]]``: ``M`` (a scipy CSR matrix or a
    :class:`PendingCSR`) with a copy of each column ``cols[j]`` appended as
    column ``n + j`` (the bodies' facet matrix after a refinement, whose
    new facets belong to their parents' bodies), as scipy's ``hstack`` and
    ``tocsr`` would store it; no scipy import."""
    if getattr(M, "format", "csr") != "csr":
        M = M.tocsr()                                  # (another scipy format)
    data, ind, ptr = np.asarray(M.data), np.asarray(M.indices), np.asarray(M.indptr)
    nrow, ncol = int(M.shape[0]), int(M.shape[1])
    cols = np.asarray(cols, dtype=np.int64)
    rows = np.repeat(np.arange(nrow, dtype=np.int64), np.diff(ptr))
    c = ind.astype(np.int64)
    by_col = np.argsort(c, kind="stable")              # the entries column by column
    start = np.zeros(ncol + 1, dtype=np.int64)
    np.cumsum(np.bincount(c, minlength=ncol), out=start[1:])
    k = start[cols + 1] - start[cols]                  # entries of each copied column
    first = np.repeat(start[cols], k)
    offset = np.arange(int(k.sum()), dtype=np.int64) - np.repeat(np.cumsum(k) - k, k)
    src = by_col[first + offset]
    new_cols = np.repeat(ncol + np.arange(len(cols), dtype=np.int64), k)
    return canonical_csr(np.concatenate([data, data[src]]), np.concatenate([rows, rows[src]]),
                         np.concatenate([c, new_cols]), (nrow, ncol + len(cols)))
