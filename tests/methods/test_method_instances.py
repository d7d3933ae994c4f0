"""METHOD_INSTANCE declarations and quantities defined by FUNCTION of their
values (spec §3 Tier 2; manual, "Named quantities"): values, ``g`` and
``hessian`` against evolver-nox-d, the gradient against finite differences,
and refusals."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.errors import PyEvolverError

CHECKS = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data", "checks")
INSTANCES = ("method_instance bb method star_perp_sq_mean_curvature global\n"
             "method_instance aa method facet_area global\n")


def _file(tmp_path, quantities, name="mi.fe"):
    with open(os.path.join(CHECKS, "blob0.fe")) as fh:
        body = "".join(l for l in fh if not l.startswith("quantity"))
    path = tmp_path / name
    path.write_text(INSTANCES + quantities + "\n" + body)
    return str(path)


def _progress(lines):
    return [tuple(float(w) for w in l.split()[2::2]) for l in lines
            if l.strip()[:1].isdigit() and "area:" in l]


@pytest.mark.parametrize("quantity", [
    "quantity bend energy function bb.value",
    "quantity bend energy modulus 2 function bb.value + 0.5*aa.value^2",
])
def test_energy_functions_match_reference(evolver, tmp_path, quantity):
    """The value at load and three ``g`` steps within 1e-9 (scale 1e-4)."""
    from reference import run_reference
    from comparison import run_pyevolver
    path = _file(tmp_path, quantity + "\nquantity combo info_only function 3*aa.value - bb.value")
    script = 'printf "RESULT %.15g %.15g\\n", bend.value, combo.value\ng 3\n'
    ref = run_reference(evolver, path, script, cwd=str(tmp_path))
    code, out, err = run_pyevolver(path, script + "q\n", cwd=str(tmp_path))
    assert code == 0, err
    r0 = [l for l in ref if l.startswith("RESULT")][0].split()[1:]
    o0 = [l for l in out if l.startswith("RESULT")][0].split()[1:]
    for a, b in zip(o0, r0):
        assert abs(float(a) - float(b)) <= 1e-12 * abs(float(b))
    pr, po = _progress(ref), _progress(out)
    assert len(pr) == len(po) == 3
    for a, b in zip(po, pr):
        assert abs(a[0] - b[0]) <= 1e-9 * b[0] and abs(a[1] - b[1]) <= 1e-9 * b[1]
        assert abs(a[2] - b[2]) <= 1e-4 * b[2]


def test_function_gradient_matches_finite_differences(tmp_path):
    from pyevolver.evolve import gradient as GR
    s = Session.load(_file(tmp_path, "quantity bend energy modulus 1.5 function "
                                     "bb.value*aa.value + sqrt(aa.value)"), out=io.StringIO())
    S = s.surface
    q = S.quantities["bend"]
    g = GR.quantity_gradient(S.evaluate(), q)
    X0 = S.X.copy()
    rng = np.random.default_rng(3)
    h = 1e-6
    for _ in range(10):
        i, k = rng.integers(S.nv), rng.integers(3)
        S.X = X0.copy()
        S.X[i, k] += h
        vp = S.evaluate().quantity_value(q)
        S.X = X0.copy()
        S.X[i, k] -= h
        vm = S.evaluate().quantity_value(q)
        S.X = X0
        assert abs((vp - vm) / (2 * h) - g[i, k]) <= 1e-6 * np.abs(g).max()


def test_hessian_with_linear_and_nonlinear_functions(tmp_path):
    """A FUNCTION linear in the instance values has the instances' sparse
    Hessians, a nonlinear one also its dense low-rank term (kept out of
    the sparse matrix, evolve/hessian.py): Newton steps converge with both,
    and the damped ``newton`` descends from where they converged."""
    s = Session.load(_file(tmp_path, "quantity bend energy function 2*bb.value + aa.value"),
                     out=io.StringIO())
    s.run("g 5")
    es = [s.hessian(echo=False).energy for _ in range(4)]
    assert abs(es[3] - es[2]) <= 1e-10 * abs(es[3])
    s2 = Session.load(_file(tmp_path, "quantity bend energy function bb.value*aa.value",
                            "mi2.fe"), out=io.StringIO(), err=io.StringIO())
    s2.run("g 5")
    es = [s2.hessian(echo=False).energy for _ in range(5)]
    assert abs(es[4] - es[3]) <= 1e-10 * abs(es[4]), es
    # the damped newton (the rank term by the Woodbury formula; all three
    # directions, where hessian_normal moved along the normals) only descends
    s2.run("newton 3")
    assert s2.value("total_energy") <= es[4]


def test_function_of_an_unknown_name_is_a_located_error(tmp_path):
    path = _file(tmp_path, "quantity bend energy function cc.value + 1")
    with pytest.raises(PyEvolverError, match=r"cc\.value"):
        Session.load(path, out=io.StringIO())
