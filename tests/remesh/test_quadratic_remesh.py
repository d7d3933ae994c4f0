"""M 2 / M 1 conversions, r in the quadratic model and QUADRATIC datafiles
(pyevolver.remesh.quadratic): counts, midpoint placement, inheritance."""
import numpy as np
import pytest

import pyevolver
from comparison import consistent
from conftest import example
from pyevolver.errors import UnsupportedError
from pyevolver.geometry import quadratic as Q
from pyevolver.remesh.quadratic import from_listed, refine_quadratic, to_linear, to_quadratic
from tolerances import ROUNDOFF


def test_m2_m1_round_trip_on_cube():
    s = pyevolver.load(example("cube.fe")).surface
    q = to_quadratic(s)
    consistent(q)
    assert (q.nv, q.ne, q.nf, q.order) == (s.nv + s.ne, s.ne, s.nf, 2)
    # midpoint of edge e is vertex nv + e, at the middle of the chord; ids follow
    assert np.allclose(q.X[q.midv], 0.5 * (s.X[s.E[:, 0]] + s.X[s.E[:, 1]]))
    assert list(q.ids("vertex")[q.midv][:3]) == [s.nv + 1, s.nv + 2, s.nv + 3]
    back = to_linear(q)
    consistent(back)
    assert back.order == 1 and np.array_equal(back.X, s.X) and back.nv == s.nv


def test_midpoints_inherit_fixed_and_constraints():
    s = pyevolver.load(example("mound.fe")).surface
    q = to_quadratic(s)
    assert np.array_equal(q.vattr["fixed"][q.midv], s.eattr["fixed"])
    on = s.econ[1] != 0
    assert np.array_equal(q.vcon[1][q.midv], on)
    assert np.allclose(q.X[q.midv][on, 2], 0.0)


def test_refine_counts_and_points_on_the_old_patches():
    s = to_quadratic(pyevolver.load(example("cube.fe")).surface)
    s.X = s.X + 0.02 * np.random.default_rng(0).standard_normal(s.X.shape)
    area = s.evaluate().total_area
    t = refine_quadratic(s)
    consistent(t)
    V, E, F = s.nv - s.ne, s.ne, s.nf
    assert (t.nv, t.ne, t.nf) == (V + E + 2 * E + 3 * F, 2 * E + 3 * F, 4 * F)
    # the old midpoints are corners now, the halves' midpoints on the old curves
    assert np.allclose(t.X[V:V + E], s.X[s.midv])
    curves = s.X[np.concatenate([s.E, s.midv[:, None]], axis=1)]
    quarter = np.einsum("c,ncd->nd", Q.edge3_shape(np.array([0.25]))[0][0], curves)
    assert np.allclose(t.X[t.midv[:E]], quarter)
    # the refined surface lies on the old patches, so its area is close
    assert abs(t.evaluate().total_area - area) < 1e-3 * area


def test_refine_keeps_no_refine_edges_with_their_midpoints():
    s = to_quadratic(pyevolver.load(example("mound.fe")).surface)
    t = refine_quadratic(s)
    consistent(t)
    keep = np.nonzero(s.eattr["no_refine"])[0]
    assert len(keep) == 8          # the table top: its 4 sides and 4 spokes
    assert np.allclose(t.X[t.midv[keep]], s.X[s.midv[keep]])


TRI = """QUADRATIC
vertices
1 0 0 0
2 1 0 0
3 0 1 0
4 0.5 -0.1 0.2
5 0.6 0.5 0.3
edges
1 1 2 4
2 2 3 5
3 3 1
faces
1 1 2 3
"""


def test_quadratic_datafile_lists_midpoints(tmp_path):
    # REF prints 0.770474878769362 for this patch with all three midpoints
    p = tmp_path / "tri.fe"
    p.write_text(TRI.replace("3 3 1\n", "3 3 1 6\n").replace("5 0.6 0.5 0.3\n",
                                                            "5 0.6 0.5 0.3\n6 -0.1 0.5 0.1\n"))
    s = pyevolver.load(str(p)).surface
    assert s.order == 2 and s.nv == 6
    assert abs(s.evaluate().total_area - 0.770474878769362) < 1e-14
    # an edge listing no midpoint gets one at its chord's middle
    p.write_text(TRI)
    s = pyevolver.load(str(p)).surface
    assert np.allclose(s.X[s.midv[2]], [0, 0.5, 0])
    assert list(s.ids("vertex")[s.midv]) == [4, 5, 6]


def test_refusals():
    s = pyevolver.load(example("twointor.fe")).surface
    with pytest.raises(UnsupportedError, match="torus"):
        to_quadratic(s)
    s = pyevolver.load(example("cube.fe")).surface
    s.listed_midpoints = np.array([s.E[1, 0]] + [-1] * (s.ne - 1))
    with pytest.raises(UnsupportedError, match="midpoint"):
        from_listed(s)
    assert ROUNDOFF > 0


def test_refine_refuses_partly_split_facets(tmp_path):
    # REF places the midpoints of the edges cutting such facets elsewhere
    text = open(example("cube.fe")).read().replace("\n1   1 2   \n", "\n1   1 2 no_refine\n")
    p = tmp_path / "c.fe"
    p.write_text(text)
    s = to_quadratic(pyevolver.load(str(p)).surface)
    assert s.eattr["no_refine"].sum() == 1
    with pytest.raises(UnsupportedError, match="NO_REFINE"):
        refine_quadratic(s)
