"""Analytic invariants of the geometry kernels and the load-time energies."""
import math

import numpy as np
import pytest

from pyevolver.geometry import kernels as G
from pyevolver import read_datafile, build_surface

ICOSA = """
vertices
{verts}
edges
{edges}
faces
{faces}
bodies
1 {body}
"""


def icosahedron_fe(scale=1.0):
    p = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p],
                  [0, -1, -p], [0, 1, -p], [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]],
                 float)
    V = V / np.linalg.norm(V[0]) * scale
    F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    edges = {}
    lines_e = []
    faces = []
    for f in F:
        row = []
        for a, b in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
            if (b, a) in edges:
                row.append(-edges[(b, a)])
            else:
                edges[(a, b)] = len(edges) + 1
                lines_e.append(f"{edges[(a, b)]} {a + 1} {b + 1}")
                row.append(edges[(a, b)])
        faces.append(row)
    text = ICOSA.format(
        verts="\n".join(f"{i + 1} {float(x)!r} {float(y)!r} {float(z)!r}" for i, (x, y, z) in enumerate(V)),
        edges="\n".join(lines_e),
        faces="\n".join(f"{i + 1} " + " ".join(map(str, r)) for i, r in enumerate(faces)),
        body=" ".join(str(i + 1) for i in range(20)))
    return text


def load_text(text, tmp_path, name="t.fe"):
    p = tmp_path / name
    p.write_text(text)
    return build_surface(read_datafile(str(p)))


def test_icosahedron_area_volume(tmp_path):
    s = load_text(icosahedron_fe(), tmp_path)
    t = s.evaluate()
    # regular icosahedron with circumradius 1: edge a = 4/sqrt(10+2 sqrt 5)
    a = 4 / math.sqrt(10 + 2 * math.sqrt(5))
    assert t.total_area == pytest.approx(5 * math.sqrt(3) * a * a, rel=1e-14)
    assert t.volumes[0] == pytest.approx(5 / 12 * (3 + math.sqrt(5)) * a ** 3, rel=1e-14)


def test_symmetric_content_same_closed_volume(tmp_path):
    s1 = load_text(icosahedron_fe(2.0), tmp_path, "a.fe")
    s2 = load_text("symmetric_content\n" + icosahedron_fe(2.0), tmp_path, "b.fe")
    assert s2.evaluate().volumes[0] == pytest.approx(s1.evaluate().volumes[0], rel=1e-13)


def test_translation_invariance(tmp_path):
    s = load_text(icosahedron_fe(), tmp_path)
    v0 = s.evaluate().volumes[0]
    s.X += np.array([3.0, -2.0, 5.0])
    t = s.evaluate()
    assert t.volumes[0] == pytest.approx(v0, rel=1e-12)


def test_triangle_rule_is_degree_6():
    B, W = G.TRI6_B, G.TRI6_W
    assert W.sum() == pytest.approx(1.0, abs=1e-15)
    for i in range(7):
        for j in range(7 - i):
            exact = 2 * math.factorial(i) * math.factorial(j) / math.factorial(i + j + 2)
            assert np.sum(W * B[:, 0] ** i * B[:, 1] ** j) == pytest.approx(exact, rel=1e-13, abs=1e-16)


def test_stored_triangle_rule_is_the_polished_one():
    # TRI6_PARAMS is what polishing the published constants gives (stored for start-up)
    B, W = G._dunavant6()
    np.testing.assert_allclose(G.TRI6_B, B, rtol=0, atol=4e-16)
    np.testing.assert_allclose(G.TRI6_W, W, rtol=0, atol=4e-16)


def test_gauss_legendre_exact_to_cubic():
    for k in range(4):
        assert np.sum(G.GL2_W * G.GL2_T ** k) == pytest.approx(1 / (k + 1), rel=1e-15)


def test_gravity_of_unit_cube(tmp_path):
    # qmound-like: G*rho*int z dV = 0.5 for the unit cube resting on z=0
    text = open("/usr/share/doc/evolver/examples/cube.fe").read().split("read")[0]
    text = text.replace("volume 1", "volume 1 density 1")
    s = load_text(text, tmp_path)
    t = s.evaluate()
    assert t.terms["gravity"] == pytest.approx(0.5, rel=1e-14)
    assert t.energy == pytest.approx(6.5, rel=1e-14)


def test_long_body_line_with_attributes(tmp_path):
    """A body listing thousands of facets followed by attributes loads fast
    (regression: the numeric-line regex used to backtrack exponentially)."""
    text = icosahedron_fe()
    body = " ".join(str(i + 1) for i in range(20)) + " 1 -1" * 3000
    text = text.replace(" ".join(str(i + 1) for i in range(20)), body + " volume 2.5 density 0")
    s = load_text(text, tmp_path)
    t = s.evaluate()
    a = 4 / math.sqrt(10 + 2 * math.sqrt(5))
    assert t.volumes[0] == pytest.approx(5 / 12 * (3 + math.sqrt(5)) * a ** 3, rel=1e-13)
    assert s.bodies.target[0] == 2.5


@pytest.mark.parametrize("d", [3, 4, 5, 7])
def test_gram_area_of_a_rotated_unit_square_is_1(d):
    # the unit square split into two triangles, rotated and moved in R^d
    q, _ = np.linalg.qr(np.random.default_rng(d).standard_normal((d, d)))
    P = np.zeros((4, d))
    P[:, :2] = [[0, 0], [1, 0], [1, 1], [0, 1]]
    P = P @ q.T + 0.7
    S = np.stack([np.stack([P[1] - P[0], P[2] - P[0]]), np.stack([P[2] - P[0], P[3] - P[0]])])
    A = G.gram_facet_areas(S)
    assert np.allclose(A, 0.5, rtol=1e-14) and abs(A.sum() - 1.0) < 1e-14
    if d == 3:                       # the cross-product kernel agrees
        assert np.allclose(G.facet_areas(G.facet_normals(S)), A, rtol=1e-14)


def test_gram_area_gradient_matches_central_differences():
    rng = np.random.default_rng(1)
    P = rng.standard_normal((6, 3, 5))                     # six triangles in R^5
    S = np.stack([P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]], axis=1)
    g = G.gram_facet_area_grad(S, G.gram_facet_areas(S))
    h = 1e-6
    num = np.zeros_like(g)
    for c in range(3):
        for k in range(5):
            Pp, Pm = P.copy(), P.copy()
            Pp[:, c, k] += h
            Pm[:, c, k] -= h
            area = [G.gram_facet_areas(np.stack([Q[:, 1] - Q[:, 0], Q[:, 2] - Q[:, 0]], axis=1))
                    for Q in (Pp, Pm)]
            num[:, c, k] = (area[0] - area[1]) / (2 * h)
    assert np.abs(g - num).max() < 1e-8
    # a degenerate facet has zero area and zero gradient
    S0 = np.zeros((1, 2, 5))
    S0[0, 0, 0] = S0[0, 1, 0] = 1.0
    assert G.gram_facet_areas(S0)[0] == 0.0 and not G.gram_facet_area_grad(S0, np.zeros(1)).any()


def test_scatter_nd_sums_rows_into_vertices():
    out = G.scatter_nd(3, np.array([0, 2, 0]), np.arange(12.0).reshape(3, 4))
    assert out.tolist() == [[8, 10, 12, 14], [0, 0, 0, 0], [4, 5, 6, 7]]


def test_corner_geometry_is_the_componentwise_formula_bit_for_bit():
    """corner_geometry gathers the three axes at once (issue 24): the same
    products and sums as written out per component, and the sides."""
    rng = np.random.default_rng(5)
    X = rng.standard_normal((30, 3)) * 10.0 ** rng.uniform(-3, 3, (30, 1))
    F = rng.integers(0, 30, size=(50, 3))
    XT, Fc = np.ascontiguousarray(X.T), np.ascontiguousarray(F.T)
    P, N2T, area, vol, a, b = G.corner_geometry(XT, Fc, False, sides=True)
    p = [X[F[:, k]] for k in range(3)]
    s, t = p[1] - p[0], p[2] - p[0]
    n = np.stack([s[:, 1] * t[:, 2] - s[:, 2] * t[:, 1], s[:, 2] * t[:, 0] - s[:, 0] * t[:, 2],
                  s[:, 0] * t[:, 1] - s[:, 1] * t[:, 0]])
    assert np.array_equal(N2T, n) and np.array_equal(a, s.T) and np.array_equal(b, t.T)
    assert np.array_equal(area, 0.5 * np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]))
    assert np.array_equal(vol, (p[0][:, 2] + p[1][:, 2] + p[2][:, 2]) / 6.0 * n[2])
    _, _, _, vsym = G.corner_geometry(XT, Fc, True)
    assert np.array_equal(vsym, (p[0][:, 0] * n[0] + p[0][:, 1] * n[1] + p[0][:, 2] * n[2]) / 6.0)


def _ordered_normals_by_loops(F, N2, nv, rank):
    """REF's ordered vertex normal written out vertex by vertex."""
    N = np.zeros((nv, 3))
    for v in range(nv):
        fs, ks = np.nonzero(F == v)
        for f in fs[np.lexsort((fs, rank[fs, ks]))]:
            n = N2[f]
            N[v] += n if n @ N[v] >= 0 else -n
    L = np.linalg.norm(N, axis=1)
    return np.where(L[:, None] > 0, N / np.where(L > 0, L, 1.0)[:, None], 0.0)


@pytest.mark.parametrize("closed", [True, False])
def test_ordered_vertex_normals_follow_the_rank_bit_for_bit(closed):
    # a fan of 6 triangles round vertex 0 (open), or an octahedron (closed);
    # the ranks a permutation at each vertex (the placing path) or not (the sort)
    rng = np.random.default_rng(3)
    if closed:
        F = np.array([[0, 2, 4], [0, 4, 3], [0, 3, 5], [0, 5, 2],
                      [1, 4, 2], [1, 3, 4], [1, 5, 3], [1, 2, 5]])
        X = np.array([[0, 0, 1], [0, 0, -1], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]],
                     float) + 0.2 * rng.standard_normal((6, 3))
    else:
        t = np.linspace(0, 2 * np.pi, 7)[:-1]
        X = np.c_[np.cos(t), np.sin(t), 0.3 * rng.standard_normal(6)]
        X = np.vstack([[0, 0, 0.5], X])
        F = np.array([[0, 1 + k, 1 + (k + 1) % 6] for k in range(6)])
    nv = len(X)
    N2 = G.cross(X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]])
    N2[1] *= -1                              # one folded facet: the sign rule acts
    rank = np.zeros(F.shape, np.int64)
    for v in range(nv):
        fs, ks = np.nonzero(F == v)
        rank[fs, ks] = rng.permutation(len(fs)) * (1 if closed else 2)
    got = G.vertex_normals(F, N2, nv, rank)
    assert np.array_equal(got, _ordered_normals_by_loops(F, N2, nv, rank))
    assert np.array_equal(G.vertex_normals(F, N2.T.copy().T, nv, rank), got)   # strided N2


@pytest.mark.parametrize("nf", [7, 20_001])
def test_corner_geometry_row_by_row_is_the_same_numbers(monkeypatch, nf):
    """Above _LOW_MEMORY_FACETS the area vectors are made row by row (fewer
    temporaries); every number is the one the takes of the small path give."""
    from pyevolver.geometry import kernels as K
    rng = np.random.default_rng(nf)
    P = rng.normal(size=(3, 3, nf)) * rng.lognormal(size=(1, 1, nf))
    want = K.geometry_of_corners(P.copy())
    big = nf > K._LOW_MEMORY_FACETS
    monkeypatch.setattr(K, "_LOW_MEMORY_FACETS", 10 ** 9 if big else 0)   # the other path
    got = K.geometry_of_corners(P.copy())
    assert all(np.array_equal(x, y) for x, y in zip(want, got))


def test_edge_index_integer_and_other_dtypes():
    """edge_index: the bit trick on signed integers equals the plain rule
    (index ~e and sign -1 for a reversed edge), for int32 and int64."""
    from pyevolver.geometry.kernels import edge_index
    for dt in (np.int64, np.int32):
        fe = np.array([[0, -1, 5], [~7, 3, ~0]], dt)
        idx, sgn = edge_index(fe)
        assert idx.dtype == dt and sgn.dtype == np.float64
        assert np.array_equal(idx, np.where(fe < 0, ~fe, fe))
        assert np.array_equal(sgn, np.where(fe < 0, -1.0, 1.0))
    idx, sgn = edge_index([3, ~2])
    assert list(idx) == [3, 2] and list(sgn) == [1.0, -1.0]
    idx, sgn = edge_index(np.zeros((0, 3), np.int64))
    assert idx.shape == sgn.shape == (0, 3)
