"""pyevolver.methods._common: scatter to vertices, unwrapped facet corners,
the derivative of D·N2 and the sparse assembly of element blocks."""
import numpy as np

from tolerances import FD, ROUNDOFF
import pyevolver
from pyevolver.methods import _common as K

OCT_X = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
OCT_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def test_scatter_sums_per_vertex():
    idx = np.array([0, 2, 0, 3])
    vecs = np.array([[1, 2, 3], [4, 5, 6], [10, 20, 30], [-1, -1, -1]], float)
    out = K.scatter(5, idx, vecs)
    assert out.shape == (5, 3)
    assert np.array_equal(out, [[11, 22, 33], [0, 0, 0], [4, 5, 6], [-1, -1, -1], [0, 0, 0]])
    assert np.array_equal(out.sum(0), vecs.sum(0))            # nothing lost


def test_facet_points_and_corner_scatter_on_the_octahedron():
    s = pyevolver.Surface.from_arrays(OCT_X, OCT_F, body=True)
    t = s.evaluate()
    P = K.facet_points(t)
    assert P.shape == (8, 3, 3)
    assert np.allclose(P, s.X[s.F], atol=ROUNDOFF)             # no torus: the corners themselves
    ones = np.ones((s.nf, 3, 3))
    # every octahedron vertex is on 4 facets
    assert np.allclose(K.corner_scatter(t, ones), 4.0)
    w = np.arange(1.0, 9.0)
    per_v = K.corner_scatter(t, ones, w)[:, 0]
    assert np.allclose(per_v, np.bincount(s.F.ravel(), weights=np.repeat(w, 3)))


def test_n2_grad_dot_matches_central_differences():
    rng = np.random.default_rng(0)
    P = rng.standard_normal((5, 3, 3))
    D = rng.standard_normal((5, 3))

    def f(P):
        N2 = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
        return np.einsum("ij,ij->i", D, N2)

    g = K.n2_grad_dot(P, D)
    h = 1e-6
    for c in range(3):
        for k in range(3):
            Pp, Pm = P.copy(), P.copy()
            Pp[:, c, k] += h
            Pm[:, c, k] -= h
            assert np.allclose((f(Pp) - f(Pm)) / (2 * h), g[:, c, k], atol=FD)
    assert np.allclose(g.sum(1), 0.0, atol=ROUNDOFF * 10)      # translation invariance


def test_assemble_places_and_sums_blocks():
    verts = np.array([[0, 2], [2, 1]])
    rng = np.random.default_rng(1)
    blocks = rng.standard_normal((2, 2, 2, 3, 3))
    M = K.assemble(3, verts, blocks).toarray()
    expect = np.zeros((9, 9))
    for e in range(2):
        for a in range(2):
            for b in range(2):
                i, j = verts[e, a], verts[e, b]
                expect[3 * i:3 * i + 3, 3 * j:3 * j + 3] += blocks[e, a, b]
    assert M.shape == (9, 9)
    assert np.allclose(M, expect, atol=ROUNDOFF)


def test_csr_matvec_is_scipys_product_bit_for_bit():
    """The bodies' volumes (issue 24): the same sums in the same order as
    scipy's CSR product, duplicates included; other inputs go to scipy."""
    import scipy.sparse as sp
    rng = np.random.default_rng(3)
    for trial in range(40):
        nb, nf = int(rng.integers(1, 5)), int(rng.integers(1, 400))
        rows = rng.integers(0, nb, size=int(rng.integers(1, 800)))
        cols = rng.integers(0, nf, size=len(rows))
        M = sp.csr_matrix((rng.choice([-1.0, 1.0, 0.5], size=len(rows)), (rows, cols)),
                          shape=(nb, nf))
        x = rng.standard_normal(nf) * 10.0 ** rng.uniform(-6, 6, nf)
        assert np.array_equal(K.csr_matvec(M, x), M @ x)
    assert np.array_equal(K.csr_matvec(M.tocsc(), x), M @ x)
    assert K.csr_matvec(sp.csr_matrix((0, 3)), np.ones(3)).shape == (0,)


def test_finite_is_nan_to_num():
    for x in (np.array([1.0, -2.0]), np.array([np.nan, np.inf, -np.inf, 3.0]),
              np.zeros((2, 3))):
        assert np.array_equal(K.finite(x.copy()), np.nan_to_num(x))
