"""pyevolver.evolve.optparams: OPTIMIZING_PARAMETER moved by ``g``.

A hexagonal film whose boundary circle has the optimizing radius ``rr``
(small scales, so that the shrinking circle stays well away from 0):
the parameter values after ``g`` steps (fixed and optimizing scale, after
``r``) against evolver-nox-d run live, its numerical gradient against the
closed form, the dump round trip and the refusals by name."""
import io

import numpy as np
import pytest
from comparison import _same
from reference import run_reference
from tolerances import STEPS

import pyevolver
from pyevolver.evolve import optparams as OP
from pyevolver.session.core import Session


def _run_both(evolver, datafile, script, tmp_path):
    """The Evolver's output lines (subprocess) and pyevolver's (in this
    process, which saves the interpreter's start-up): ``(None, ref, out, err)``."""
    ref = run_reference(evolver, datafile, script, cwd=str(tmp_path), timeout=120)
    out, err = io.StringIO(), io.StringIO()
    sess = Session.load(datafile, out=out, err=err)
    sess.run(script)
    return None, ref, out.getvalue().rstrip("\n").split("\n"), err.getvalue()


HEXAGON = """optimizing_parameter rr = 1.2 {opts}
boundary 1 parameters 1
x1: rr*cos(p1)
x2: rr*sin(p1)
x3: 0
vertices
1 0 0 {z}
2 0 boundary 1 fixed
3 1.0471975511965976 boundary 1 fixed
4 2.0943951023931953 boundary 1 fixed
5 3.141592653589793 boundary 1 fixed
6 4.1887902047863905 boundary 1 fixed
7 5.235987755982989 boundary 1 fixed
edges
1 2 3 boundary 1 fixed
2 3 4 boundary 1 fixed
3 4 5 boundary 1 fixed
4 5 6 boundary 1 fixed
5 6 7 boundary 1 fixed
6 7 2 boundary 1 fixed
7 1 2
8 1 3
9 1 4
10 1 5
11 1 6
12 1 7
faces
1 7 1 -8
2 8 2 -9
3 9 3 -10
4 10 4 -11
5 11 5 -12
6 12 6 -7
{bodies}
"""


def _hexagon(tmp_path, opts="pscale = 0.3", z=0.1, bodies=""):
    p = tmp_path / "hexagon.fe"
    p.write_text(HEXAGON.format(opts=opts, z=z, bodies=bodies))
    return str(p)


def _numbers(lines):
    return [ln for ln in lines if ln.strip() and (ln.strip()[0] in "-0123456789")]


@pytest.mark.parametrize("opts", ["pscale = 0.3", "pdelta = 0.001", "", "pscale = 0.5"])
def test_parameter_moves_as_in_the_evolver(evolver, tmp_path, opts):
    f = _hexagon(tmp_path, opts)
    pr = 'printf "%.15g %.15g\\n", rr, vertex[1].z\n'
    script = ("m 0.05\ng 1\n" + pr + "g 1\n" + pr + "optimize 0.04\ng 3\n" + pr
              + "r\ng 2\n" + pr)
    _, ref, out, err = _run_both(evolver, f, script, tmp_path)
    ref = [ln for ln in _numbers(ref) if len(ln.split()) == 2]
    out = [ln for ln in _numbers(out) if len(ln.split()) == 2]
    assert len(ref) == 4, ref
    assert _same(out, ref, STEPS), (out, ref, err)


@pytest.mark.parametrize("opts", ["pdelta = 0.001", "pdelta = 0.003 pscale = 1"])
def test_parameter_moves_with_conj_grad_as_in_the_evolver(evolver, tmp_path, opts):
    """conj_grad: the parameters join the CG sums (velocity·grad, and
    grad·oldgrad for Polak-Ribiere) and move along their plain gradient."""
    f = _hexagon(tmp_path, opts)
    pr = 'printf "%.15g %.15g %.15g\\n", rr, vertex[1].z, total_energy\n'
    script = "U\ng 2\n" + pr + "ribiere\ng 1\n" + pr + "ribiere\ng 1\n" + pr
    _, ref, out, err = _run_both(evolver, f, script, tmp_path)
    ref = [ln for ln in _numbers(ref) if len(ln.split()) == 3]
    out = [ln for ln in _numbers(out) if len(ln.split()) == 3]
    assert len(ref) == 3, ref
    assert _same(out, ref, STEPS), (out, ref, err)


def test_gradient_is_the_derivative_of_the_hexagon_area(tmp_path):
    # flat regular hexagon of radius rr: E = (3√3/2) rr², dE/drr = 3√3 rr
    sess = pyevolver.load(_hexagon(tmp_path, "", z=0.0))
    s = sess.surface
    assert OP.names(s) == ["rr"]
    g = OP.gradient(s)
    assert abs(g[0] - 3 * np.sqrt(3) * 1.2) <= 1e-7
    assert s.params["rr"] == 1.2          # left as it was
    OP.set_values(s, np.array([1.5]))
    assert abs(s.evaluate().energy - 1.5 * np.sqrt(3) * 1.5 ** 2) <= 1e-12


def test_dump_keeps_the_declaration(tmp_path):
    sess = pyevolver.load(_hexagon(tmp_path, "pdelta = 0.001 pscale = 0.3"))
    out = tmp_path / "d.fe"
    sess.run(f'dump "{out}"')
    line = next(ln for ln in out.read_text().splitlines() if " rr " in ln)
    assert line.startswith("OPTIMIZING_PARAMETER rr = 1.2 pdelta = 0.001 pscale = 0.")
    assert pyevolver.load(str(out)).surface.optimizing["rr"] == pytest.approx((0.001, 0.3))


@pytest.mark.parametrize("cmd", ["hessian", "newton", "bfgs", "U; g"])
def test_unsupported_combinations_are_refused_by_name(tmp_path, cmd):
    # _hexagon's parameter has PSCALE 0.3: with conj_grad refused (REF's CG
    # sums with a PSCALE other than 1 are not matched)
    sess = pyevolver.load(_hexagon(tmp_path))
    with pytest.raises(pyevolver.errors.PyEvolverError,
                       match="not supported in pyevolver: OPTIMIZING_PARAMETER with"):
        sess.run(cmd)


def _torus_sheet(n=3):
    """A 3x3 elastic sheet in a torus cell whose x period is the optimizing
    parameter ``ll`` (1.2; the form factors are those of the cell with ll = 1)."""
    h = 1.0 / n
    lines = ["optimizing_parameter ll = 1.2 pscale = 0.5",
             "define facet attribute poisson_ratio real",
             "define facet attribute form_factors real[3]",
             "quantity st energy modulus 20 method linear_elastic global",
             "torus", "periods", "ll 0 0", "0 1 0", "0 0 1", "", "vertices"]

    def vid(i, j):
        return (j % n) * n + (i % n) + 1
    for j in range(n):
        for i in range(n):
            z = float(0.05 * np.sin(2 * np.pi * i / n + 1) * np.cos(2 * np.pi * j / n))
            lines.append(f"{vid(i, j)} {i * 1.2 / n!r} {j / n!r} {z!r}")
    lines.append("\nedges")
    edges = {}
    k = 0
    for j in range(n):
        for i in range(n):
            for di, dj in [(1, 0), (0, 1), (1, 1)]:
                k += 1
                edges[(i, j, di, dj)] = k
                wx = "+" if i + di >= n else "*"
                wy = "+" if j + dj >= n else "*"
                lines.append(f"{k} {vid(i, j)} {vid(i + di, j + dj)} {wx} {wy} *")
    lines.append("\nfaces")
    f = 0
    for j in range(n):
        for i in range(n):
            e10, e11, e01 = edges[(i, j, 1, 0)], edges[(i, j, 1, 1)], edges[(i, j, 0, 1)]
            eup, etop = edges[((i + 1) % n, j, 0, 1)], edges[(i, (j + 1) % n, 1, 0)]
            f += 1
            lines.append(f"{f} {e10} {eup} -{e11} tension 0 poisson_ratio 0.3 "
                         f"form_factors {{{h * h!r}, {h * h!r}, {2 * h * h!r}}}")
            f += 1
            lines.append(f"{f} {e11} -{etop} -{e01} tension 0 poisson_ratio 0.3 "
                         f"form_factors {{{2 * h * h!r}, {h * h!r}, {h * h!r}}}")
    return "\n".join(lines) + "\n"


def test_torus_period_parameter_with_an_elastic_sheet(evolver, tmp_path):
    p = tmp_path / "tor.fe"
    p.write_text(_torus_sheet())
    pr = 'printf "%.15g %.15g\\n", ll, total_energy\n'
    _, ref, out, err = _run_both(evolver, str(p), pr + "g 5\n" + pr + "m 0.01\ng 2\n" + pr,
                                 tmp_path)
    def keep(lines):
        return [ln for ln in lines
                if "area:" in ln or (_numbers([ln]) and len(ln.split()) == 2)]
    ref, out = keep(ref), keep(out)
    assert len(ref) == 10, ref
    assert _same(out, ref, STEPS), (out, ref, err)


def test_fix_and_unfix_toggle_a_parameter(evolver, tmp_path):
    # manual: "unfix rr" makes a plain parameter optimizing (its PSCALE kept)
    p = tmp_path / "plain.fe"
    p.write_text(HEXAGON.format(opts="pscale = 0.3", z=0.1, bodies="")
                 .replace("optimizing_parameter", "parameter"))
    pr = 'printf "%.15g\\n", rr\n'
    script = ("m 0.1\ng 1\n" + pr + "unfix rr\ng 1\n" + pr + "fix rr\ng 1\n" + pr
              + "unfix rr\ng 1\n" + pr)
    _, ref, out, err = _run_both(evolver, str(p), script, tmp_path)
    ref = [ln for ln in _numbers(ref) if len(ln.split()) == 1]
    out = [ln for ln in _numbers(out) if len(ln.split()) == 1]
    assert len(ref) == 4 and ref[0].strip() == "1.2" and ref[1] != ref[0], ref
    assert _same(out, ref, STEPS), (out, ref, err)
