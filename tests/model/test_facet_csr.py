"""The bodies' facet matrix kept as CSR arrays until used (pyevolver.model.facet_csr):
the arrays are scipy's, and the volumes the same numbers."""
import numpy as np
import pytest
import scipy.sparse as sp

from pyevolver.methods._common import csr_matvec
from pyevolver.model.facet_csr import PendingCSR, canonical_csr, with_copied_columns
from pyevolver.model.surface import Bodies


@pytest.mark.parametrize("seed", range(6))
def test_arrays_are_scipys(seed):
    rng = np.random.default_rng(seed)
    nb, nf = int(rng.integers(1, 5)), int(rng.integers(1, 40))
    n = int(rng.integers(0, 80))
    rows, cols = rng.integers(0, nb, n), rng.integers(0, nf, n)
    vals = rng.choice([-1.0, 1.0], n)           # duplicates and cancellations included
    want = sp.csr_matrix((vals, (rows, cols)), shape=(nb, nf))
    got = canonical_csr(vals, rows, cols, (nb, nf))
    for name in ("data", "indices", "indptr"):
        a, b = getattr(want, name), getattr(got, name)
        assert a.dtype == b.dtype and np.array_equal(a, b), name
    assert got.shape == want.shape and got.format == "csr" and got.dtype == want.dtype
    x = rng.normal(size=nf)
    assert np.array_equal(csr_matvec(got, x), csr_matvec(want, x))
    assert ((got.to_scipy() != want).nnz, got.to_scipy().has_canonical_format) == (0, True)


def test_empty():
    got = canonical_csr([], [], [], (0, 5))
    assert got.indptr.tolist() == [0] and got.to_scipy().shape == (0, 5)


def test_bodies_make_the_matrix_when_first_read():
    b = Bodies()
    pending = canonical_csr([1.0, -1.0, 1.0], [0, 0, 1], [2, 0, 1], (2, 3))
    b.facet_matrix = pending
    assert b.facet_csr is pending                       # volumes need no scipy matrix
    M = b.facet_matrix
    assert sp.issparse(M) and M.format == "csr" and not isinstance(M, PendingCSR)
    assert M.toarray().tolist() == [[-1, 0, 1], [0, 1, 0]]
    assert b.facet_matrix is M and b.facet_csr is M     # made once
    b.facet_matrix = sp.csr_matrix((1, 3))              # a remesh sets a new one
    assert b.facet_csr.nnz == 0


@pytest.mark.parametrize("seed", range(40))
def test_copied_columns_are_scipys_hstack(seed):
    """[M, M[:, cols]] as scipy's hstack and tocsr store it (the facet matrix
    after a refinement), from a scipy matrix and from pending arrays."""
    rng = np.random.default_rng(seed)
    nb, nf = int(rng.integers(1, 5)), int(rng.integers(1, 30))
    A = sp.random(nb, nf, density=0.4, random_state=seed, format="csr")
    A.data = np.where(A.data < 0.5, -1.0, 1.0)
    cols = rng.integers(0, nf, int(rng.integers(0, 40)))
    want = sp.hstack([A.tocsc(), A.tocsc()[:, cols]]).tocsr()
    for M in (A, PendingCSR(A.data, A.indices, A.indptr, A.shape), A.tocsc()):
        got = with_copied_columns(M, cols)
        assert got.shape == want.shape
        assert np.array_equal(got.indptr, want.indptr)
        assert np.array_equal(got.indices, want.indices)
        assert np.array_equal(got.data, want.data)
