"""``O`` (pop edges with four facets, pyevolver.remesh.pop) against
evolver-nox-d, run live: the whole listing after the pop (coordinates to
1e-12, edge and facet numbering and orientation exactly), the area, and the
``g`` lines that follow; refusals of what was not checked.
"""
import io
import re

import numpy as np
import pytest
from conftest import example
from reference import run_reference
from comparison import consistent

from pyevolver import Session
from pyevolver.errors import PyEvolverError

LISTING = "O\nlist vertices\nlist edges\nlist facets\nprintf \"RESULT %.17g\\n\", total_area"


def _rows(lines):
    """Listing lines as token lists, ``fixed`` dropped (pyevolver prints it
    after the length comment), numbers as floats."""
    out = []
    for ln in lines:
        toks = [t for t in re.split(r"[\s/*]+|length|area", ln) if t and t != "fixed"]
        if toks:
            out.append(toks)
    return out


def _same(a, b, tol=1e-12):
    assert len(a) == len(b), (a, b)
    for ra, rb in zip(a, b):
        assert len(ra) == len(rb), (ra, rb)
        for x, y in zip(ra, rb):
            if x == y:
                continue
            fx, fy = float(x), float(y)
            assert abs(fx - fy) <= tol * max(1.0, abs(fy)), (ra, rb)


def _ours(path, cmds):
    out = io.StringIO()
    s = Session.load(path, out=out)
    s.run(cmds)
    return s, out.getvalue().rstrip("\n").split("\n")


def _write_fe(path, verts, faces, free_edge):
    """A datafile of fixed vertices and triangles; every edge but
    ``free_edge`` (a vertex pair) FIXED; edges numbered as first met."""
    edges, lines_e, lines_f = {}, [], []
    for f in faces:
        es = []
        for i in range(3):
            a, b = f[i], f[(i + 1) % 3]
            if (b, a) in edges:
                es.append(-edges[(b, a)])
                continue
            if (a, b) not in edges:
                edges[(a, b)] = len(edges) + 1
                fx = "" if {a, b} == set(free_edge) else " fixed"
                lines_e.append(f"{edges[(a, b)]} {a} {b}{fx}")
            es.append(edges[(a, b)])
        lines_f.append(f"{len(lines_f) + 1} " + " ".join(map(str, es)))
    text = ["vertices"] + [f"{i} {x!r} {y!r} {z!r} fixed" for i, (x, y, z) in
                           enumerate(verts, 1)]
    text += ["edges"] + lines_e + ["faces"] + lines_f
    path.write_text("\n".join(text) + "\n")
    return str(path)


def _random_edge(rng, tmp_path, k):
    """Four fixed triangles of random shape and orientation on one free edge."""
    a = rng.uniform(-1, 1, 3)
    b = a + np.array([rng.uniform(0.5, 3), *rng.uniform(-1, 1, 2)])
    d = (b - a) / np.linalg.norm(b - a)
    p = np.cross(d, [0.3, 0.5, 0.7])
    p /= np.linalg.norm(p)
    q = np.cross(d, p)
    verts = [tuple(a), tuple(b)]
    for t in np.sort(rng.uniform(0, 2 * np.pi, 4)):
        r, s = rng.uniform(0.5, 3), rng.uniform(-0.5, 1.5)
        verts.append(tuple(a + s * (b - a) + r * (np.cos(t) * p + np.sin(t) * q)))
    faces = [(1, 2, 3 + j) if rng.random() < 0.5 else (2, 1, 3 + j) for j in range(4)]
    faces = [faces[j] for j in rng.permutation(4)]
    return _write_fe(tmp_path / f"edge{k}.fe", [tuple(map(float, v)) for v in verts],
                     faces, (1, 2))


def test_pop_edges_on_octa_matches_reference(evolver, tmp_path):
    """octa.fe: six four-facet edges meeting at the centre; equal angles
    (ties) on three of them, decided by the facet loop's start."""
    ref = [ln for ln in run_reference(evolver, example("octa.fe"), LISTING, cwd=str(tmp_path))
           if ln.strip()]
    s, ours = _ours(example("octa.fe"), LISTING)
    assert ref[0] == ours[0] == "Edges popped: 6"
    _same(_rows(ours), _rows(ref))
    t = s.surface
    consistent(t)
    assert (t.nv, t.ne, t.nf) == (19, 66, 48)
    # every edge now has at most three facets
    a = np.where(t.FE >= 0, t.FE, ~t.FE).ravel()
    assert np.bincount(a).max() == 3


def test_pop_then_g_follows_reference(evolver, tmp_path):
    """``g 2; O; g 3; O``: the pop after motion (the loop start survives
    ``g``), the g lines after it, and a second O that finds nothing."""
    cmds = "g 2\nO\ng 3\nO\nprint edge_pop_count"
    ref = run_reference(evolver, example("octa.fe"), cmds, cwd=str(tmp_path))
    _, ours = _ours(example("octa.fe"), cmds)
    assert [l for l in ours if "popped" in l] == [l for l in ref if "popped" in l] \
        == ["Edges popped: 6", "Edges popped: 0"]
    assert ours[-1].split() == ref[-1].split() == ["0"]
    num = re.compile(r"area:\s*(\S+)\s+energy:\s*(\S+)")
    ra = [tuple(map(float, m.groups())) for m in map(num.search, ref) if m]
    oa = [tuple(map(float, m.groups())) for m in map(num.search, ours) if m]
    assert len(ra) == len(oa) == 5
    for x, y in zip(oa, ra):
        assert abs(x[0] - y[0]) <= 1e-9 * y[0] and abs(x[1] - y[1]) <= 1e-9 * y[1]


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_pop_random_edges_match_reference(evolver, tmp_path, seed):
    """Single four-facet edges of random shape, facet order and facet
    orientation: the chosen pair, positions, numbering and orientations."""
    path = _random_edge(np.random.default_rng(seed), tmp_path, seed)
    ref = [ln for ln in run_reference(evolver, path, LISTING, cwd=str(tmp_path)) if ln.strip()]
    s, ours = _ours(path, LISTING)
    assert ref[0] == ours[0] == "Edges popped: 1"
    _same(_rows(ours), _rows(ref))
    consistent(s.surface)


def test_offset_is_proportional_to_the_edge_length(tmp_path):
    """The offset vertex sits 0.005 L (u_p + u_q) off the midpoint (REF on
    octa.fe scaled by 10 and 0.1 prints the same digits scaled)."""
    pos = []
    for scale in (1.0, 10.0):
        verts = [(0, 0, 0), (2 * scale, 0, 0), (0.5, 2, 0), (0.3, 0, -3), (0.7, 0, 1.5),
                 (0.4, -1, 0)]
        path = _write_fe(tmp_path / f"s{scale}.fe", [tuple(map(float, v)) for v in verts],
                         [(1, 2, 3), (1, 2, 4), (2, 1, 5), (1, 2, 6)], (1, 2))
        s, _ = _ours(path, "O")
        pos.append(s.surface.X[7] - s.surface.X[6])
    # u = +y and +z exactly: offset 0.005 * 2 * scale * (0, 1, 1)
    assert np.allclose(pos[0], [0, 0.01, 0.01], atol=1e-15)
    assert np.allclose(pos[1], [0, 0.1, 0.1], atol=1e-14)


def _refused(path, cmds, what):
    s = Session.load(path, out=io.StringIO())
    before = (s.surface.nv, s.surface.ne, s.surface.nf)
    *pre, last = cmds.split("\n")
    if pre:
        s.run("\n".join(pre))
        before = (s.surface.nv, s.surface.ne, s.surface.nf)
    with pytest.raises(PyEvolverError, match=what):
        s.run(last)
    assert (s.surface.nv, s.surface.ne, s.surface.nf) == before


def test_unchecked_configurations_are_refused(tmp_path):
    octa = example("octa.fe")
    # a multiple edge through a vertex (after r: REF pops the chain, adding
    # one vertex per chain)
    _refused(octa, "r\nO", "continuing through a vertex")
    # equal angles after an operation that does not record the loop start
    _refused(octa, "refine edges where id == 1\nO", "angles tie")
    # five facets (REF pops twice)
    verts = [(0, 0, 0), (1, 0, 0), (0.5, 2, 0), (0.3, 0, 3), (0.7, -1.5, 0), (0.4, 0.2, -1),
             (0.2, -1, 1)]
    path = _write_fe(tmp_path / "five.fe", [tuple(map(float, v)) for v in verts],
                     [(1, 2, 3), (1, 2, 4), (2, 1, 5), (1, 2, 6), (1, 2, 7)], (1, 2))
    _refused(path, "O", "more than four facets")
    # a FIXED four-facet edge (REF stops without a word)
    fixed = tmp_path / "octa_fixed.fe"
    with open(octa) as fh:
        text = fh.read()
    fixed.write_text(text.replace("\n13  1  2\n", "\n13  1  2 fixed\n"))
    _refused(str(fixed), "O", "FIXED edge")
    # o refuses what O refuses (and leaves the surface as it was); autopop stays refused
    _refused(str(fixed), "o", "FIXED edge")
    _refused(octa, "autopop", "autopop")


def test_nothing_to_pop_reports_zero():
    _, out = _ours(example("cube.fe"), "O")
    assert out == ["Edges popped: 0"]


def test_first_facets_on_load():
    """The loop start of each edge: the first datafile face listing it;
    spokes of faces split on load are unknown (-1)."""
    from pyevolver.model.records import edge_first_facet
    s = Session.load(example("octa.fe"), out=io.StringIO()).surface
    first = edge_first_facet(s)
    assert first[12] == 0 and first[14] == 1 and first[15] == 2     # edges 13, 15, 16
    cube = Session.load(example("cube.fe"), out=io.StringIO()).surface
    first = edge_first_facet(cube)
    assert (first[:12] >= 0).all() and (first[12:] == -1).all()
