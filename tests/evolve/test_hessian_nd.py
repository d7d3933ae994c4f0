"""pyevolver.evolve.hessian_nd: ``hessian`` in SPACE_DIMENSION 4..9 against
evolver-nox-d (run live), and its difference Hessian against the energy."""
import os

import numpy as np
import pytest

import pyevolver
from comparison import run_pyevolver
from conftest import example
from reference import run_reference
from pyevolver.errors import PyEvolverError

DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")
SQUARE = os.path.join(DATA, "square5d.fe")


def _g(lines):
    return [float(l.split()[4]) for l in lines if "energy:" in l]


@pytest.mark.parametrize("normal", ["off", "on"])
def test_hessian_steps_in_five_dimensions_as_the_evolver(evolver, normal):
    """Tension on a 5-D square with a free centre: two Newton steps as REF;
    with ``hessian_normal`` the centre moves along the x1..x3 normal only
    (x4, x5 stay: REF's rule, measured here)."""
    script = (f"hessian_normal {normal}\nhessian\nhessian\n"
              'printf "%.15g %.15g %.15g %.15g %.15g\\n", vertex[5].x, vertex[5].y, '
              "vertex[5].z, vertex[5].x4, vertex[5].x5\n")
    ref = run_reference(evolver, SQUARE, script)
    rc, out, err = run_pyevolver(SQUARE, script)
    assert rc == 0, err
    assert _g(out) == pytest.approx(_g(ref), rel=1e-9) and len(_g(ref)) == 2
    xo = [float(v) for v in out[-1].split()]
    xr = [float(v) for v in ref[-1].split()]
    assert xo == pytest.approx(xr, abs=1e-9)
    if normal == "on":
        assert xo[3:] == [0.2, -0.1]


@pytest.mark.parametrize("cmds", ["g 5\nhessian", "g 5\nn 0.5\ng 5"])
def test_relaxed_fe_hessian_and_notch_as_the_evolver(evolver, cmds):
    script = cmds + '\nprintf "%.15g\\n", total_energy\n'
    ref = run_reference(evolver, example("relaxed.fe"), script)
    rc, out, err = run_pyevolver(example("relaxed.fe"), script)
    assert rc == 0 and "not supported" not in err + "".join(out), err
    assert float(out[-1]) == pytest.approx(float(ref[-1]), abs=1e-12)


def test_difference_hessian_matches_the_energy():
    """The colouring's difference Hessian of the 5-D square: v·Hv against
    second differences of the energy along random directions."""
    from pyevolver.evolve.hessian_nd import fd_hessian_nd
    from pyevolver.evolve.gradient import energy_gradient
    s = pyevolver.load(SQUARE).surface
    H = fd_hessian_nd(lambda: energy_gradient(s.evaluate()), s).toarray()
    assert np.allclose(H, H.T)
    rng = np.random.default_rng(1)
    X0 = s.X.copy()
    h = 1e-4
    for _ in range(3):
        v = rng.normal(size=X0.shape)
        E = []
        for t in (-h, 0.0, h):
            s.X = X0 + t * v
            E.append(s.evaluate().energy)
        s.X = X0
        d2 = (E[0] - 2 * E[1] + E[2]) / h ** 2
        assert v.ravel() @ H @ v.ravel() == pytest.approx(d2, rel=1e-4)


def test_eigenvalue_commands_stay_refused_in_five_dimensions():
    sess = pyevolver.load(SQUARE)
    with pytest.raises(PyEvolverError, match="SPACE_DIMENSION 5: the Hessian's eigenvalues"):
        sess.run("saddle")
