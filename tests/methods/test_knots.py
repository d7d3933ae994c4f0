"""pyevolver.methods.knots: the knot energies against evolver-nox-d run live
(values, and ``g`` steps for the methods whose force is REF's), their
gradients (and knot_energy's Hessian) against central differences, and
knotty.fe (the default energy knot_energy with a FIXED edge_tension length)."""
import io
import os

import numpy as np
import pytest
from comparison import _same, number_lines, run_both_in_process
from finite_differences import central_gradient, method_energy
from tolerances import FD, PRINTED, STEPS

from pyevolver.methods import knots as KN
from pyevolver.methods.registry import lookup
from pyevolver.session.core import Session

EXAMPLES = "/usr/share/doc/evolver/examples"

# a wobbly octagon in space
_TH = np.arange(8) * 2 * np.pi / 8
_X = np.c_[2 * np.cos(_TH), 2 * np.sin(_TH), 0.3 * np.sin(2 * _TH)] + 0.1 * np.array(
    [[0.3, -0.2, 0.1], [-0.1, 0.4, 0.2], [0.2, 0.1, -0.3], [0.0, -0.3, 0.1],
     [0.1, 0.2, 0.0], [-0.4, 0.1, 0.2], [0.2, -0.1, -0.1], [0.1, 0.3, 0.4]])
METHODS = ["knot_energy", "uniform_knot_energy", "edge_knot_energy", "edge_edge_knot_energy",
           "buck_knot_energy", "proj_knot_energy", "circle_knot_energy", "writhe"]


def _octagon(tmp_path, methods, decl="", tension=1):
    lines = ["string", "space_dimension 3", decl]
    lines += [f"quantity q{k} energy method {m} global" for k, m in enumerate(methods)]
    lines.append("vertices")
    lines += [f"{i + 1} {x[0]!r} {x[1]!r} {x[2]!r}" for i, x in enumerate(_X.tolist())]
    lines.append("edges")
    lines += [f"{i + 1} {i + 1} {(i + 1) % 8 + 1} tension {tension}" for i in range(8)]
    p = tmp_path / "octagon.fe"
    p.write_text("\n".join(lines) + "\n")
    return str(p)


_run_both = run_both_in_process
_numbers = number_lines


@pytest.mark.parametrize("power", [2, 3])
def test_values_agree_with_the_evolver(evolver, tmp_path, power):
    f = _octagon(tmp_path, METHODS + ["edge_min_knot_energy"],
                 decl=f"parameter knot_power = {power}")
    script = "".join(f'printf "%.15g\\n", q{k}.value\n' for k in range(len(METHODS) + 1))
    ref, out, err = _run_both(evolver, f, script, tmp_path)
    ref, out = _numbers(ref), _numbers(out)
    assert len(ref) == len(METHODS) + 1, ref
    assert _same(out, ref, PRINTED), (out, ref, err)


@pytest.mark.parametrize("method", ["knot_energy", "edge_knot_energy", "buck_knot_energy",
                                    "circle_knot_energy", "uniform_knot_energy", "writhe"])
def test_steps_agree_with_the_evolver(evolver, tmp_path, method):
    f = _octagon(tmp_path, [method])
    ref, out, err = _run_both(evolver, f, "g 3\n", tmp_path)
    ref = [ln for ln in ref if "energy:" in ln]
    out = [ln for ln in out if "energy:" in ln]
    assert len(ref) == 3, ref
    assert _same(out, ref, STEPS), (out, ref, err)


def test_uniform_force_is_the_evolvers(tmp_path):
    """REF moves by the distance part of the gradient plus half its charge
    part (measured with v_force; the steps test above compares g)."""
    s = Session.load(_octagon(tmp_path, ["uniform_knot_energy"]), out=io.StringIO()).surface
    t = s.evaluate()
    idx = np.arange(s.nv)
    w = np.ones(s.nv)
    full = KN.uniform_knot_gradient(t, None, idx, w)
    force = KN.uniform_knot_force(t, None, idx, w)
    assert np.abs(force - full).max() > 1e-3


def test_proj_gradient_and_hessians_refused(tmp_path):
    out, err = io.StringIO(), io.StringIO()
    sess = Session.load(_octagon(tmp_path, ["proj_knot_energy"]), out=out, err=err)
    with pytest.raises(Exception, match="gradient of method proj_knot_energy"):
        sess.run("g 1\n")
    for name in METHODS:
        assert (lookup(name).no_hessian is None) == (name == "knot_energy")


def test_knot_energy_closed_form_and_node_charge(tmp_path):
    sess = Session.load(_octagon(tmp_path, ["knot_energy"]), out=io.StringIO())
    s = sess.surface
    t = s.evaluate()
    idx = np.arange(s.nv)
    D = _X[:, None] - _X[None]
    r2 = (D ** 2).sum(-1)
    np.fill_diagonal(r2, np.inf)
    assert abs(KN.knot(t, None, idx).sum() - (1 / r2).sum()) <= 1e-12 * (1 / r2).sum()
    s.extra[("vertex", "node_charge")] = np.arange(1.0, 9.0)
    q = np.arange(1.0, 9.0)
    want = (np.outer(q, q) / r2).sum()
    assert abs(KN.knot(t, None, idx).sum() - want) <= 1e-12 * want


# the gradients of the values where g moves otherwise (REF's force) or is refused
TRUE = {"uniform_knot_energy": KN.uniform_knot_gradient,
        "proj_knot_energy": KN.proj_knot_gradient}


def _fd(s, entry, w, h=1e-6):
    idx = np.arange(s.nv if entry.etype == "vertex" else s.ne)
    grad = TRUE.get(entry.name, entry.gradient)(s.evaluate(), None, idx, w)
    return grad, central_gradient(s, method_energy(entry, idx, w), h)


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("power", [2.0, 3.0])
def test_gradients_against_central_differences(tmp_path, method, power):
    s = Session.load(_octagon(tmp_path, [method]), out=io.StringIO()).surface
    s.params["knot_power"] = power
    entry = lookup(method)
    n = s.nv if entry.etype == "vertex" else s.ne
    grad, num = _fd(s, entry, np.linspace(0.5, 1.5, n))
    assert np.abs(grad - num).max() <= FD * max(1.0, np.abs(grad).max())


def test_knot_energy_hessian_against_the_gradient(tmp_path):
    s = Session.load(_octagon(tmp_path, ["knot_energy"]), out=io.StringIO()).surface
    s.params["knot_power"] = 3.0
    w = np.linspace(0.5, 1.5, s.nv)
    idx = np.arange(s.nv)
    H = KN.knot_hessian(s.evaluate(), None, idx, w).toarray()
    X0 = s.X.copy()
    num = np.zeros_like(H)
    h = 1e-6
    for i in range(s.nv):
        for k in range(3):
            g = []
            for sg in (1, -1):
                s.X = X0.copy()
                s.X[i, k] += sg * h
                g.append(KN.knot_gradient(s.evaluate(), None, idx, w).ravel())
            num[:, 3 * i + k] = (g[0] - g[1]) / (2 * h)
    s.X = X0
    assert np.abs(H - num).max() <= FD * max(1.0, np.abs(H).max())


def test_segment_distances():
    P0 = np.array([[0.0, 0, 0], [0, 0, 0], [0, 0, 0]])
    P1 = np.array([[1.0, 0, 0], [1, 0, 0], [1, 0, 0]])
    Q0 = np.array([[0.5, 1, 2], [2, 0, 1], [-1, -2, 0]])
    Q1 = np.array([[0.5, -1, 2], [3, 0, 1], [-3, -2, 0]])
    want = [2.0, np.sqrt(2.0), np.sqrt(5.0)]       # crossing above, end to end, corner
    assert np.allclose(KN.segment_distances(P0, P1, Q0, Q1), want, rtol=0, atol=1e-15)


def test_buck_denominator_error(tmp_path):
    # edges 1 and 3 of this quadrilateral have no common vertex and δ ≤ 0:
    # the Evolver stops loading with error 1543
    p = tmp_path / "thin.fe"
    p.write_text("string\nspace_dimension 3\nquantity b energy method buck_knot_energy global\n"
                 "vertices\n1 0 0 0\n2 1 0 0\n3 1 2 0\n4 0 1 1\n"
                 "edges\n1 1 2\n2 2 3\n3 3 4\n4 4 1\n")
    with pytest.raises(Exception, match="Buck denominator nonpositive"):
        Session.load(str(p), out=io.StringIO(), err=io.StringIO())


@pytest.mark.skipif(not os.path.exists(os.path.join(EXAMPLES, "knotty.fe")),
                    reason="evolver-doc examples not installed")
def test_knotty_agrees_with_the_evolver(evolver, tmp_path):
    f = os.path.join(EXAMPLES, "knotty.fe")
    script = "v\ng 3\nprint knot_length.pressure\n"
    ref, out, err = _run_both(evolver, f, script, tmp_path)
    pick = lambda lines: [ln for ln in lines if "energy" in ln or "length" in ln
                          or ln.strip()[:1] in "-0123456789"]
    ref, out = pick(ref), pick(out)
    assert len(ref) >= 12, ref
    assert _same(out, ref, STEPS), (out, ref, err)
