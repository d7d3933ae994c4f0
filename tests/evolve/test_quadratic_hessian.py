"""The quadratic model's Hessian (pyevolver/evolve/quadratic_hessian.py):
the coloured differences against dense ones, the node normals and the
Newton step against single-threaded evolver-nox-d, refusals by name."""
import io
import os
import subprocess

import numpy as np
import pytest
import scipy.sparse as sp

import pyevolver
from conftest import EXAMPLES
from pyevolver.evolve import hessian as H
from pyevolver.evolve import quadratic_hessian as QH

CUBE = os.path.join(EXAMPLES, "cube.fe")


def _session(fe, cmds):
    s = pyevolver.load(fe, out=io.StringIO(), err=io.StringIO())
    for c in cmds:
        s.run(c)
    return s


def _ref(exe, fe, cmds, tmp_path, extra=""):
    script = tmp_path / "q.cmd"
    script.write_text("\n".join(cmds) + "\n" + extra + 'printf "DS_E %.17g\\n", total_energy\n')
    out = subprocess.run([exe, "-f", str(script), fe], stdin=subprocess.DEVNULL,
                         capture_output=True, text=True, timeout=120).stdout
    return out


def _energy(out):
    return float(next(l.split()[1] for l in out.split("\n") if l.startswith("DS_E ")))


def test_coloured_differences_are_the_dense_ones(evolver):
    """Every pair of nodes on one patch or edge curve is in the pattern: the
    coloured central differences equal column-by-column ones."""
    s = _session(CUBE, ["M 2", "g 3"]).surface
    from pyevolver.evolve.gradient import energy_gradient

    def fun(X):
        return energy_gradient(s.evaluate())
    h = 1e-4
    got = H.fd_hessian(fun, s, h, QH.node_adjacency(s)).toarray()
    X0 = s.X.copy()
    dense = np.zeros_like(got)
    for j in range(X0.size):
        s.X = X0.copy()
        s.X.flat[j] += h
        gp = fun(s.X).ravel()
        s.X = X0.copy()
        s.X.flat[j] -= h
        gm = fun(s.X).ravel()
        dense[:, j] = (gp - gm) / (2 * h)
    s.X = X0
    dense = 0.5 * (dense + dense.T)
    assert np.abs(dense).max() > 1.0
    assert np.allclose(got, dense, atol=1e-9 * np.abs(dense).max())
    assert sp.issparse(QH.node_adjacency(s))


def test_node_normals_are_ref_vertex_normal(evolver, tmp_path):
    """cube.fe refined, then quadratic: each node's direction is REF's
    ``vertex_normal``."""
    cmds = ["r", "M 2", "g 2"]
    s = _session(CUBE, cmds)
    nrm = QH.node_normals(s.surface)
    out = _ref(evolver, CUBE, cmds, tmp_path, extra=(
        'foreach vertex vv do printf "N %.17g %.17g %.17g %.17g %.17g %.17g\\n", '
        'x, y, z, vv.vertex_normal[1], vv.vertex_normal[2], vv.vertex_normal[3]\n'))
    R = np.array([[float(v) for v in l.split()[1:]] for l in out.split("\n")
                  if l.startswith("N ")])
    X = s.surface.X
    assert len(R) == len(X) > 100
    j = np.array([np.argmin(np.linalg.norm(X - p, axis=1)) for p in R[:, :3]])
    assert np.abs(X[j] - R[:, :3]).max() < 1e-12
    assert np.abs(np.abs(np.einsum("ij,ij->i", nrm[j], R[:, 3:])) - 1).max() < 1e-12


def _step(evolver, tmp_path, cmds, fe=CUBE):
    ref = _energy(_ref(evolver, fe, cmds, tmp_path))
    ours = _session(fe, cmds).value("total_energy")
    assert abs(ours - ref) < 1e-9 * abs(ref), (cmds, ours, ref)


def test_newton_step_as_single_threaded_ref(evolver, tmp_path):
    _step(evolver, tmp_path, ["M 2", "g 5", "hessian"])


@pytest.mark.slow
@pytest.mark.parametrize("normal", ["on", "off"])
def test_newton_step_refined(evolver, tmp_path, normal):
    """The refined cube: the node normals matter (normal on) and the
    indefinite Hessian (index 123) needs the extrapolated differences (off)."""
    _step(evolver, tmp_path, ["r", "M 2", "g 5", f"hessian_normal {normal}", "hessian"])


def test_refused_by_name():
    s = _session(os.path.join(EXAMPLES, "octa.fe"), ["M 2", "g 2"])
    e0 = s.value("total_energy")
    with pytest.raises(pyevolver.CommandError, match="quadratic model with junction lines"):
        s.run("hessian")
    assert s.value("total_energy") == e0


@pytest.mark.slow
def test_newton_step_quad(evolver, tmp_path):
    _step(evolver, tmp_path, ["M 2", "g 5", "hessian"], os.path.join(EXAMPLES, "quad.fe"))
