"""pyevolver.remesh.string_pop: ``o`` in the string model and autopop's
edge deletion, against the reference Evolver (run live) and closed forms."""
import os
import re
import subprocess

import numpy as np
import pytest

import pyevolver
from pyevolver.remesh import string_pop as SP

FIVE = """STRING
SPACE_DIMENSION 2
vertices
1 0 0
2 3 0 fixed
3 1 1.732 fixed
4 -0.5 0.1 fixed
5 0.3 -1.5 fixed
6 -1 -1.2 fixed
edges
1 1 2
2 3 1
3 1 4
4 5 1
5 1 6
"""

HPAIR = """STRING
SPACE_DIMENSION 2
scale 0.001 fixed
vertices
1 0 0
2 0.04 0
3 0.3 1 fixed
4 0.3 -1 fixed
5 -0.26 1 fixed
6 -0.26 -1 fixed
edges
1 1 2
2 3 1
3 1 4
4 2 5
5 6 2
"""


def _file(tmp_path, text, name="s.fe"):
    f = tmp_path / name
    f.write_text(text)
    return str(f)


def _ref_lists(exe, path, cmds):
    """REF's `list vertices` rows after ``cmds``: {id: (x, y)}."""
    script = "\n".join(cmds + ["list vertices", "q", "q"]) + "\n"
    out = subprocess.run([exe, "-p1", path], input=script, capture_output=True, text=True,
                         timeout=60, cwd=os.path.dirname(path)).stdout
    rows = {}
    for line in out.splitlines():
        m = re.match(r"^\s*(\d+)\s+(\S+)\s+(\S+)", line.replace("Enter command:", ""))
        if m:
            try:
                rows[int(m.group(1))] = (float(m.group(2)), float(m.group(3)))
            except ValueError:
                pass
    return rows, out


def _ours(sess):
    s = sess.surface
    return {int(i): tuple(x[:2]) for i, x in zip(s.ids("vertex"), s.X)}


def test_five_valent_pops_twice_as_ref(tmp_path, evolver):
    path = _file(tmp_path, FIVE)
    ref, out = _ref_lists(evolver, path, ["o"])
    assert "Vertices popped: 2" in out
    sess = pyevolver.load(path)
    sess.run("o")
    ours = _ours(sess)
    assert sorted(ours) == sorted(ref)
    for k in ref:
        assert np.allclose(ours[k], ref[k], atol=1e-12)
    s = sess.surface
    assert s.ne == 7 and np.array_equal(s.E[5:], [[0, 6], [0, 7]])


def test_autopop_merges_and_pops_as_ref(tmp_path, evolver):
    path = _file(tmp_path, HPAIR)
    ref, out = _ref_lists(evolver, path, ["autopop on", "g 1"])
    assert "Autopopped 1 edges, 1 vertices." in out
    sess = pyevolver.load(path)
    sess.run("autopop on")
    res = sess.g(1)
    assert "Autopopped 1 edges, 1 vertices." in res[0].warnings
    ours = _ours(sess)
    assert sorted(ours) == sorted(ref)
    for k in ref:
        assert np.allclose(ours[k], ref[k], atol=1e-9)
    e = float(re.search(r"length:\s*(\S+)", out).group(1))
    assert sess.total_energy == pytest.approx(e, rel=1e-12)


def test_popstr_tie_and_placement():
    sess = pyevolver.load("/usr/share/doc/evolver/examples/popstr.fe") \
        if os.path.exists("/usr/share/doc/evolver/examples/popstr.fe") else None
    if sess is None:
        pytest.skip("examples not installed")
    t, n = SP.pop_vertices(sess.surface)
    assert n == 1
    # REF: edges 1 and 4 (the first 90-degree pair in ring order) go to the
    # new vertex, 0.1 * 0.7071 off along their bisector
    assert np.allclose(t.X[5], [0.5 - 0.1 * np.sqrt(0.5), 0, 0.5])
    assert t.E[0, 1] == 5 and t.E[3, 1] == 5 and tuple(t.E[4]) == (4, 5)


def test_delete_short_edges_midpoint(tmp_path):
    s = pyevolver.load(_file(tmp_path, HPAIR)).surface
    t, n, vmap = SP.delete_short_edges(s, 0.05)
    assert n == 1 and t.nv == s.nv - 1 and t.ne == s.ne - 1
    assert vmap[1] == -1 and vmap[0] == 0
    assert np.allclose(t.X[0, :2], [0.02, 0])
    assert (np.count_nonzero(t.E == 0)) == 4


def test_predicted_lengths_first_order(tmp_path):
    s = pyevolver.load(_file(tmp_path, HPAIR)).surface
    vel = np.zeros((s.nv, 3))
    vel[1, 0] = 1.0                         # the head runs away along the edge
    p = SP.predicted_lengths(s, vel, 0.01)
    assert p[0] == pytest.approx(0.05)
    assert np.allclose(p[1:3], SP.after_move_lengths(s)[1:3])   # edges away from it


def test_pop_command_on_given_vertices(tmp_path, evolver):
    path = _file(tmp_path, FIVE)
    ref, out = _ref_lists(evolver, path, ["pop vertex[2]", "pop vertex[1]"])
    assert "Vertices popped: 2" in out and out.count("Vertices popped") == 1
    sess = pyevolver.load(path)
    sess.run("pop vertex[2]")                   # fixed, two edges: nothing (REF silent)
    sess.run("pop vertices where id == 1")
    ours = _ours(sess)
    assert sorted(ours) == sorted(ref)
    for k in ref:
        assert np.allclose(ours[k], ref[k], atol=1e-12)
    assert sess.value("vertex_pop_count") == 2


def test_pop_of_edges_refused_in_the_string_model():
    sess = pyevolver.load("/usr/share/doc/evolver/examples/popstr.fe")
    with pytest.raises(pyevolver.errors.CommandError, match="not supported.*pop of edges"):
        sess.run("pop edge[1]")
