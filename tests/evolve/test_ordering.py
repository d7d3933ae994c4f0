"""Geometric nested dissection for the hessian's factorization
(pyevolver/evolve/ordering.py)."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from pyevolver.evolve import hessian as H
from pyevolver.evolve.ordering import nested_dissection
from pyevolver.studies.meshes import edges, icosphere


def _graph_laplacian(level):
    X, F = icosphere(level)
    E, _ = edges(F)
    n = len(X)
    A = sp.coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(n, n))
    A = (A + A.T).tocsr()
    return X, (sp.diags(np.asarray(A.sum(1)).ravel()) - A).tocsc()


def _fill(M):
    """Nonzeros of the LU factors of an SPD matrix eliminated in the given order."""
    lu = spla.splu(M.tocsc(), permc_spec="NATURAL", diag_pivot_thresh=0.0,
                   options={"SymmetricMode": True})
    return lu.L.nnz + lu.U.nnz


def test_is_a_permutation_and_cuts_fill():
    """On the 2,562-vertex icosphere the order is a permutation of the
    unknowns and the factor of the graph Laplacian (+I) has less than a
    third of the fill of the file's own vertex order (nested dissection
    of a planar-like graph: O(n log n) instead of O(n^1.5))."""
    X, L = _graph_laplacian(4)
    M = (L + sp.identity(L.shape[0])).tocsc()
    p = nested_dissection(X, M)
    assert np.array_equal(np.sort(p), np.arange(len(X)))
    natural = _fill(M)
    nd = _fill(M[p][:, p])
    assert nd < natural / 3, (nd, natural)


def test_small_problems_keep_their_order():
    X = np.random.default_rng(0).standard_normal((10, 3))
    assert np.array_equal(nested_dissection(X, sp.identity(10), leaf=64), np.arange(10))


@pytest.mark.cholmod
def test_cholmod_in_this_order_solves_the_bordered_system():
    """An indefinite K (graph Laplacian shifted by -0.37) bordered by two
    dense columns: CHOLMOD in the nested-dissection order and SuperLU on the
    whole bordered matrix give the same solution."""
    X, L = _graph_laplacian(4)
    assert L.shape[0] > H._ND_MIN
    K = (L - 0.37 * sp.identity(L.shape[0])).tocsc()
    rng = np.random.default_rng(5)
    B = rng.standard_normal((K.shape[0], 2))
    r = rng.standard_normal(K.shape[0])
    d = rng.standard_normal(2)
    a = H.solve_bordered(K, B, r, d, method="cholmod", points=X)
    b = H.solve_bordered(K, B, r, d, method="splu")
    assert np.abs(a - b).max() <= 1e-8 * np.abs(b).max()


@pytest.mark.parametrize("case", ["no couplings", "one point", "two components"])
def test_degenerate_inputs_give_a_permutation(case):
    """Parts whose points coincide (no widest axis), unknowns without
    couplings (no separators) and a graph in two pieces (edges that stop
    joining one part) still give a permutation that eliminates every
    separator after the parts it separates: the factor of the Laplacian + I
    in that order has no more fill than in the file's order."""
    X, L = _graph_laplacian(3)
    n = L.shape[0]
    if case == "no couplings":
        M = sp.identity(n, format="csc")
    elif case == "one point":
        X = np.zeros_like(X)
        M = (L + sp.identity(n)).tocsc()
    else:
        M = sp.block_diag([L + sp.identity(n), L + sp.identity(n)]).tocsc()
        X = np.vstack([X, X + 0.5])
    p = nested_dissection(X, M)
    assert np.array_equal(np.sort(p), np.arange(M.shape[0]))
    assert _fill(M[p][:, p]) <= _fill(M)
