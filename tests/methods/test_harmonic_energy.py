"""pyevolver.methods.harmonic: the edge energy E = (1/√3) Σ |e|², its
gradient against central differences and its Hessian (symmetric, exact
for the quadratic energy: H v equals the difference of gradients)."""
import numpy as np

from tolerances import FD, ROUNDOFF
import pyevolver
from pyevolver.methods import harmonic as H
from pyevolver.methods.registry import lookup

OCT_X = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
OCT_F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def _octahedron(seed=0):
    rng = np.random.default_rng(seed)
    return pyevolver.Surface.from_arrays(OCT_X + 0.1 * rng.standard_normal(OCT_X.shape), OCT_F,
                                         body=True)


def _energy(s, w):
    t = s.evaluate()
    return float(w @ H.values(t, None, np.arange(s.ne)))


def test_values_are_squared_lengths_over_sqrt3():
    s = pyevolver.Surface.from_arrays(OCT_X, OCT_F, body=True)
    t = s.evaluate()
    v = H.values(t, None, np.arange(s.ne))
    assert s.ne == 12
    # every octahedron edge has |e|² = 2
    assert np.allclose(v, 2.0 / np.sqrt(3.0), rtol=0, atol=ROUNDOFF)
    assert abs(v.sum() - 24.0 / np.sqrt(3.0)) <= ROUNDOFF * 24
    assert lookup("harmonic_energy").etype == "edge"
    assert lookup("harmonic_energy").value is H.values


def test_gradient_matches_central_differences():
    s = _octahedron(1)
    w = np.linspace(0.5, 2.0, s.ne)
    g = H.gradient(s.evaluate(), None, np.arange(s.ne), w)
    X0 = s.X.copy()
    h = 1e-6
    num = np.zeros_like(g)
    for i in range(s.nv):
        for k in range(3):
            s.X = X0.copy(); s.X[i, k] += h
            ep = _energy(s, w)
            s.X = X0.copy(); s.X[i, k] -= h
            em = _energy(s, w)
            num[i, k] = (ep - em) / (2 * h)
    s.X = X0
    assert np.abs(g - num).max() <= FD * max(1.0, np.abs(g).max())
    # a translation does not change E: the forces sum to zero
    assert np.allclose(g.sum(axis=0), 0.0, atol=ROUNDOFF * 100)


def test_hessian_symmetric_and_exact_on_a_quadratic():
    s = _octahedron(2)
    idx = np.arange(s.ne)
    w = np.linspace(1.0, 3.0, s.ne)
    Hm = H.hessian(s.evaluate(), None, idx, w).tocsr()
    assert Hm.shape == (3 * s.nv, 3 * s.nv)
    D = Hm.toarray()
    assert np.abs(D - D.T).max() <= ROUNDOFF
    g0 = H.gradient(s.evaluate(), None, idx, w)
    v = np.random.default_rng(3).standard_normal((s.nv, 3))
    s.X = s.X + v
    g1 = H.gradient(s.evaluate(), None, idx, w)
    # E is quadratic: g(x + v) - g(x) = H v exactly
    assert np.abs(D @ v.ravel() - (g1 - g0).ravel()).max() <= 1e-10
    # the constant blocks (2/√3) w [[I, -I], [-I, I]]: diagonal = (2/√3) Σ w over the star
    deg_w = np.bincount(s.E.ravel(), weights=np.repeat(w, 2), minlength=s.nv)
    assert np.allclose(np.diag(D).reshape(-1, 3), (2 / np.sqrt(3) * deg_w)[:, None],
                       atol=ROUNDOFF * 10)
