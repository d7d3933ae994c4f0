"""Gradients of ``facet_scalar_integral`` and ``vertex_scalar_integral``
(used as energies by the shengdie torus sheets: a substrate and an end
tension): central finite differences, and ``g`` / ``r`` on a cube with both
as energies against the Evolver run live."""
import io
import os

import numpy as np

from comparison import _run_both, _same
from conftest import EXAMPLES
from pyevolver import Session
from pyevolver.evolve.gradient import energy_gradient
from tolerances import FD

HEAD = """parameter ls = 1.5
parameter lf = 0.3
quantity sub energy modulus 0.7 method facet_scalar_integral global
 scalar_integrand: 1/(ls + lf*x)^4 * z^2 + 0.1*x*y
quantity rt energy method vertex_scalar_integral
 scalar_integrand: -(x - 2) * 0.4 + z*z*y
"""


def _datafile(tmp_path):
    lines = open(os.path.join(EXAMPLES, "cube.fe")).read().split("\n")
    out, part = [HEAD], None
    for ln in lines:
        w = ln.split()
        if w and w[0].lower() in ("vertices", "edges"):
            part = w[0].lower()
            out.append(ln)
            continue
        if part == "vertices" and w and w[0].isdigit():
            ln = " ".join(w[:4]) + (" rt" if int(w[0]) <= 4 else "")
        if part is not None:
            out.append(ln)
    p = tmp_path / "fsi.fe"
    p.write_text("\n".join(out) + "\n")
    return str(p)


def test_scalar_integral_gradients_match_finite_differences(tmp_path):
    s = Session.load(_datafile(tmp_path), out=io.StringIO())
    S = s.surface
    S.X = S.X + 0.05 * np.random.default_rng(1).standard_normal(S.X.shape)
    g = energy_gradient(S.evaluate())
    X0, h = S.X.copy(), 1e-6
    fd = np.zeros_like(X0)
    for i in range(S.nv):
        for k in range(3):
            S.X = X0.copy()
            S.X[i, k] += h
            ep = S.evaluate().energy
            S.X = X0.copy()
            S.X[i, k] -= h
            fd[i, k] = (ep - S.evaluate().energy) / (2 * h)
    S.X = X0
    assert np.abs(fd - g).max() <= FD * np.abs(g).max()


def test_scalar_integral_energies_evolve_like_the_evolver(evolver, tmp_path):
    fe = _datafile(tmp_path)
    script = ('printf "%.15g\\n", total_energy\ng 4\nr\ng 3\n'
              'printf "%.15g %.15g %.15g\\n", total_energy, sub.value, rt.value\n')
    _, ref, out, err = _run_both(evolver, fe, script, tmp_path)
    ref = [ln for ln in ref if not ln.startswith(("Vertices:", "Element memory", "Total data"))]
    out = [ln for ln in out if not ln.startswith("Vertices:")]
    assert _same(out, ref, rtol=1e-10), (out, ref, err)
