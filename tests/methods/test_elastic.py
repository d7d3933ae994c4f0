"""pyevolver.methods.elastic: linear_elastic and the relaxed_elastic_A family.

Values against closed forms (a uniformly stretched triangle) and against
evolver-nox-d run live (per-facet values and ``g`` steps on a small file
written from the manual, and the shipped mylarcube.fe); analytic gradients
against central differences on every branch of the relaxed energy."""
import io
import os

import numpy as np
import pytest
from comparison import _same
from reference import run_reference
from conftest import EXAMPLES
from finite_differences import assert_gradient, assert_hessian_columns, central_gradient, method_energy
from tolerances import PRINTED, ROUNDOFF, STEPS

import pyevolver
from pyevolver.methods import elastic as EL
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


# two facets sharing an edge, each with its own Poisson ratio and form factors;
# facet 1 is stretched in one direction only, facet 2 in both
SHEET = """define facet attribute poisson_ratio real
define facet attribute form_factors real[3]
{extra}
quantity st energy method {method} global
quantity st1 info_only method relaxed_elastic1_A global
quantity st2 info_only method relaxed_elastic2_A global
vertices
1 0 0 0 fixed
2 1.2 0 0.1
3 0.1 0.9 0
4 1.1 1.3 0.2
5 -0.7 0.6 0.3
edges
1 1 2
2 2 3
3 3 1
4 2 4
5 4 3
6 3 5
7 5 1
faces
1 1 2 3 poisson_ratio 0.3 form_factors {{1, 0, 1}} {w1}
2 4 5 -2 poisson_ratio 0.25 form_factors {{1, 0.5, 1.2}} {w2}
3 -3 6 7 poisson_ratio 0.35 form_factors {{1.4, 0.2, 1.9}} {w3}
"""


def _sheet(tmp_path, method="linear_elastic", leb=False):
    extra = "define facet attribute LEBweight real" if leb else ""
    w = ("LEBweight 2", "LEBweight 0.5", "") if leb else ("", "", "")
    p = tmp_path / f"sheet_{method}_{int(leb)}.fe"
    p.write_text(SHEET.format(extra=extra, method=method, w1=w[0], w2=w[1], w3=w[2]))
    return str(p)


def _numbers(lines):
    return [ln for ln in lines if ln.strip() and (ln.strip()[0] in "-0123456789")]


@pytest.mark.parametrize("method,leb", [("linear_elastic", False), ("relaxed_elastic_A", False),
                                        ("relaxed_elastic_A", True),
                                        ("dirichlet_elastic", False)])
def test_values_and_steps_agree_with_the_evolver(evolver, tmp_path, method, leb):
    f = _sheet(tmp_path, method, leb)
    script = ("foreach facet ff do printf \"%.15g %.15g %.15g\\n\", ff.st, ff.st1, ff.st2\n"
              "printf \"%.15g\\n\", total_energy\ng 4\n"
              "printf \"%.15g %.15g\\n\", st1.value, st2.value\n")
    _, ref, out, err = _run_both(evolver, f, script, tmp_path)
    ref, out = _numbers(ref), _numbers(out)
    assert len(ref) == 9, ref
    assert _same(out[:4], ref[:4], PRINTED), (out, ref, err)
    assert _same(out[4:], ref[4:], STEPS), (out, ref, err)


def test_uniform_stretch_has_the_closed_form(tmp_path):
    # the right triangle with legs 1 stretched by s along x: C = diag((s²-1)/2, 0),
    # E = A0 c² / (2 (1 - ν²)), both stresses positive (the relaxed energy is the
    # same); also squeezed along y (σ₂ < 0): the relaxed energy is the uniaxial A0 c²/2
    s_, nu = 1.1, 0.3
    c = (s_ ** 2 - 1) / 2
    idx = np.array([0])
    for ylen in (1.0, 0.9):
        text = SHEET.format(extra="", method="linear_elastic", w1="", w2="", w3="")
        text = text.replace("2 1.2 0 0.1", f"2 {s_} 0 0").replace("3 0.1 0.9 0", f"3 0 {ylen} 0")
        p = tmp_path / "stretch.fe"
        p.write_text(text)
        t = pyevolver.load(str(p)).surface.evaluate()
        rel = [lookup(n).value(t, None, idx)[0] for n in
               ("relaxed_elastic_a", "relaxed_elastic1_a", "relaxed_elastic2_a")]
        if ylen == 1.0:
            e_lin = EL.linear_elastic(t, None, idx)[0]
            assert abs(e_lin - 0.5 * c ** 2 / (2 * (1 - nu ** 2))) <= ROUNDOFF
            assert rel == [e_lin, 0.0, e_lin]
        else:
            assert abs(rel[0] - 0.5 * c ** 2 / 2) <= ROUNDOFF
            assert rel[1:] == [rel[0], 0.0]


def test_degenerate_form_factors_give_zero_and_missing_attributes_stop(tmp_path):
    text = SHEET.format(extra="", method="linear_elastic", w1="", w2="", w3="")
    p = tmp_path / "zero.fe"
    p.write_text(text.replace("form_factors {1, 0, 1}", ""))
    t = pyevolver.load(str(p)).surface.evaluate()
    assert EL.linear_elastic(t, None, np.array([0]))[0] == 0.0
    p2 = tmp_path / "missing.fe"
    p2.write_text(text.replace("define facet attribute poisson_ratio real\n", "")
                  .replace("poisson_ratio 0.3 ", "").replace("poisson_ratio 0.25 ", "")
                  .replace("poisson_ratio 0.35 ", ""))
    with pytest.raises(pyevolver.errors.PyEvolverError, match="poisson_ratio missing"):
        pyevolver.load(str(p2))


@pytest.mark.parametrize("name", ["linear_elastic", "relaxed_elastic_a", "relaxed_elastic1_a",
                                  "relaxed_elastic2_a", "dirichlet_elastic"])
def test_gradient_matches_central_differences(tmp_path, name):
    # a random 3x3-vertex sheet, form factors from a random reference shape, so
    # that facets fall in all three branches of the relaxed energy
    rng = np.random.default_rng(4)
    g = np.array([[i, j, 0.0] for j in range(3) for i in range(3)])
    F = []
    for j in range(2):
        for i in range(2):
            a = 3 * j + i
            F += [[a, a + 1, a + 4], [a, a + 4, a + 3]]
    F = np.array(F)
    s = pyevolver.Surface.from_arrays(g + 0.15 * rng.standard_normal(g.shape), F)
    ref = g + 0.15 * rng.standard_normal(g.shape)
    a, b = ref[s.F[:, 1]] - ref[s.F[:, 0]], ref[s.F[:, 2]] - ref[s.F[:, 0]]
    s.extra[("facet", "form_factors")] = np.stack(
        [np.einsum("ij,ij->i", a, a), np.einsum("ij,ij->i", a, b),
         np.einsum("ij,ij->i", b, b)], 1)
    s.extra[("facet", "poisson_ratio")] = rng.uniform(0.1, 0.45, s.nf)
    m = lookup(name)
    idx = np.arange(s.nf)
    w = rng.uniform(0.5, 2.0, s.nf)
    t = s.evaluate()
    if name.startswith("relaxed"):
        _, branch, _, _, _ = EL._relaxed(t, idx, name)
        assert set(branch.tolist()) == {0, 1, 2}, branch
    grad = m.gradient(t, None, idx, w)
    assert_gradient(grad, central_gradient(s, method_energy(m, idx, w)))


def test_mylarcube_agrees_with_the_evolver(evolver, tmp_path):
    script = ('printf "%.15g\\n", total_energy\ng 5\n'
              'printf "%.15g %.15g %.15g\\n", total_energy, stretch1.value, stretch2.value\n')
    _, ref, out, err = _run_both(evolver, os.path.join(EXAMPLES, "mylarcube.fe"), script,
                                 tmp_path)
    ref = [ln for ln in ref if "area:" in ln or ln[:1].isdigit() or ln[:1] == "-"]
    out = [ln for ln in out if "area:" in ln or ln[:1].isdigit() or ln[:1] == "-"]
    assert len(ref) == 7, ref
    assert _same(out, ref, 1e-6), (out, ref, err)


@pytest.mark.parametrize("name", ["linear_elastic", "dirichlet_elastic"])
def test_hessian_matches_differences_of_the_gradient(name):
    rng = np.random.default_rng(6)
    X = np.array([[0, 0, 0], [1, 0, 0.1], [0.1, 1, 0], [1.1, 1.2, 0.2]]) \
        + 0.05 * rng.standard_normal((4, 3))
    s = pyevolver.Surface.from_arrays(X, np.array([[0, 1, 2], [1, 3, 2]]))
    s.extra[("facet", "form_factors")] = np.array([[1.0, 0.1, 0.9], [1.2, -0.2, 1.1]])
    s.extra[("facet", "poisson_ratio")] = np.array([0.3, 0.2])
    m = lookup(name)
    idx = np.arange(s.nf)
    w = np.array([1.5, 0.7])
    D = m.hessian(s.evaluate(), None, idx, w).toarray()
    assert np.abs(D - D.T).max() <= 1e-12 * max(1.0, np.abs(D).max())
    assert_hessian_columns(s, D, lambda s: m.gradient(s.evaluate(), None, idx, w))


def test_the_evolvers_dump_loads_with_the_same_energy(evolver, tmp_path):
    # REF writes form_factors and poisson_ratio into its dump; read back here
    dmp = tmp_path / "mylar.dmp"
    ref = run_reference(evolver, os.path.join(EXAMPLES, "mylarcube.fe"),
                        f'g 3\ndump "{dmp}"\nprintf "%.15g %.15g\\n", total_energy, '
                        'stretch.value\n', cwd=str(tmp_path))
    e_ref, st_ref = (float(v) for v in _numbers(ref)[-1].split())
    sess = pyevolver.load(str(dmp))
    assert abs(sess.value("total_energy") - e_ref) <= STEPS * abs(e_ref)
    assert abs(sess.value("stretch.value") - st_ref) <= STEPS * abs(st_ref)


def _sheet5d(tmp_path, rng, energy="linear_elastic_B", tension=0.0):
    """A 3x3-vertex sheet in SPACE_DIMENSION 5: x1..x3 a jiggled grid, x4, x5
    another (the unstrained plane), random Poisson ratios, every vertex free."""
    g = np.array([[i, j] for j in range(3) for i in range(3)], float)
    X = np.concatenate([g + 0.15 * rng.standard_normal(g.shape),
                        0.1 * rng.standard_normal((9, 1)),
                        g + 0.15 * rng.standard_normal(g.shape)], axis=1)
    F = []
    for j in range(2):
        for i in range(2):
            a = 3 * j + i
            F += [[a, a + 1, a + 4], [a, a + 4, a + 3]]
    E = sorted({tuple(sorted((f[k], f[(k + 1) % 3]))) for f in F for k in range(3)})
    eid = {e: k + 1 for k, e in enumerate(E)}

    def fe(a, b):
        return eid[(a, b)] if (a, b) in eid else -eid[(b, a)]
    nu = rng.uniform(0.1, 0.45, len(F))
    text = [f"space_dimension 5\nquantity st energy method {energy} global",
            "define facet attribute poisson_ratio real\nvertices"]
    text += [f"{k + 1} " + " ".join(f"{x:.17g}" for x in row) for k, row in enumerate(X)]
    text += ["edges"] + [f"{k + 1} {a + 1} {b + 1}" for k, (a, b) in enumerate(E)]
    text += ["faces"] + [f"{k + 1} {fe(a, b)} {fe(b, c)} {fe(c, a)} tension {tension} "
                         f"poisson_ratio {nu[k]:.17g}" for k, (a, b, c) in enumerate(F)]
    p = tmp_path / f"sheet5d_{energy}.fe"
    p.write_text("\n".join(text) + "\n")
    return pyevolver.load(str(p), out=io.StringIO())


@pytest.mark.parametrize("name", ["linear_elastic_b", "relaxed_elastic", "relaxed_elastic1",
                                  "relaxed_elastic2"])
def test_five_dimensional_gradient_matches_central_differences(tmp_path, name):
    # the strained coordinates x1..x3 and the reference plane x4, x5 both move
    rng = np.random.default_rng(7)
    sess = _sheet5d(tmp_path, rng)
    s = sess.surface
    assert s.X.shape == (9, 5)
    m = lookup(name)
    idx = np.arange(s.nf)
    w = rng.uniform(0.5, 2.0, s.nf)
    t = s.evaluate()
    if name.startswith("relaxed"):
        _, branch, _, _, _ = EL._relaxed(t, idx, name)
        assert set(branch.tolist()) >= {1, 2}, branch
    grad = m.gradient(t, None, idx, w)
    assert grad.shape == (9, 5)
    assert np.abs(grad[:, 3:]).max() > 1e-3          # the reference plane is pulled too
    assert_gradient(grad, central_gradient(s, method_energy(m, idx, w), dims=5))


def test_five_dimensional_methods_agree_with_the_three_dimensional_ones(tmp_path):
    # linear_elastic_B on (x1..x3 | x4, x5) is linear_elastic with the form
    # factors of the x4, x5 sides; relaxed_elastic{,1,2} the _A variants
    rng = np.random.default_rng(3)
    s5 = _sheet5d(tmp_path, rng).surface
    t5 = s5.evaluate()
    S = t5.facet_S
    ra, rb = S[:, 0, 3:], S[:, 1, 3:]
    s3 = pyevolver.Surface.from_arrays(s5.X[:, :3], s5.F)
    s3.extra[("facet", "form_factors")] = np.stack(
        [np.einsum("ij,ij->i", ra, ra), np.einsum("ij,ij->i", ra, rb),
         np.einsum("ij,ij->i", rb, rb)], 1)
    s3.extra[("facet", "poisson_ratio")] = s5.extra[("facet", "poisson_ratio")]
    t3 = s3.evaluate()
    idx = np.arange(s5.nf)
    for b, a in [("linear_elastic_b", "linear_elastic"), ("relaxed_elastic", "relaxed_elastic_a"),
                 ("relaxed_elastic1", "relaxed_elastic1_a"),
                 ("relaxed_elastic2", "relaxed_elastic2_a")]:
        v5, v3 = lookup(b).value(t5, None, idx), lookup(a).value(t3, None, idx)
        assert np.allclose(v5, v3, rtol=ROUNDOFF, atol=0), b


def test_five_dimensional_methods_need_space_dimension_5(tmp_path):
    p = tmp_path / "b3.fe"
    p.write_text(SHEET.format(extra="", method="linear_elastic_B", w1="", w2="", w3="")
                 .replace("relaxed_elastic1_A", "relaxed_elastic1"))
    with pytest.raises(pyevolver.errors.PyEvolverError) as exc:     # located at the quantity
        pyevolver.load(str(p), out=io.StringIO())
    assert "not supported in pyevolver: linear_elastic_b in SPACE_DIMENSION 3" in str(exc.value)


@pytest.mark.parametrize("method", ["linear_elastic", "relaxed_elastic_A"])
def test_hessian_step_with_one_free_vertex_as_the_evolver(evolver, tmp_path, method):
    """With one free vertex REF's elastic Hessian is exact even with its
    worker thread (-p1): its `hessian` steps are pyevolver's.  (With two free
    vertices on one facet REF's threaded matrix is not the Hessian:
    docs/differences.md, tests/reference/test_elastic_hessian_reference.py.)"""
    from comparison import run_pyevolver
    from reference import run_reference
    here = os.path.dirname(os.path.dirname(__file__))
    text = open(os.path.join(here, "data", "elastic_two_free.fe")).read()
    text = text.replace("4 1.2 1.1 -0.1\n", "4 1.2 1.1 -0.1 fixed\n")
    text = text.replace("method linear_elastic", f"method {method}")
    p = tmp_path / "one_free.fe"
    p.write_text(text)
    script = ('hessian_normal off\nhessian\nhessian\n'
              'printf "%.15g %.15g %.15g\\n", vertex[3].x, vertex[3].y, vertex[3].z\n')
    ref = run_reference(evolver, str(p), script)
    rc, out, err = run_pyevolver(str(p), script)
    assert [float(v) for v in out[-1].split()] == pytest.approx(
        [float(v) for v in ref[-1].split()], abs=1e-9)


@pytest.mark.parametrize("name", ["relaxed_elastic_a", "relaxed_elastic1_a", "relaxed_elastic2_a"])
def test_relaxed_hessian_matches_differences_of_the_gradient(name):
    """The relaxed methods' analytic Hessian, branch by branch: facet 0 is
    stretched in one direction and compressed in the other (λ₁²/2), facet 1
    stretched in both (the linear density), facet 2 compressed (zero)."""
    rng = np.random.default_rng(8)
    X = np.array([[0, 0, 0], [1.3, 0, 0.05], [0.05, 0.8, 0], [1.25, 1.2, 0.1], [-0.1, 0.9, 0.0],
                  [0.6, 1.2, 0.05]]) + 0.02 * rng.standard_normal((6, 3))
    s = pyevolver.Surface.from_arrays(X, np.array([[0, 1, 2], [1, 3, 2], [2, 5, 4]]))
    s.extra[("facet", "form_factors")] = np.array([[1.0, 0.05, 1.0], [1.0, -0.3, 0.8],
                                                  [0.8, 0.1, 0.9]])
    s.extra[("facet", "poisson_ratio")] = np.array([0.3, 0.25, 0.4])
    idx = np.arange(s.nf)
    _, branch, _, _, _ = EL._relaxed(s.evaluate(), idx, name)
    assert branch.tolist() == [1, 2, 0]
    m = lookup(name)
    w = np.array([1.5, 0.7, 1.1])
    D = m.hessian(s.evaluate(), None, idx, w).toarray()
    assert np.abs(D).max() > 0.1
    assert np.abs(D - D.T).max() <= 1e-12 * max(1.0, np.abs(D).max())
    assert_hessian_columns(s, D, lambda s: m.gradient(s.evaluate(), None, idx, w))
