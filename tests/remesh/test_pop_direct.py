"""Direct tests of pyevolver.remesh.pop.pop_edges on a Surface: octa.fe's
four-facet edges are popped (+2 vertices, +8 edges, +6 facets each)."""
import numpy as np
import pytest

import pyevolver
from comparison import consistent
from conftest import EXAMPLES, example
from pyevolver.errors import UnsupportedError
from pyevolver.remesh.pop import pop_edges

pytestmark = pytest.mark.skipif(not __import__("os").path.isdir(EXAMPLES),
                                reason="Evolver examples not installed")


def _valence(s):
    return np.bincount(np.where(s.FE >= 0, s.FE, ~s.FE).ravel(), minlength=s.ne)


def test_pop_octa_counts_and_invariants():
    s = pyevolver.load(example("octa.fe")).surface
    k = int(np.count_nonzero(_valence(s) == 4))
    assert k == 6
    t, n = pop_edges(s)
    assert n == k
    assert (t.nv, t.ne, t.nf) == (s.nv + 2 * k, s.ne + 8 * k, s.nf + 6 * k)
    consistent(t)
    val = _valence(t)
    assert val.max() <= 3                 # no four-facet edge left
    # each pop leaves the two new triple edges a-M1-b and a-M2-b
    assert np.count_nonzero(val == 3) >= 2 * k
    # the input is not modified
    assert (s.nv, s.ne, s.nf) == (7, 18, 12)


def test_pop_single_quadruple_edge_geometry():
    # four unit triangles round the edge (0,0,0)-(0,0,1), in the +x, +y,
    # -x, -y directions: M1 at the midpoint, M2 nudged into a wedge
    X = np.array([[0, 0, 0], [0, 0, 1], [1, 0, .5], [0, 1, .5], [-1, 0, .5],
                  [0, -1, .5]], float)
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 0, 5]])
    s = pyevolver.Surface.from_arrays(X, F)
    t, n = pop_edges(s)
    assert n == 1
    assert (t.nv, t.ne, t.nf) == (8, 9 + 8, 10)
    consistent(t)
    new = t.X[6:]
    mid = np.array([0, 0, .5])
    d = np.sort(np.linalg.norm(new - mid, axis=1))
    assert d[0] == pytest.approx(0.0, abs=1e-15)
    # 0.005 |b - a| (u_p + u_q) with u_p, u_q perpendicular unit vectors
    assert d[1] == pytest.approx(0.005 * np.sqrt(2), rel=1e-12)
    assert _valence(t).max() == 3


def test_pop_without_quadruple_edges_returns_input():
    X = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    s = pyevolver.Surface.from_arrays(X, np.array([[0, 1, 2]]))
    t, n = pop_edges(s)
    assert n == 0 and t is s


def test_pop_refuses_string_model():
    s = pyevolver.load(example("popstr.fe")).surface
    with pytest.raises(UnsupportedError):
        pop_edges(s)
