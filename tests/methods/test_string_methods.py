"""pyevolver.methods.string: facet areas and gravity of the string model by
one-dimensional divergence theorems (unit square: area 1, ∬ y dA = 1/2),
their derivatives against central differences, and StringTotals."""
import io
import os

import numpy as np

from tolerances import FD, ROUNDOFF
from pyevolver import Session
from pyevolver.methods import string as ST

DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")
SQUARE = """STRING
SPACE_DIMENSION 2
vertices
1 0 0
2 1 0
3 1 1
4 0 1
edges
1 1 2
2 2 3
3 3 4
4 4 1
faces
1 1 2 3 4
bodies
1 1
"""


def _load(tmp_path, text, name="sq.fe"):
    p = tmp_path / name
    p.write_text(text)
    return Session.load(str(p), out=io.StringIO()).surface


def test_unit_square_area_gravity_and_totals(tmp_path):
    s = _load(tmp_path, SQUARE)
    assert np.allclose(ST.facet_areas(s), [1.0], atol=ROUNDOFF)
    assert np.allclose(ST.facet_gravity(s), [0.5], atol=ROUNDOFF)
    t = s.evaluate()
    assert isinstance(t, ST.StringTotals) and ST.MODEL_TOTALS["string"] is ST.StringTotals
    assert abs(t.total_area - 4.0) <= ROUNDOFF                 # the total length
    assert abs(t.terms["edge_tension"] - 4.0) <= ROUNDOFF
    assert np.allclose(t.volumes, [1.0], atol=ROUNDOFF)
    assert np.allclose(t.volume_magnitudes(), [1.0], atol=ROUNDOFF)
    # the same square traversed backwards has area -1
    rev = SQUARE.replace("1 1 2 3 4\nbodies", "1 -4 -3 -2 -1\nbodies")
    assert np.allclose(ST.facet_areas(_load(tmp_path, rev, "rev.fe")), [-1.0], atol=ROUNDOFF)


def test_edge_term_derivatives_match_central_differences():
    rng = np.random.default_rng(0)
    Pt, Ph = rng.standard_normal((2, 6, 3))
    h = 1e-6
    for derivs, fn in ((ST.area_derivs, ST._edge_area), (ST.gravity_derivs, ST._edge_gravity)):
        gt, gh = derivs(Pt, Ph)
        for k in range(2):
            for which, g in ((0, gt), (1, gh)):
                A, B = [Pt.copy(), Ph.copy()], [Pt.copy(), Ph.copy()]
                A[which][:, k] += h
                B[which][:, k] -= h
                num = (fn(*A) - fn(*B)) / (2 * h)
                assert np.abs(num - g[:, k]).max() <= FD


def test_body_area_gradient_matches_central_differences():
    S = Session.load(os.path.join(DATA, "string_circle.fe"), out=io.StringIO()).surface
    g = ST.body_gradient(S, 0)
    assert np.allclose(ST.volume_gradients(S.evaluate())[0], g)
    assert np.allclose(g[:, 2], 0.0)                  # a plane curve: no z force
    X0 = S.X.copy()
    h = 1e-6
    for i in range(S.nv):
        for k in range(2):
            S.X = X0.copy(); S.X[i, k] += h
            ap = ST.facet_areas(S)[0]
            S.X = X0.copy(); S.X[i, k] -= h
            am = ST.facet_areas(S)[0]
            assert abs((ap - am) / (2 * h) - g[i, k]) <= FD
    S.X = X0
    # a translation keeps the area: the forces sum to zero
    assert np.allclose(g[:, :2].sum(0), 0.0, atol=ROUNDOFF * 10)
