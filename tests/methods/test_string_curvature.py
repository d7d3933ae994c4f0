"""pyevolver.methods.string_curvature: sqcurve_string, sqcurve2_string and
sqcurve3_string against evolver-nox-d run live (values under parameter_1 and
curvature_power, ``g`` steps), against the series the Evolver uses
(``T = 2(1 − c) + (1 − c)²/3``) at one vertex, and their gradients against
central differences."""
import io

import numpy as np
import pytest
from comparison import _same, number_lines, run_both_in_process
from finite_differences import assert_gradient, central_gradient, method_energy
from tolerances import PRINTED, STEPS

from pyevolver.errors import UnsupportedError
from pyevolver.methods import string_curvature as SC
from pyevolver.methods.registry import lookup
from pyevolver.session.core import Session

POLY = [[0, 0, 0], [1, 0, 0.2], [1.3, 2, 0], [0, 1.2, 1], [-0.8, 0.4, 0.3]]


def _file(tmp_path, quantities, X=POLY, closed=True, decl=""):
    lines = ["string", "space_dimension 3", decl]
    lines += [f"quantity {n} energy {rest}" for n, rest in quantities]
    lines.append("vertices")
    lines += [f"{i + 1} {float(x[0])!r} {float(x[1])!r} {float(x[2])!r}" for i, x in enumerate(X)]
    lines.append("edges")
    n = len(X)
    lines += [f"{i + 1} {i + 1} {(i + 1) % n + 1}" for i in range(n if closed else n - 1)]
    p = tmp_path / "poly.fe"
    p.write_text("\n".join(lines) + "\n")
    return str(p)


_run_both = run_both_in_process
_numbers = number_lines


QS = [("qa", "method sqcurve_string global"),
      ("qb", "method sqcurve_string global parameter_1 3"),
      ("qc", "method sqcurve2_string global"),
      ("qd", "method sqcurve3_string global"),
      ("qe", "method sqcurve3_string global parameter_1 3")]


@pytest.mark.parametrize("closed", [True, False])
def test_values_agree_with_the_evolver(evolver, tmp_path, closed):
    f = _file(tmp_path, QS, closed=closed)
    names = [n for n, _ in QS]
    script = "".join(f'printf "%.15g\\n", {n}.value\n' for n in names)
    script += "curvature_power := 4\nrecalc\n" + 'printf "%.15g\\n", qa.value\n'
    ref, out, err = _run_both(evolver, f, script, tmp_path)
    ref, out = _numbers(ref), _numbers(out)
    assert len(ref) == len(names) + 1, ref
    assert _same(out, ref, PRINTED), (out, ref, err)


@pytest.mark.parametrize("rest", ["method sqcurve_string global",
                                  "method sqcurve_string global parameter_1 3",
                                  "method sqcurve3_string global"])
def test_steps_agree_with_the_evolver(evolver, tmp_path, rest):
    f = _file(tmp_path, [("qq", rest)])
    ref, out, err = _run_both(evolver, f, "g 3\n", tmp_path)
    ref = [ln for ln in ref if "energy:" in ln]
    out = [ln for ln in out if "energy:" in ln]
    assert len(ref) == 3, ref
    assert _same(out, ref, STEPS), (out, ref, err)


def test_one_vertex_series(tmp_path):
    t_ = 1.0
    X = [[-2.0, 0, 0], [0, 0, 0], [np.cos(t_), np.sin(t_), 0]]
    s = Session.load(_file(tmp_path, QS[:1], X=X, closed=False), out=io.StringIO()).surface
    t = s.evaluate()
    u = 1 - np.cos(t_)
    T = 2 * u + u * u / 3
    h = 1.5
    idx = np.arange(3)
    assert abs(SC.sqcurve(t, s.quantities["qa"].methods[0][0], idx).sum()
               - T / h) <= 1e-14
    assert abs(SC.sqcurve3(t, None, idx).sum() - T * (1 / 2 + 1) / 2) <= 1e-14
    assert abs(SC.sqcurve2(t, None, idx).sum() - np.sin(t_) ** 2 / h) <= 1e-14


H_ZERO = """string
space_dimension 2
define vertex attribute h_zero real
quantity qa energy method sqcurve2_string global
vertices
1 0 0 h_zero 0.3
2 1 0 h_zero -0.2
3 1.3 2 h_zero 0.5
4 0 1.2 h_zero 0.1
5 -0.8 0.4 h_zero 0.7
edges
1 1 2
2 3 2
3 3 4
4 4 5
5 5 1
"""


@pytest.mark.parametrize("cmds", ["g 3", "r\ng 3", "r\nr\ng 2"])
def test_h_zero_in_ring_order_agrees_with_the_evolver(evolver, tmp_path, cmds):
    """σ's sign follows REF's edge rings (edge 2 is reversed here), also
    after r; the vertex attribute h_zero."""
    p = tmp_path / "hzero.fe"
    p.write_text(H_ZERO)
    script = f'printf "%.15g\\n", qa.value\n{cmds}\nprintf "%.15g\\n", qa.value\n'
    ref, out, err = _run_both(evolver, str(p), script, tmp_path)
    pick = lambda lines: [ln for ln in lines if "energy:" in ln or ln.strip()[:1].isdigit()]
    ref, out = pick(ref), pick(out)
    assert len(ref) >= 4, ref
    assert _same(out, ref, STEPS), (out, ref, err)


def test_h_zero_variable_in_space_agrees_with_the_evolver(evolver, tmp_path):
    f = _file(tmp_path, QS[2:3], decl="parameter h_zero = 0.7")
    ref, out, err = _run_both(evolver, f, 'printf "%.15g\\n", qc.value\n', tmp_path)
    assert _same(_numbers(out), _numbers(ref), PRINTED), (out, ref, err)


def test_three_edges_at_a_vertex_refused(tmp_path):
    p = tmp_path / "tee.fe"
    p.write_text("string\nspace_dimension 2\nvertices\n1 0 0\n2 1 0\n3 2 0\n4 1 1\n"
                 "edges\n1 1 2\n2 2 3\n3 2 4\n")
    s = Session.load(str(p), out=io.StringIO()).surface
    with pytest.raises(UnsupportedError):
        SC.vertex_pairs(s, np.arange(s.nv))


@pytest.mark.parametrize("name,p", [("sqcurve_string", None), ("sqcurve_string", 3.0),
                                    ("sqcurve_string", 1.5), ("sqcurve2_string", None),
                                    ("sqcurve2_string", "h_zero"), ("sqcurve3_string", None)])
def test_gradients_against_central_differences(tmp_path, name, p):
    decl = "parameter h_zero = 0.6" if p == "h_zero" else ""
    p = None if p == "h_zero" else p
    s = Session.load(_file(tmp_path, [("qq", f"method {name} global")], decl=decl),
                     out=io.StringIO()).surface
    m = s.quantities["qq"].methods[0][0]
    m.parameter_1 = p
    entry = lookup(name)
    w = np.linspace(0.5, 1.5, s.nv)
    idx = np.arange(s.nv)
    fn = SC.sqcurve2_full_gradient if name == "sqcurve2_string" else entry.gradient
    grad = fn(s.evaluate(), m, idx, w)
    assert_gradient(grad, central_gradient(s, method_energy(entry, idx, w, m)))


def test_sqcurve2_gradient_refused_in_space(tmp_path):
    s = Session.load(_file(tmp_path, [("qq", "method sqcurve2_string global")]),
                     out=io.StringIO()).surface
    with pytest.raises(UnsupportedError, match="space dimension 3"):
        lookup("sqcurve2_string").gradient(s.evaluate(), None, np.arange(s.nv), np.ones(s.nv))


def _planar(tmp_path):
    X = [x[:2] for x in POLY]
    lines = ["string", "space_dimension 2", "quantity qq energy method sqcurve2_string global",
             "vertices"]
    lines += [f"{i + 1} {x[0]!r} {x[1]!r}" for i, x in enumerate(X)]
    lines += ["edges"] + [f"{i + 1} {i + 1} {i % 5 + 2 if i < 4 else 1}" for i in range(5)]
    p = tmp_path / "planar.fe"
    p.write_text("\n".join(lines) + "\n")
    return str(p)


def test_sqcurve2_steps_in_the_plane_agree_with_the_evolver(evolver, tmp_path):
    f = _planar(tmp_path)
    ref, out, err = _run_both(evolver, f, "g 3\n", tmp_path)
    ref = [ln for ln in ref if "energy:" in ln]
    out = [ln for ln in out if "energy:" in ln]
    assert len(ref) == 3, ref
    assert _same(out, ref, STEPS), (out, ref, err)


def test_string_mean_curvature_agrees_with_the_evolver(evolver, tmp_path):
    f = _file(tmp_path, [])
    script = ("foreach vertex vv do printf \"%.15g\\n\", vv.mean_curvature\n"
              "set vertex[2] x 0.5\n"
              "foreach vertex vv do printf \"%.15g\\n\", vv.mean_curvature\n")
    ref, out, err = _run_both(evolver, f, script, tmp_path)
    ref, out = _numbers(ref), _numbers(out)
    assert len(ref) == 10, ref
    assert _same(out, ref, PRINTED), (out, ref, err)


def test_string_mean_curvature_on_reversed_edges_agrees_with_the_evolver(evolver, tmp_path):
    """Edge 2 reversed: vertex 2 has both edges coming in, vertex 3 both
    going out (REF's sign follows the first edge of its ring)."""
    p = tmp_path / "rev.fe"
    p.write_text("string\nspace_dimension 2\nvertices\n1 0 0\n2 1 0\n3 1.3 2\n4 0 1.2\n"
                 "5 -0.8 0.4\nedges\n1 1 2\n2 3 2\n3 3 4\n4 4 5\n5 5 1\n")
    script = "foreach vertex vv do printf \"%.15g\\n\", vv.mean_curvature\nr\n" \
             "foreach vertex vv do printf \"%.15g\\n\", vv.mean_curvature\n"
    ref, out, err = _run_both(evolver, str(p), script, tmp_path)
    ref, out = _numbers(ref), _numbers(out)
    assert len(ref) == 15, ref
    assert _same(out, ref, PRINTED), (out, ref, err)


MARKED = """string
space_dimension 3
define edge attribute sqcurve_string_mark integer
quantity qm energy method sqcurve_string_marked global
quantity qs energy modulus 0 method sqcurve_string global
vertices
1 0 0 0
2 1 0 0.1
3 2 0.3 0
4 1 1 0.2
5 3 1 0
6 1.2 -1 0.3
edges
1 1 2 sqcurve_string_mark 1
2 2 3 sqcurve_string_mark 1
3 2 4
4 3 5 sqcurve_string_mark 1
5 6 2 sqcurve_string_mark 0
"""


def test_marked_agrees_with_the_evolver(evolver, tmp_path):
    p = tmp_path / "marked.fe"
    p.write_text(MARKED)
    script = ('printf "%.15g\\n", qm.value\ng 3\nset edge[2] sqcurve_string_mark 0\n'
              'set edge[3] sqcurve_string_mark 1\nrecalc\nprintf "%.15g\\n", qm.value\ng 2\n')
    ref, out, err = _run_both(evolver, str(p), script, tmp_path)
    pick = lambda lines: [ln for ln in lines if "energy:" in ln or ln.strip()[:1].isdigit()]
    ref, out = pick(ref), pick(out)
    assert len(ref) == 7, ref
    assert _same(out, ref, STEPS), (out, ref, err)


def test_string_sqcurve_attribute_is_zero_without_facets(evolver, tmp_path):
    f = _file(tmp_path, QS[:1])
    script = 'printf "%.15g\\n", max(vertex, sqcurve)\ng 2\nprintf "%.15g\\n", vertex[2].sqcurve\n'
    ref, out, err = _run_both(evolver, f, script, tmp_path)
    ref, out = _numbers(ref), _numbers(out)
    assert ref[0] == "0" and ref[-1] == "0", ref
    assert _same(out, ref, STEPS), (out, ref, err)
