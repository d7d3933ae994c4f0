"""The nonsmooth BFGS minimizer (pyevolver/evolve/bfgs.py, Lewis & Overton
2013) and the ``bfgs`` command; its use on Bobenko's energy is in
test_studies.py (the paper's Figure 1)."""
import numpy as np
import pytest


def test_bfgs_minimizes_smooth_and_nonsmooth_functions():
    """Rosenbrock to 1e-10; a nonsmooth max of quadratics (Lewis–Overton's
    kind of test: minimum on the kink) to 1e-6."""
    from pyevolver.evolve.bfgs import minimize

    def rosen(x):
        f = 100 * (x[1] - x[0] ** 2) ** 2 + (1 - x[0]) ** 2
        g = np.array([-400 * x[0] * (x[1] - x[0] ** 2) - 2 * (1 - x[0]), 200 * (x[1] - x[0] ** 2)])
        return f, g
    r = minimize(rosen, np.array([-1.2, 1.0]), 500)
    assert np.abs(r.x - 1).max() <= 1e-6 and r.energy <= 1e-10

    def kink(x):
        a = (x[0] - 1) ** 2 + 2 * x[1] ** 2
        b = (x[0] + 1) ** 2 + 2 * x[1] ** 2
        if a >= b:
            return a, np.array([2 * (x[0] - 1), 4 * x[1]])
        return b, np.array([2 * (x[0] + 1), 4 * x[1]])
    r = minimize(kink, np.array([0.7, 0.9]), 500)
    assert abs(r.energy - 1.0) <= 1e-6


def test_bfgs_command_refuses_constraints_and_keeps_the_surface():
    import io
    from conftest import example
    from pyevolver import Session
    from pyevolver.errors import PyEvolverError
    s = Session.load(example("cube.fe"), out=io.StringIO(), err=io.StringIO())
    X = s.surface.X.copy()
    with pytest.raises(PyEvolverError, match="bfgs with fixed volumes"):
        s.run("bfgs 10")
    assert np.array_equal(s.surface.X, X)
