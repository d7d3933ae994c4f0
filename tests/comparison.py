"""Helpers the tests share: running pyevolver like a user, comparing its
transcript with the Evolver's, the invariants every mesh operation keeps.

The tolerances of the comparisons are named in one place,
:mod:`tolerances`."""
import glob as _glob
import os
import shutil as _shutil
import subprocess
import sys

import numpy as np

import pyevolver
from conftest import EXAMPLES
from pyevolver.geometry import kernels as G
from reference import run_reference
from tolerances import PRINTED

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def run_pyevolver(datafile, commands, cwd=None):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.abspath(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    p = subprocess.run([sys.executable, "-m", "pyevolver", datafile], input=commands,
                       capture_output=True, text=True, timeout=120, env=env, cwd=cwd)
    return p.returncode, p.stdout.rstrip("\n").split("\n"), p.stderr


def _tokens(lines):
    return [l.split() for l in lines if l.strip()]


def _same(out, ref, rtol=PRINTED):
    """Token-wise equality, numbers within ``rtol`` (round-off differs)."""
    a, b = _tokens(out), _tokens(ref)
    if len(a) != len(b):
        return False
    for la, lb in zip(a, b):
        if len(la) != len(lb):
            return False
        for x, y in zip(la, lb):
            if x == y:
                continue
            try:
                fx = float(x.strip("/*").replace("*/", ""))
                fy = float(y.strip("/*").replace("*/", ""))
            except ValueError:
                return False
            if abs(fx - fy) > rtol * max(abs(fx), abs(fy)) + 1e-15:
                return False
    return True


def _run_both(evolver, datafile, script, tmp_path):
    dirs = {}
    for who in ("ref", "ours"):
        d = tmp_path / who
        d.mkdir()
        for f in _glob.glob(os.path.join(EXAMPLES, "*.cmd")):
            _shutil.copy(f, d)
        dirs[who] = d
    ref = run_reference(evolver, datafile, script, cwd=str(dirs["ref"]), timeout=120)
    code, out, err = run_pyevolver(datafile, script + "q\n", cwd=str(dirs["ours"]))
    return dirs, ref, out, err


MEMORY = ("Element memory", "Total data memory")


def compare_transcripts(evolver, datafile, script, tmp_path, rtol=1e-10):
    """Run ``script`` on ``datafile`` in REF and in pyevolver (a child):
    pyevolver writes nothing on stderr and its transcript equals REF's
    (blank and memory-report lines aside) within ``rtol``; returns ours."""
    ref = run_reference(evolver, datafile, script, cwd=str(tmp_path), timeout=120)
    code, out, err = run_pyevolver(datafile, script + "q\n", cwd=str(tmp_path))
    assert err == "", err
    assert _same(transcript_lines(out), transcript_lines(ref), rtol), (out, ref)
    return out


def transcript_lines(lines):
    """The lines of a transcript without blank and memory-report lines."""
    return [l for l in lines if l.strip() and not l.startswith(MEMORY)]


def run_both_in_process(evolver, datafile, script, tmp_path):
    """REF's transcript of ``script`` and pyevolver's (a Session in this
    process: faster than a child), as lists of lines, and pyevolver's stderr."""
    import io
    from pyevolver.session.core import Session
    ref = run_reference(evolver, datafile, script, cwd=str(tmp_path), timeout=120)
    out, err = io.StringIO(), io.StringIO()
    sess = Session.load(datafile, out=out, err=err)
    sess.run(script)
    return ref, out.getvalue().rstrip("\n").split("\n"), err.getvalue()


def number_lines(lines):
    """The lines that start with a number (printed values)."""
    return [ln for ln in lines if ln.strip() and (ln.strip()[0] in "-0123456789")]


def consistent(s):
    """Assert the invariants every operation must keep."""
    assert s.E.shape == (s.ne, 2) and s.FE.shape == (s.nf, 3)
    idx, sgn = G.edge_index(s.FE)
    assert s.nf == 0 or (idx.min() >= 0 and idx.max() < s.ne)
    tails = np.where(sgn > 0, s.E[idx, 0], s.E[idx, 1])
    heads = np.where(sgn > 0, s.E[idx, 1], s.E[idx, 0])
    assert np.array_equal(heads, np.roll(tails, -1, axis=1)), "facet edge loops must close"
    assert not np.any(s.E[:, 0] == s.E[:, 1]), "no edge may join a vertex to itself"
    for arr in s.vattr.values():
        assert len(arr) == s.nv
    for arr in s.eattr.values():
        assert len(arr) == s.ne
    for arr in s.fattr.values():
        assert len(arr) == s.nf
    for m in s.vcon.values():
        assert len(m) == s.nv
    for m in s.econ.values():
        assert len(m) == s.ne
    if s.bodies.n:
        assert s.bodies.facet_matrix.shape == (s.bodies.n, s.nf)
    for q in s.quantities.values():
        for m, etype, idx_, sg in q.methods:
            n = {"vertex": s.nv, "edge": s.ne, "facet": s.nf}[etype]
            assert len(idx_) == 0 or idx_.max() < n


def octasphere(seed=0, jiggle=0.03, scale=1.0, shift=(0.0, 0.0, 0.0)):
    """The octahedron split once (18 vertices, 32 facets) on a sphere of radius
    ``scale`` about ``shift``, each coordinate jiggled by ``jiggle`` times a
    standard normal (generator seeded ``seed``); one body."""
    X = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
    F0 = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    X = [np.array(x, float) for x in X]
    mid = {}

    def m(a, b):
        k = (min(a, b), max(a, b))
        if k not in mid:
            mid[k] = len(X)
            X.append((X[a] + X[b]) / 2)
        return mid[k]
    F = []
    for a, b, c in F0:
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        F += [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
    X = np.array(X)
    X /= np.linalg.norm(X, axis=1)[:, None]
    X += jiggle * np.random.default_rng(seed).standard_normal(X.shape)
    return pyevolver.Surface.from_arrays(scale * X + np.asarray(shift), np.array(F), body=True)
