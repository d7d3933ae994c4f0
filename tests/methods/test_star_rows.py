"""The star-sum Jacobian assembled straight into CSR (pyevolver.methods.star_rows)."""
import io
import os
import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse as sp

from pyevolver.methods import star_rows as SR

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


class _Basis:
    def __init__(self, ndof):
        self.ndof = np.asarray(ndof, np.int64)
        self.start = np.concatenate([[0], np.cumsum(self.ndof)[:-1]]).astype(np.int64)
        self.n = int(self.ndof.sum())
        self.B = np.zeros((len(ndof), 3, 1))


def _coo(F, basis, r, vals):
    """The same matrix from COO triplets (duplicates summed)."""
    m = len(F)
    rows = np.broadcast_to((r * F[:, :, None] + np.arange(r))[:, :, :, None], (m, 3, r, 3))
    colv = np.broadcast_to(F[:, None, None, :], (m, 3, r, 3))
    keep = basis.ndof[colv] > 0
    return sp.csr_matrix((vals[keep], (rows[keep], basis.start[colv][keep])),
                         shape=(r * len(basis.ndof), basis.n)).toarray()


#: a small closed surface: the octahedron
OCTAHEDRON = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                       [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def _octahedron_basis(fixed):
    ndof = np.ones(6, np.int64)
    ndof[fixed] = 0
    return OCTAHEDRON, _Basis(ndof)


@pytest.mark.parametrize("fast", [True, False])        # np.add.at, or one bincount a chunk
@pytest.mark.parametrize("fixed", [[], [0, 3]])
def test_chunks_add_up_to_the_coo_assembly(fixed, fast, monkeypatch):
    monkeypatch.setattr(SR, "_FAST_ADD_AT", fast)
    F, basis = _octahedron_basis(fixed)
    r = 4
    vals = np.random.default_rng(1).standard_normal((len(F), 3, r, 3))
    rows = SR.StarRows(F, basis, r)
    rows.add_chunk(0, F[:5], vals[:5])
    rows.add_chunk(5, F[5:], vals[5:])
    assert np.allclose(rows.matrix().toarray(), _coo(F, basis, r, vals), rtol=0, atol=1e-14)
    # each pair once: at most the star's vertices per row
    assert rows.matrix().nnz == np.count_nonzero(_coo(F, basis, r, np.ones_like(vals)))


@pytest.mark.parametrize("fixed", [[], [0, 3]])
def test_block_product_is_the_block_diagonal_product(fixed):
    # diag(M) J with per-vertex (r, r) blocks: the sparse product's numbers
    F, basis = _octahedron_basis(fixed)
    r = 3
    rng = np.random.default_rng(2)
    rows = SR.StarRows(F, basis, r)
    rows.add_chunk(0, F, rng.standard_normal((len(F), 3, r, 3)))
    M = rng.standard_normal((6, r, r))
    J = rows.matrix().toarray()
    want = sp.block_diag(list(M)).toarray() @ J
    got = rows.block_product(M)
    assert np.allclose(got.toarray(), want, rtol=0, atol=1e-13)
    assert np.array_equal(got.indices, rows.matrix().indices)


def test_bending_hessian_same_as_the_coo_path(tmp_path, monkeypatch):
    """star_perp_sq_mean_curvature + area + volume on a 320-facet icosphere
    (hessian_normal): the Hessian system with the CSR path equals the COO
    path's to round-off."""
    from pyevolver import Session
    from pyevolver.evolve import hessian_nd
    fe = str(tmp_path / "ico.fe")
    subprocess.run([sys.executable, os.path.join(ROOT, "benchmarks", "make_icosphere.py"),
                    "--level", "2", "--out", fe], check=True, capture_output=True)
    text = open(fe).read()
    open(fe, "w").write("quantity bend energy modulus 1 method star_perp_sq_mean_curvature"
                        " global\n" + text)
    s = Session.load(fe, out=io.StringIO())
    s.run("set vertex z z*1.5 where id > 3\nfix vertex where id <= 2\n"
          "set body target body[1].volume\ng 2\n")
    made = []
    monkeypatch.setattr(SR, "StarRows", lambda *a, _c=SR.StarRows: made.append(1) or _c(*a))
    K1 = hessian_nd.system(s.iterator, True).K.toarray()
    assert made                           # the CSR path ran
    monkeypatch.setattr(SR, "applies", lambda basis: False)
    K2 = hessian_nd.system(s.iterator, True).K.toarray()
    assert np.abs(K1 - K2).max() <= 1e-12 * np.abs(K2).max()
