"""Direct tests of pyevolver.remesh.refine: ``refine`` and ``split_edges``
on a Surface (counts V+E, 2E+3F, 4F; flat faces keep area and volume)."""
import os

import numpy as np
import pytest

import pyevolver
from comparison import consistent
from pyevolver.remesh.refine import refine, split_edges
from tolerances import ROUNDOFF

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def _cube():
    return pyevolver.load(CUBE).surface


def _euler(s):
    return s.nv - s.ne + s.nf


def test_refine_counts_and_keeps_cube_area_volume():
    s = _cube()
    nv, ne, nf = s.nv, s.ne, s.nf
    t = refine(s)
    assert (t.nv, t.ne, t.nf) == (nv + ne, 2 * ne + 3 * nf, 4 * nf)
    consistent(t)
    assert _euler(t) == _euler(s) == 2
    tot = t.evaluate()
    # flat faces: subdividing them changes neither area nor volume
    assert tot.total_area == pytest.approx(6.0, rel=ROUNDOFF)
    assert tot.volumes[0] == pytest.approx(1.0, rel=ROUNDOFF)
    # every facet a quarter of its parent (cube.fe: 24 congruent triangles)
    assert np.allclose(tot.facet_area, 6.0 / 96, rtol=ROUNDOFF)


def test_refine_new_vertices_are_edge_midpoints_and_input_untouched():
    s = _cube()
    X0, E0, FE0 = s.X.copy(), s.E.copy(), s.FE.copy()
    t = refine(s)
    mids = 0.5 * (X0[E0[:, 0]] + X0[E0[:, 1]])
    assert np.allclose(t.X[s.nv:], mids, atol=ROUNDOFF)
    assert np.array_equal(t.X[:s.nv], X0)
    # the original surface is left as it was (the session can restore it)
    assert np.array_equal(s.X, X0) and np.array_equal(s.E, E0) and np.array_equal(s.FE, FE0)
    # every edge is halved: the tail half keeps the edge id, the head half is new
    assert np.array_equal(t.E[:s.ne, 0], E0[:, 0])
    assert np.array_equal(t.E[s.ne:2 * s.ne, 1], E0[:, 1])


def test_refine_twice_quadruples_again():
    t = refine(refine(_cube()))
    assert t.nf == 24 * 16
    consistent(t)
    assert _euler(t) == 2
    assert t.evaluate().total_area == pytest.approx(6.0, rel=ROUNDOFF)


def test_split_one_edge_bisects_its_two_facets():
    s = _cube()
    mask = np.zeros(s.ne, bool)
    mask[0] = True
    t = split_edges(s, mask)
    # one new vertex, the new half plus one cut per facet on the edge
    assert (t.nv, t.ne, t.nf) == (s.nv + 1, s.ne + 3, s.nf + 2)
    consistent(t)
    assert _euler(t) == 2
    assert np.allclose(t.X[s.nv], 0.5 * (s.X[s.E[0, 0]] + s.X[s.E[0, 1]]))
    tot = t.evaluate()
    assert tot.total_area == pytest.approx(6.0, rel=ROUNDOFF)
    assert tot.volumes[0] == pytest.approx(1.0, rel=ROUNDOFF)


def test_no_refine_edges_are_not_split():
    s = _cube()
    s.eattr["no_refine"] = s.eattr["no_refine"].copy()
    s.eattr["no_refine"][:] = True
    t = refine(s)
    assert (t.nv, t.ne, t.nf) == (s.nv, s.ne, s.nf)
    consistent(t)


def _datafiles():
    here = os.path.dirname(__file__)
    names = sorted(os.path.join(here, "..", "data", f)
                   for f in os.listdir(os.path.join(here, "..", "data")) if f.endswith(".fe"))
    ex = "/usr/share/doc/evolver/examples"
    if os.path.isdir(ex):
        names += sorted(os.path.join(ex, f) for f in os.listdir(ex) if f.endswith(".fe"))
    return [CUBE] + names


def _same_surface(a, b):
    from pyevolver.model.records import along_first, vertex_edge_rank
    for name in ("X", "E", "FE"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and np.array_equal(x, y), name
    for d in ("vattr", "eattr", "fattr", "vcon", "econ", "fcon"):
        x, y = getattr(a, d), getattr(b, d)
        assert x.keys() == y.keys() and all(np.array_equal(x[k], y[k]) for k in x), d
    assert np.array_equal(along_first(a), along_first(b))
    assert np.array_equal(vertex_edge_rank(a), vertex_edge_rank(b))
    x, y = a.bodies, b.bodies
    assert x.n == y.n and (x.volume is None) == (y.volume is None)
    if x.n:
        for k in ("data", "indices", "indptr"):
            p, q = np.asarray(getattr(x.facet_csr, k)), np.asarray(getattr(y.facet_csr, k))
            assert p.dtype == q.dtype and np.array_equal(p, q), k
        assert x.facet_csr.shape == y.facet_csr.shape
        for p, q in zip(x.occurrences, y.occurrences):
            assert p.dtype == q.dtype and np.array_equal(p, q)
    for k in vars(y):
        if k not in ("_facet_matrix", "occurrences", "volume"):
            p, q = getattr(x, k), getattr(y, k)
            assert (p is q) or np.array_equal(p, q, equal_nan=True), k


def test_refine_every_edge_is_split_edges_general_path(monkeypatch):
    """``r``'s slices (refine._split_every_edge) make what the general
    split makes (``order`` given takes the general path), on every datafile
    it applies to; the topology it keeps is what Surface.topology computes."""
    import importlib
    RF = importlib.import_module("pyevolver.remesh.refine")
    fast = []
    real = RF._split_every_edge
    monkeypatch.setattr(RF, "_split_every_edge", lambda s: fast.append(1) or real(s))
    done = 0
    for path in _datafiles():
        try:
            s = pyevolver.load(path).surface
        except Exception:
            continue
        if s.string or s.simplex or s.order != 1 or not s.nf or s.eattr["no_refine"].any() \
                or "wrap" in s.eattr or s.symmetry_group is not None:
            continue
        t = refine(s)
        u = split_edges(s, np.ones(s.ne, bool), order=np.arange(s.ne))
        _same_surface(t, u)
        kept = t.__dict__["_topo"]
        assert kept[0] is t.FE and kept[1] is t.E
        t.__dict__.pop("_topo")
        for x, y in zip(kept[2], t.topology()):
            assert x.dtype == y.dtype and np.array_equal(x, y)
        assert np.allclose(t.evaluate().total_area, u.evaluate().total_area, rtol=0, atol=0)
        done += 1
    assert done >= 5 and len(fast) == done      # (the path tested, each time)
