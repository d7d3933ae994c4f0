"""SuperLU without scipy.sparse.linalg's import (pyevolver.evolve.superlu)."""
import subprocess
import sys

import numpy as np
import scipy.sparse as sp

from pyevolver.evolve import superlu


def _indefinite(n=200, seed=0):
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.03, random_state=seed)
    return (A + A.T + sp.diags(rng.normal(size=n) * 4.0)).tocsc()


def test_factor_solves_and_pivots_count_negative_eigenvalues():
    A = _indefinite()
    lu = superlu.factor(A, natural=True)
    b = np.arange(A.shape[0], dtype=float)
    assert np.allclose(A @ lu.solve(b), b, atol=1e-9)
    d = superlu.pivots(lu)
    # Sylvester: the LDLᵀ pivots have the matrix's inertia
    assert int(np.sum(d < 0)) == int(np.sum(np.linalg.eigvalsh(A.toarray()) < 0))


def test_minimum_degree_order_gives_the_same_solution():
    A = _indefinite(seed=3)
    b = np.ones(A.shape[0])
    x1 = superlu.factor(A, natural=True).solve(b)
    x2 = superlu.factor(A, natural=False).solve(b)
    assert np.allclose(x1, x2, rtol=1e-8, atol=1e-10)


def test_diagonal_of_general_csc_arrays():
    # a column whose diagonal entry is neither first nor last
    M = sp.csc_matrix(np.array([[2.0, 0, 1], [0, 3.0, 0], [5.0, 0, 7.0]]))
    M.indices[:] = M.indices.copy()
    d = superlu.Diagonal((M.data, M.indices, M.indptr), shape=M.shape).diagonal()
    assert np.array_equal(d, [2.0, 3.0, 7.0])
    # longer arrays than nnz (SuperLU's buffers) and an empty column
    data = np.array([4.0, 1.0, 9.0, 0.0])
    d = superlu.Diagonal((data, np.array([0, 2, 2, 0]), np.array([0, 1, 1, 3])),
                         shape=(3, 3)).diagonal()
    assert np.array_equal(d, [4.0, 0.0, 9.0])


def test_singular_matrix_raises_runtime_error():
    A = sp.csc_matrix(np.array([[1.0, 1.0], [1.0, 1.0]]))
    try:
        superlu.factor(A, natural=True)
    except RuntimeError:
        return
    raise AssertionError("no RuntimeError")


def test_factor_does_not_import_scipy_sparse_linalg():
    # in a fresh interpreter (this one may have imported it already)
    code = ("import sys, numpy as np, scipy.sparse as sp\n"
            "from pyevolver.evolve import superlu\n"
            "before = 'scipy.sparse.linalg' in sys.modules\n"
            "lu = superlu.factor(sp.identity(5, format='csc') * 2.0)\n"
            "print(before, lu.solve(np.ones(5))[0], superlu.pivots(lu)[0],"
            " 'scipy.sparse.linalg' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "0.5", "2.0", "False"]


def test_stored_diagonal_is_the_diagonal_of_U():
    # read from SuperLU's supernodes without copying the factors; the same
    # numbers as scipy's copied U, with either order, on sizes 1 to 400
    for n, seed in [(1, 0), (2, 1), (7, 2), (60, 3), (400, 4)]:
        rng = np.random.default_rng(seed)
        M = sp.random(n, n, density=min(1.0, 6 / n), random_state=seed)
        A = (M + M.T + sp.diags(rng.normal(size=n) * 3.0)).tocsc()
        A.sort_indices()
        for natural in (True, False):
            lu = superlu.factor(A, natural=natural)
            d = superlu._stored_diagonal(lu)
            assert d is not None
            assert np.array_equal(d, lu.U.diagonal())


def test_stored_diagonal_refuses_what_is_not_a_superlu_object():
    class Fake:                          # the attributes, not the layout
        shape = (3, 3)
        perm_r = np.arange(3, dtype=np.intc)
    assert superlu._stored_diagonal(Fake()) is None
