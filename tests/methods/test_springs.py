"""pyevolver.methods.springs: hooke_energy, hooke2_energy, hooke3_energy and
dihedral_hooke against evolver-nox-d run live (values under each power and
flag, and ``g`` steps), against closed forms, and their gradients (and
hooke_energy's Hessian) against central differences."""
import io
import os

import numpy as np
import pytest
from comparison import _same
from reference import run_reference
from finite_differences import assert_gradient, assert_hessian_columns, central_gradient, method_energy
from tolerances import PRINTED, ROUNDOFF, STEPS

import pyevolver
from pyevolver.methods import springs as SP
from pyevolver.methods.registry import lookup
from pyevolver.session.core import Session


def _run_both(evolver, datafile, script, tmp_path):
    """The Evolver's output lines (subprocess) and pyevolver's (in this
    process, which saves the interpreter's start-up): ``(None, ref, out, err)``."""
    ref = run_reference(evolver, datafile, script, cwd=str(tmp_path), timeout=120)
    out, err = io.StringIO(), io.StringIO()
    sess = Session.load(datafile, out=out, err=err)
    sess.run(script)
    return None, ref, out.getvalue().rstrip("\n").split("\n"), err.getvalue()


ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")

# four facets round vertex 1: interior edges and boundary edges (one facet)
FAN = """{decl}
quantity hk energy method {method} global
vertices
1 0 0 0
2 1.2 0 0.1
3 0.1 0.9 0
4 1.1 1.3 0.5
5 0.5 -0.8 -0.3
6 -0.6 0.4 0.4
edges
1 1 2
2 2 3
3 3 1
4 2 4
5 4 3
6 1 5
7 5 2
8 3 6
9 6 1
faces
1 1 2 3 tension {t}
2 4 5 -2 tension {t}
3 6 7 -1 tension {t}
4 -3 8 9 tension {t}
"""


def _fan(tmp_path, method, decl="", t=0):
    p = tmp_path / f"fan_{method}.fe"
    p.write_text(FAN.format(decl=decl, method=method, t=t))
    return str(p)


def _numbers(lines):
    return [ln for ln in lines if ln.strip() and (ln.strip()[0] in "-0123456789")]


CASES = {
    "hooke_energy": ("", "hooke_power := 3\nhooke_length := 0.5\n",
                     "hooke_power := 0\n", "hooke_power := 1\n"),
    "hooke2_energy": ("", "set edge hooke_size 1\n", "hooke2_power := 3\n",
                      "hooke2_power := 0\n"),
    "hooke3_energy": ("", "set edge hooke_size 1.2\n", "hooke3_power := 3\n",
                      "frickenhaus_flag := 1\n", "hooke3_power := 0\n",
                      "frickenhaus_flag := 0\n"),
    "dihedral_hooke": ("",),
}


@pytest.mark.parametrize("method", sorted(CASES))
def test_values_agree_with_the_evolver(evolver, tmp_path, method):
    f = _fan(tmp_path, method)
    script = "".join(c + 'recalc\nprintf "%.15g\\n", hk.value\n' for c in CASES[method])
    _, ref, out, err = _run_both(evolver, f, script, tmp_path)
    ref, out = _numbers(ref), _numbers(out)
    assert len(ref) == len(CASES[method]), ref
    assert _same(out, ref, PRINTED), (out, ref, err)


@pytest.mark.parametrize("method,decl,cmd", [
    ("hooke_energy", "parameter hooke_length = 0.8", ""),
    ("hooke2_energy", "define edge attribute hooke_size real", "set edge hooke_size 0.7\n"),
    ("hooke3_energy", "", "set edge hooke_size length*0.9\n"),
    ("dihedral_hooke", "", ""),
])
def test_steps_agree_with_the_evolver(evolver, tmp_path, method, decl, cmd):
    f = _fan(tmp_path, method, decl, t=1)
    _, ref, out, err = _run_both(evolver, f, cmd + "g 4\n", tmp_path)
    ref = [ln for ln in ref if "area:" in ln]
    out = [ln for ln in out if "area:" in ln]
    assert len(ref) == 4, ref
    assert _same(out, ref, STEPS), (out, ref, err)


def test_closed_forms(tmp_path):
    sess = pyevolver.load(_fan(tmp_path, "hooke_energy"))
    s = sess.surface
    t = s.evaluate()
    L = t.edge_length
    idx = np.arange(s.ne)
    # hooke_length unset: 0 (the Evolver's value), so E = Σ L²
    assert abs(SP.hooke(t, None, idx).sum() - (L ** 2).sum()) <= ROUNDOFF
    # hooke_size undeclared: created with the current lengths, energy 0
    assert np.all(SP.hooke2(t, None, idx) == 0.0)
    assert np.array_equal(s.extra[("edge", "hooke_size")], L)
    # dihedral_hooke: 2 L on boundary edges, (1 - cos θ) L inside
    val = np.bincount(s.topology()[0].ravel(), minlength=s.ne)
    d = SP.dihedral_hooke(t, None, idx)
    assert np.allclose(d[val == 1], 2 * L[val == 1], rtol=0, atol=ROUNDOFF)


def _fd_check(s, m, w, h=1e-6):
    idx = np.arange(s.ne)
    grad = m.gradient(s.evaluate(), None, idx, w)
    assert_gradient(grad, central_gradient(s, method_energy(m, idx, w), h))


@pytest.mark.parametrize("method,params", [
    ("hooke_energy", {}), ("hooke_energy", {"hooke_length": 0.4, "hooke_power": 3}),
    ("hooke_energy", {"hooke_length": 0.3, "hooke_power": 0}),
    ("hooke2_energy", {"hooke2_power": 2.5}), ("hooke3_energy", {"hooke3_power": 2}),
    ("hooke3_energy", {"frickenhaus_flag": 1, "hooke3_power": 3}),
    ("dihedral_hooke", {}),
])
def test_gradient_matches_central_differences(tmp_path, method, params):
    s = pyevolver.load(_fan(tmp_path, method)).surface
    s.params.update(params)
    rng = np.random.default_rng(5)
    s.extra[("edge", "hooke_size")] = rng.uniform(0.6, 1.4, s.ne)
    _fd_check(s, lookup(method), rng.uniform(0.5, 2.0, s.ne))


@pytest.mark.parametrize("method,params", [
    ("hooke_energy", {"hooke_length": 0.4, "hooke_power": 3}),
    ("hooke2_energy", {"hooke2_power": 2}),
    ("hooke3_energy", {"hooke3_power": 3, "frickenhaus_flag": 1}),
])
def test_hooke_hessians_match_differences_of_the_gradient(tmp_path, method, params):
    s = pyevolver.load(_fan(tmp_path, method)).surface
    s.params.update(params)
    s.extra[("edge", "hooke_size")] = np.random.default_rng(7).uniform(0.6, 1.4, s.ne)
    m = lookup(method)
    idx = np.arange(s.ne)
    w = np.linspace(0.5, 2.0, s.ne)
    D = m.hessian(s.evaluate(), None, idx, w).toarray()
    assert np.abs(D - D.T).max() <= ROUNDOFF * 10
    assert_hessian_columns(s, D, lambda s: m.gradient(s.evaluate(), None, idx, w))


def test_dihedral_hooke_refuses_triple_edges(tmp_path):
    # edge 1 (vertices 1, 2) gets a third facet 1-2-4
    text = FAN.format(decl="", method="dihedral_hooke", t=0).replace(
        "9 6 1\n", "9 6 1\n10 4 1\n") + "5 1 4 10 tension 0\n"
    p = tmp_path / "triple.fe"
    p.write_text(text)
    with pytest.raises(pyevolver.errors.PyEvolverError,
                       match="not supported in pyevolver: dihedral_hooke on edges with more"):
        pyevolver.load(str(p))


def test_paper_torus_with_hooke_energy_agrees_with_the_evolver(evolver, tmp_path):
    f = os.path.join(ROOT, "datafiles", "paper", "torus10x16_offset_normal_hooke.fe")
    script = 'printf "%.15g %.15g\\n", total_energy, hooke.value\ng 4\n' \
             'printf "%.15g %.15g\\n", total_energy, hooke.value\n'
    _, ref, out, err = _run_both(evolver, os.path.abspath(f), script, tmp_path)
    ref, out = _numbers(ref), _numbers(out)
    assert len(ref) == 6, ref
    assert _same(out, ref, 1e-6), (out, ref, err)
    # the same energy as the paper's harmonic regularizer (modulus 0.25)
    h = pyevolver.load(os.path.join(ROOT, "datafiles", "paper",
                                    "torus10x16_offset_normal_harmonic.fe"))
    k = pyevolver.load(f)
    assert abs(h.value("harmonic.value") - k.value("hooke.value")) <= ROUNDOFF * 100
