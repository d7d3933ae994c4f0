"""Direct tests of pyevolver.remesh.string (string model): ``split_edges``
(r) and ``vertex_average`` (V, rawv, rawestv)."""
import re

import numpy as np
import pytest

import pyevolver
from pyevolver.remesh.string import split_edges, vertex_average
from tolerances import ROUNDOFF


def _string(tmp_path, pts, fixed_ends=True):
    lines = ["STRING", "vertices"]
    for i, p in enumerate(pts):
        fx = " fixed" if fixed_ends and i in (0, len(pts) - 1) else ""
        lines.append(f"{i + 1} {p[0]!r} {p[1]!r} 0{fx}")
    lines.append("edges")
    for i in range(len(pts) - 1):
        lines.append(f"{i + 1} {i + 1} {i + 2}")
    f = tmp_path / "s.fe"
    f.write_text("\n".join(lines) + "\n")
    s = pyevolver.load(str(f)).surface
    assert s.string
    return s


def _length(s):
    return float(np.linalg.norm(s.X[s.E[:, 1]] - s.X[s.E[:, 0]], axis=1).sum())


def test_split_all_edges(tmp_path):
    s = _string(tmp_path, [(0, 0), (1, 0.5), (2, 0), (3, 1)])
    L = _length(s)
    R = np.arange(s.ne)
    t = split_edges(s, R)
    assert (t.nv, t.ne) == (s.nv + s.ne, 2 * s.ne)
    mids = 0.5 * (s.X[s.E[:, 0]] + s.X[s.E[:, 1]])
    assert np.allclose(t.X[s.nv:], mids, atol=ROUNDOFF)
    assert _length(t) == pytest.approx(L, rel=ROUNDOFF)
    # tail half keeps the edge, head half is new and ends at the old head
    assert np.array_equal(t.E[:s.ne, 0], s.E[:, 0])
    assert np.array_equal(t.E[:s.ne, 1], s.nv + R)
    assert np.array_equal(t.E[s.ne:, 1], s.E[:, 1])
    # still one chain: every inner vertex has two edges, the two ends one
    deg = np.bincount(t.E.ravel(), minlength=t.nv)
    assert sorted(deg.tolist()) == [1, 1] + [2] * (t.nv - 2)
    # the input is untouched
    assert (s.nv, s.ne) == (4, 3)


def test_split_some_edges(tmp_path):
    s = _string(tmp_path, [(0, 0), (1, 0), (2, 0)])
    t = split_edges(s, [1])
    assert (t.nv, t.ne) == (4, 3)
    assert np.allclose(t.X[3], [1.5, 0, 0])
    assert _length(t) == pytest.approx(2.0, rel=ROUNDOFF)


def test_vertex_average_straight_even_string_does_not_move(tmp_path):
    s = _string(tmp_path, [(0, 0), (1, 0), (2, 0), (3, 0)])
    for mode in ("V", "raw", "rawest"):
        assert np.allclose(vertex_average(s, mode).X, s.X, atol=ROUNDOFF)


def test_vertex_average_moves(tmp_path):
    # middle vertex (0.5, 0.5) between fixed (0,0) and (2,0):
    # D = mean of (x_e - x_v) = (0.5, -0.5); x += D/4
    s = _string(tmp_path, [(0, 0), (0.5, 0.5), (2, 0)])
    raw = vertex_average(s, "raw")
    assert np.allclose(raw.X[1], [0.625, 0.375, 0], atol=ROUNDOFF)
    assert np.array_equal(raw.X[[0, 2]], s.X[[0, 2]])            # FIXED ends
    # V keeps only the part of D along the chord (2,0)-(0,0): (0.5, 0)
    v = vertex_average(s, "V")
    assert np.allclose(v.X[1], [0.625, 0.5, 0], atol=ROUNDOFF)
    assert np.allclose(s.X[1], [0.5, 0.5, 0])                     # input unchanged
    # free ends do not move either (one edge)
    f = _string(tmp_path, [(0, 0), (0.5, 0.5), (2, 0)], fixed_ends=False)
    assert np.allclose(vertex_average(f, "raw").X, raw.X, atol=ROUNDOFF)


TREFOIL = """string
parameter maj_r = 2
parameter min_r = 0.5
boundary 1 parameter 1
x1:  cos(2*p1)*(maj_r + min_r*cos(3*p1))
x2:  sin(2*p1)*(maj_r + min_r*cos(3*p1))
x3:  min_r*sin(3*p1)
vertices
""" + "".join(f"{i + 1} {0.2 * i}*pi boundary 1\n" for i in range(10)) + "edges\n" + \
    "".join(f"{i + 1} {i + 1} {(i + 1) % 10 + 1} boundary 1\n" for i in range(10))


def test_split_on_a_boundary_agrees_with_the_evolver(evolver, tmp_path):
    """knotty.fe's curve refined twice: the new vertices are the curve's
    points nearest the chords' midpoints, REF's parameters to round-off
    (the curve wraps at p1 = 2π between vertices 10 and 1)."""
    from reference import run_reference
    import io
    from pyevolver.session.core import Session
    f = tmp_path / "trefoil.fe"
    f.write_text(TREFOIL)
    script = 'r\nr\nforeach vertex vv do printf "%.15g %.15g %.15g\\n", vv.p1, vv.x, vv.z\n'
    ref = [ln for ln in run_reference(evolver, str(f), script, cwd=str(tmp_path))
           if ln.strip() and ln[:1] in "-0123456789"]
    out = io.StringIO()
    Session.load(str(f), out=out).run(script)
    ours = [ln for ln in out.getvalue().split("\n") if ln.strip() and ln[:1] in "-0123456789"]
    assert len(ref) == 40
    a = np.array([[float(x) for x in ln.split()] for ln in ref])
    b = np.array([[float(x) for x in ln.split()] for ln in ours])
    assert np.abs(a - b).max() <= 1e-12


def test_torus_midpoints_rounded_as_ref(evolver, tmp_path):
    # REF's midpoint of a wrapped edge is (tail + (head + shift)) / 2: after
    # r; r on 100grain.fe every coordinate equals REF's to the last bit
    import subprocess
    path = "/usr/share/doc/evolver/examples/100grain.fe"
    cmd = 'foreach vertex vv do printf "%d %.17g %.17g\\n", vv.id, vv.x, vv.y'
    out = subprocess.run([evolver, "-p1", path], input=f"r\nr\n{cmd}\nq\nq\n", capture_output=True,
                         text=True, timeout=60, cwd=str(tmp_path)).stdout
    ref = {int(m[0]): (float(m[1]), float(m[2]))
           for m in re.findall(r"^(\d+) (\S+) (\S+)$", out, re.M)}
    sess = pyevolver.load(path)
    sess.run("r")
    sess.run("r")
    s = sess.surface
    ours = {int(i): (float(x[0]), float(x[1])) for i, x in zip(s.ids("vertex"), s.X)}
    assert len(ref) == 1100 and ours == ref
