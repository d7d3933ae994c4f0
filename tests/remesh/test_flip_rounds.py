"""Direct tests of pyevolver.remesh.flip_rounds: the equiangulation pass in
rounds gives the sequential pass's surface, bit for bit.

The reference here is a plain pass written for the test: every edge in id
order, one visit each, the joined pairs in a set.  The meshes are jittered
icospheres with shuffled edge ids (other visiting orders), made irregular by
random edge swaps (vertices of valence 3 and 4, where a new diagonal may
already be an edge), and ``edgeswap``-like passes over many neighbouring
edges."""
import numpy as np
import pytest

import pyevolver
import pyevolver.remesh.equiangulate as EQ
from pyevolver.model.records import along_first, vertex_edge_rank
from pyevolver.remesh import flip_rounds as FR
from pyevolver.studies.meshes import icosahedron


def _icosphere(level):
    X, F = icosahedron()                        # all counter-clockwise from outside
    for _ in range(level):
        X = list(map(tuple, X))
        mid = {}

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                v = (np.array(X[a]) + np.array(X[b])) / 2
                X.append(tuple(v / np.linalg.norm(v)))
                mid[k] = len(X) - 1
            return mid[k]
        G = []
        for a, b, c in F:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            G += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        X, F = np.array(X), np.array(G)
    return X, F


def _surface(level, seed, jitter=0.3, tmp_path=None):
    """A jittered icosphere (tangential moves of ``jitter`` mean edge
    lengths) whose vertices, edges and facets are numbered at random."""
    rng = np.random.default_rng(seed)
    X, F = _icosphere(level)
    n = len(X)
    pv = rng.permutation(n)
    X = X[np.argsort(pv)]
    F = pv[F][rng.permutation(len(F))]
    h = np.linalg.norm(X[F[:, 0]] - X[F[:, 1]], axis=1).mean()
    d = rng.normal(size=X.shape)
    d -= (d * X).sum(1)[:, None] * X
    X = X + jitter * h * d / np.linalg.norm(d, axis=1)[:, None]
    X /= np.linalg.norm(X, axis=1)[:, None]
    # edges in a random order, as a datafile lists them
    und = {}
    for f in F:
        for k in range(3):
            a, b = int(f[k]), int(f[(k + 1) % 3])
            und.setdefault((min(a, b), max(a, b)), None)
    keys = list(und)
    order = rng.permutation(len(keys))
    keys = [keys[i] for i in order]
    eid = {k: i for i, k in enumerate(keys)}
    lines = ["vertices"] + [f"{i + 1} {x:.17g} {y:.17g} {z:.17g}" for i, (x, y, z) in enumerate(X)]
    lines += ["", "edges"] + [f"{i + 1} {a + 1} {b + 1}" for i, (a, b) in enumerate(keys)]
    lines += ["", "faces"]
    for i, f in enumerate(F):
        sides = []
        for k in range(3):
            a, b = int(f[k]), int(f[(k + 1) % 3])
            e = eid[(min(a, b), max(a, b))] + 1
            sides.append(str(e if a < b else -e))
        lines.append(f"{i + 1} " + " ".join(sides))
    path = tmp_path / f"sphere_{level}_{seed}.fe"
    path.write_text("\n".join(lines) + "\n")
    return pyevolver.load(str(path)).surface


def _reference(s, threshold=-0.001, only=None):
    """The sequential pass, plainly: (E, FE, number of flips)."""
    E, FE = s.E.copy(), s.FE.copy()
    nv, ne = s.nv, s.ne
    where = [[] for _ in range(ne)]
    for f in range(s.nf):
        for k in range(3):
            x = int(FE[f, k])
            where[x if x >= 0 else ~x].append(f)
    fac = [(w[0], w[-1]) if len(w) == 2 else None for w in where]
    ok = [fac[e] is not None and not s.eattr["fixed"][e] and (only is None or only[e])
          for e in range(ne)]
    L = np.linalg.norm(s.X[E[:, 1]] - s.X[E[:, 0]], axis=1)
    first = along_first(s)
    pairs = {(min(a, b), max(a, b)) for a, b in E.tolist()}
    flips = 0

    def u(x):
        return x if x >= 0 else ~x

    def head(x):
        return int(E[x, 1]) if x >= 0 else int(E[~x, 0])
    for e in range(ne):
        if not ok[e]:
            continue
        fa, fb = fac[e]
        ka = [u(int(x)) for x in FE[fa]].index(e)
        kb = [u(int(x)) for x in FE[fb]].index(e)
        if FE[fa, ka] < 0:
            fa, fb, ka, kb = fb, fa, kb, ka
        if FE[fa, ka] < 0 or FE[fb, kb] >= 0:
            continue
        b1, c1 = int(FE[fa, (ka + 1) % 3]), int(FE[fa, (ka + 2) % 3])
        b2, c2 = int(FE[fb, (kb + 1) % 3]), int(FE[fb, (kb + 2) % 3])
        if np.isfinite(threshold):
            a, lb, lc, ld, le = L[e], L[u(b1)], L[u(c1)], L[u(b2)], L[u(c2)]
            with np.errstate(all="ignore"):
                crit = ((lb * lb + lc * lc - a * a) / (lb * lc)
                        + (ld * ld + le * le - a * a) / (ld * le))
            if not crit < threshold:
                continue
        r, sv = head(b1), head(b2)
        if r == sv or (min(r, sv), max(r, sv)) in pairs:
            continue
        p, q = int(E[e, 0]), int(E[e, 1])
        pairs.discard((min(p, q), max(p, q)))
        pairs.add((min(r, sv), max(r, sv)))
        if first[e]:
            E[e] = (sv, r)
            FE[fa], FE[fb] = (e, c1, b2), (~e, c2, b1)
            moved = ((b1, fa, fb), (b2, fb, fa))
        else:
            E[e] = (r, sv)
            FE[fa], FE[fb] = (e, c2, b1), (~e, c1, b2)
            moved = ((c1, fa, fb), (c2, fb, fa))
        for x, old, new in moved:
            i = u(x)
            if fac[i] is not None:
                fac[i] = tuple(new if f == old else f for f in fac[i])
        d = s.X[r] - s.X[sv]
        L[e] = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        flips += 1
    return E, FE, flips


@pytest.fixture
def counted(monkeypatch):
    """Counts of the rounds' calls and of those that left the pass to the
    sequential visits."""
    n = {"calls": 0, "undecided": 0}
    real = EQ.flip_rounds

    def wrapped(*a, **k):
        out = real(*a, **k)
        n["calls"] += 1
        n["undecided"] += out is None
        return out
    monkeypatch.setattr(EQ, "flip_rounds", wrapped)
    return n


def _sequential_only(monkeypatch, s, **kw):
    with monkeypatch.context() as m:
        m.setattr(EQ, "flip_rounds", lambda *a, **k: None)
        return EQ.equiangulate(s, **kw)


def _same(s, t, n, ref, seq):
    E, FE, flips = ref
    assert n == flips
    if n == 0:
        assert t is s
        return
    assert np.array_equal(t.E, E) and np.array_equal(t.FE, FE)
    u, m = seq
    assert m == n
    assert np.array_equal(along_first(t), along_first(u))
    assert np.array_equal(vertex_edge_rank(t), vertex_edge_rank(u))


@pytest.mark.parametrize("seed", range(6))
def test_rounds_equal_the_sequential_pass(tmp_path, monkeypatch, counted, seed):
    s = _surface(3 if seed % 2 else 2, seed, tmp_path=tmp_path)
    t, n = EQ.equiangulate(s)
    assert n > 0
    _same(s, t, n, _reference(s), _sequential_only(monkeypatch, s))
    # a second pass on the result (flips where the first pass's flips led)
    t2, n2 = EQ.equiangulate(t)
    _same(t, t2, n2, _reference(t), _sequential_only(monkeypatch, t))
    assert counted["calls"] >= 1


def _swap_passes(s, rng, passes, share, monkeypatch):
    """``passes`` edgeswap-style passes (every flip that passes the
    topological tests, on a random ``share`` of the edges), each checked
    against the plain and the sequential pass; the last surface."""
    for _ in range(passes):
        only = rng.random(s.ne) < share
        ref = _reference(s, np.inf, only)
        t, n = EQ.equiangulate(s, threshold=np.inf, only=only)
        _same(s, t, n, ref, _sequential_only(monkeypatch, s, threshold=np.inf, only=only))
        s = t
    return s


@pytest.mark.parametrize("seed", range(6))
def test_rounds_on_irregular_meshes_and_edgeswap(tmp_path, monkeypatch, counted, seed):
    """Random swaps make vertices of low valence, where a new diagonal may
    already be an edge and a flip may enable or block another far in id
    order: the rounds either agree or leave the pass to the visits."""
    rng = np.random.default_rng(100 + seed)
    s = _surface(2, 50 + seed, jitter=0.5, tmp_path=tmp_path)
    s = _swap_passes(s, rng, 3, 0.6, monkeypatch)
    for k in range(2):
        t, n = EQ.equiangulate(s)
        _same(s, t, n, _reference(s), _sequential_only(monkeypatch, s))
        s = t


def test_some_passes_are_left_to_the_visits(tmp_path, monkeypatch, counted):
    """On meshes full of low-valence vertices the rounds meet pairs they
    cannot order; the result is still the sequential pass's."""
    for seed in range(8):
        rng = np.random.default_rng(seed)
        s = _surface(1, 200 + seed, jitter=0.4, tmp_path=tmp_path)
        _swap_passes(s, rng, 4, 0.8, monkeypatch)
    assert counted["undecided"] >= 1
    assert counted["undecided"] < counted["calls"]


def test_initial_criterion_is_the_visits_sum():
    rng = np.random.default_rng(3)
    X, F = _icosphere(2)
    s = pyevolver.Surface.from_arrays(X + 0.05 * rng.normal(size=X.shape), F)
    from pyevolver.model.records import edge_facets
    ef, ek, val = edge_facets(s)
    L = np.linalg.norm(s.X[s.E[:, 1]] - s.X[s.E[:, 0]], axis=1)
    L[5] = 0.0                                  # IEEE results for zero lengths
    items = np.arange(s.ne)
    got = FR.initial_criterion(s.topology()[0], ef, ek, items, L)
    FEa = s.topology()[0]
    for e in range(s.ne):
        tot = 0.0
        for j in (0, 1):
            row = list(FEa[ef[e, j]])
            k = row.index(e)
            b, c, a = L[row[(k + 1) % 3]], L[row[(k + 2) % 3]], L[e]
            with np.errstate(all="ignore"):
                tot = tot + (b * b + c * c - a * a) / (b * c)
        assert (got[e] == tot) or (np.isnan(got[e]) and np.isnan(tot))


@pytest.mark.parametrize("seed", range(3))
def test_rings_replayed_in_rounds_as_one_by_one(tmp_path, monkeypatch, seed):
    """equiangulate._rings_after_flips replays the flips' ring changes in
    rounds of flips with no vertex in common: the rings of one flip after
    the other in id order."""
    from pyevolver.remesh.rings import Rings
    seen = []
    real = EQ._flip_rings
    monkeypatch.setattr(EQ, "_flip_rings", lambda s, t, moves, E=None: (
        seen.append((s, t, moves)), real(s, t, moves, E))[1])
    s = _surface(3, 300 + seed, jitter=0.5, tmp_path=tmp_path)
    t, n = EQ.equiangulate(s)
    assert n > 20 and len(seen) == 1
    s, t, moves = seen[0]
    got = EQ._rings_after_flips(s, t.E, t.nv, moves)
    g = Rings(s, t.ne, t.nv)
    I = np.concatenate([m[0] for m in moves])
    p = np.concatenate([m[1] for m in moves])
    q = np.concatenate([m[2] for m in moves])
    for k in np.argsort(I, kind="stable"):
        e = I[k:k + 1]
        g.remove(p[k:k + 1], 2 * e)
        g.remove(q[k:k + 1], 2 * e + 1)
        g.insert(t.E[e, 0], 2 * e)
        g.insert(t.E[e, 1], 2 * e + 1)
    assert np.array_equal(got, g.rank())
    assert np.array_equal(vertex_edge_rank(t), got)
