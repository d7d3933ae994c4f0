"""pyevolver.remesh.simplex: ``r`` in the simplex model, its counts, its
invariants (area, volume, orientation) and REF's numbering (live)."""
import io
import os
import re

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.geometry import simplex as GS
from pyevolver.remesh import simplex as RS

from conftest import example
from reference import run_reference

DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")
EX = example("simplex3.fe")


def _session(path):
    return Session.load(path, out=io.StringIO(), err=io.StringIO())


def _perturbed(tmp_path, path, seed=5, amount=0.2):
    """``path`` with its vertices moved at random (so that REF's sort order
    of the corners is not the coordinates')."""
    text = open(path).read()
    rng = np.random.default_rng(seed)

    def move(m):
        nums = [float(v) + amount * rng.normal() for v in m.group(2).split()]
        return m.group(1) + " ".join(repr(v) for v in nums)
    head, rest = text.split("vertices", 1)
    verts, tail = rest.split("faces", 1)
    verts = re.sub(r"(?m)^(\s*\d+\s+)((?:[-\d.]+\s*?)+?)(?=\s*(?:fixed)?$)", move, verts)
    p = tmp_path / os.path.basename(path)
    p.write_text(head + "vertices" + verts + "faces" + tail)
    return str(p)


@pytest.mark.skipif(not os.path.exists(EX), reason="evolver-doc examples not installed")
def test_counts_and_invariants():
    s = _session(EX)
    t0 = s.surface.evaluate()
    s.run("r")
    s1 = s.surface
    assert (s1.nv, s1.n_facets) == (15, 40)
    t1 = s1.evaluate()
    assert t1.total_area == pytest.approx(t0.total_area)
    assert t1.volumes == pytest.approx(t0.volumes)
    # every child has its parent's orientation: its cone content over the
    # parent's centroid has the parent's sign
    kids = np.concatenate([np.arange(5), 5 + np.arange(35)])
    parent = np.concatenate([np.arange(5), np.repeat(np.arange(5), 7)])
    c = s1.X[s1.SF[parent]].mean(axis=1)[:, None, :]
    assert np.all(GS.cone_contents(s1.X[s1.SF[kids]] - c + 0.0) >= -1e-15)
    s.run("r")
    assert (s.surface.nv, s.surface.n_facets) == (70, 320)
    assert s.settings["scale_limit"] == 4          # REF doubles it per r when k = 3


def test_templates_cover_the_simplex():
    for k, kids in RS.TEMPLATES.items():
        assert len(kids) == 2 ** k
        pairs, cols = RS._columns(k)
        assert cols.shape == (2 ** k, k + 1) and len(pairs) == k * (k + 1) // 2
        # the children of the standard simplex fill it: their volumes add up
        P = np.vstack([np.zeros(k), np.eye(k)])
        pts = np.vstack([P, 0.5 * (P[pairs[:, 0]] + P[pairs[:, 1]])])
        vol = GS.simplex_areas(GS.simplex_sides(pts[cols]))
        assert vol.sum() == pytest.approx(GS.simplex_areas(GS.simplex_sides(P[None]))[0])
        assert np.allclose(vol, vol[0])


def test_odd_permutations():
    perm = np.array([[0, 1, 2], [1, 0, 2], [2, 0, 1], [0, 2, 1]])
    assert RS._odd(perm).tolist() == [False, True, False, True]


def _facet_lines(lines):
    return [ln.split("/*")[0].split() for ln in lines if re.match(r"^\s*\d+\s+\d+\s+\d+", ln)
            and "/*area" in ln]


@pytest.mark.parametrize("name,moved", [("simplex3", False), ("simplex3", True),
                                        ("simplex_tetra", True), ("simplex_4d", True)])
def test_numbering_as_reference(evolver, tmp_path, name, moved):
    """``r; r`` then ``list facets`` and ``list vertices``: the same facets,
    vertex lists (in order) and coordinates as REF."""
    path = EX if name == "simplex3" else os.path.join(DATA, name + ".fe")
    if moved:
        path = _perturbed(tmp_path, path)
    cmds = "r\nr\nlist facets\nlist vertices"
    ref = run_reference(evolver, path, cmds, cwd=str(tmp_path))
    out = io.StringIO()
    s = Session.load(path, out=out, err=io.StringIO())
    s.run(cmds)
    ours = out.getvalue().splitlines()
    assert _facet_lines(ours) == _facet_lines(ref)
    num = re.compile(r"^\s*\d+(\s+[-\d.e+]+){3,}\s*$")
    rv = [[float(v) for v in ln.split()] for ln in ref if num.match(ln)]
    ov = [[float(v) for v in ln.split()] for ln in ours if num.match(ln)]
    assert len(rv) == len(ov) and np.allclose(rv, ov, atol=1e-14)


def test_refused_dimensions():
    class S:
        simplex = 5
    with pytest.raises(Exception, match="simplex model of dimension 5"):
        RS.refine(S())


def test_midpoints_keep_common_constraints():
    s = _session(os.path.join(DATA, "simplex_constraint.fe"))
    s.run("r")
    on = s.surface.vcon[1]
    # vertices 1..4 are on x4 = 0.1 x1; the midpoints 12 (1-4), 13 (1-3), 15 (1-2)
    # and 6 (3-4), 8 (2-4), 10 (2-3) too, those towards vertex 5 not (REF)
    assert np.nonzero(on)[0].tolist() == [0, 1, 2, 3, 5, 7, 9, 11, 12, 14]
    X = s.surface.X
    assert np.allclose(X[on, 3], 0.1 * X[on, 0])
