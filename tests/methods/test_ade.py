"""Area-difference elasticity and spontaneous curvature as a datafile
(pyevolver.studies.phase_ade.ade_header): ``∫(H − h_zero)² dA`` by a
squared mean curvature method with ``h_zero = c0/2``, plus the FUNCTION
quantity ``ade_k (mci.value − ade_m0)²`` of a ``mean_curvature_integral``
instance.

Expected numbers: evolver-nox-d 2.70 on the same file (written by
:func:`_ade_file`), obtained with

    printf 'printf "%.15g %.15g %.15g %.15g\\n", willmore.value, mci.value,
            ade.value, total_energy\\ng 5\\n(the same printf)\\nq\\nq\\n'
      | evolver-nox-d -p1 FILE

and the analytic gradient against central differences.
"""
import io
import re

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.evolve import gradient as GR
from pyevolver.studies.meshes import fe_text, icosphere
from pyevolver.studies.phase_ade import ade_header
from finite_differences import assert_gradient, central_gradient
from tolerances import PRINTED, STEPS

#: REF's (willmore, mci, ade, total energy) after loading, the five g
#: energies, and the four values after them
REF = {
    "star_perp_sq_mean_curvature": (
        (6.54578595926009, 12.8626814578181, 0.345834916850258, 6.89162087611035),
        (6.86043105861728, 6.73891482522650, 6.67238944374521, 6.62543149523094,
         6.58944478519911),
        (5.84688930786127, 12.4158303807937, 0.74255547733784, 6.58944478519911)),
    "normal_sq_mean_curvature": (
        (6.56272770112295, 12.8626814578181, 0.345834916850258, 6.9085626179732),
        (6.87972269084636, 6.75902755282741, 6.69316603274498, 6.64700814902658,
         6.61173780026167),
        (5.8686582444818, 12.415333891824, 0.743079555779862, 6.61173780026167)),
}
PRINT = 'printf "%.15g %.15g %.15g %.15g\\n", willmore.value, mci.value, ade.value, total_energy'


def _ade_file(path, method, c0=0.8, alpha=1.5, m0=1.1):
    """A perturbed ellipsoid (42 vertices) with the ADE energy, no surface
    tension, volume fixed at 3.5."""
    X, F = icosphere(1)
    rng = np.random.default_rng(0)
    X = X * np.array([1.3, 1.0, 0.8]) + 0.03 * rng.standard_normal(X.shape)
    txt = fe_text(X, F, header=ade_header(c0, alpha, m0, area=4 * np.pi, method=method),
                  face_attrs="tension 0")
    txt += "\nbodies\n1 " + " ".join(str(i + 1) for i in range(len(F))) + " volume 3.5\n"
    with open(path, "w") as fh:
        fh.write(txt)
    return str(path)


def _floats(text):
    return [float(x) for x in re.findall(r"-?\d+\.\d+(?:e[-+]?\d+)?", text)]


@pytest.mark.parametrize("method", sorted(REF))
def test_ade_datafile_prints_the_evolvers_numbers(tmp_path, method):
    out = io.StringIO()
    s = Session.load(_ade_file(tmp_path / "ade.fe", method), out=out, err=io.StringIO())
    s.run(PRINT + "\ng 5\n" + PRINT)
    lines = out.getvalue().strip().splitlines()
    first, last = _floats(lines[-7]), _floats(lines[-1])
    steps = [_floats(ln)[1] for ln in lines[-6:-1]]
    start, g5, end = REF[method]
    assert first == pytest.approx(start, rel=PRINTED)
    assert steps == pytest.approx(g5, rel=STEPS)
    assert last == pytest.approx(end, rel=STEPS)


@pytest.mark.parametrize("method", sorted(REF))
def test_ade_energy_gradient_matches_differences(tmp_path, method):
    """The whole energy (bending with h_zero + the ADE function of ∫H dA)."""
    s = Session.load(_ade_file(tmp_path / "ade.fe", method), out=io.StringIO())
    S = s.surface
    g = GR.energy_gradient(S.evaluate())
    num = central_gradient(S, lambda surf: surf.evaluate().energy)
    assert_gradient(g, num)
    # the ADE part alone is non-trivial here: M is not at its preferred value
    q = s.totals.quantity_values
    assert q["ade"] > 0.3


def test_ade_header_without_alpha_is_plain_helfrich():
    h = ade_header(c0=-0.4, method="normal_sq_mean_curvature")
    assert "h_zero = c0/2" in h and "mci" not in h


def test_ade_header_refuses_methods_without_h_zero():
    with pytest.raises(ValueError, match="h_zero"):
        ade_header(method="star_sq_mean_curvature")


def test_docs_example_is_the_headers_output():
    import os
    here = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    with open(os.path.join(here, "docs", "phase.md")) as fh:
        text = fh.read()
    block = "\n".join("    " + ln for ln in ade_header(0.8, 1.5, 1.1).splitlines())
    assert block in text


# -- h_zero in the MDSB cotangent energy (pyevolver's own method) --------------------------

def _cotan_file(path, h0, level=1, perturb=True):
    X, F = icosphere(level)
    if perturb:
        rng = np.random.default_rng(0)
        X = X * np.array([1.3, 1.0, 0.8]) + 0.03 * rng.standard_normal(X.shape)
    hdr = ("" if h0 is None else f"parameter h_zero = {h0!r}\n") + \
        "quantity willmore energy method cotan_sq_mean_curvature global\n"
    with open(path, "w") as fh:
        fh.write(fe_text(X, F, header=hdr, face_attrs="tension 0"))
    return str(path)


@pytest.mark.parametrize("h0", [0.4, -0.7])
def test_cotan_h_zero_gradient_matches_differences(tmp_path, h0):
    s = Session.load(_cotan_file(tmp_path / "c.fe", h0), out=io.StringIO())
    S = s.surface
    num = central_gradient(S, lambda surf: surf.evaluate().energy)
    assert_gradient(GR.energy_gradient(S.evaluate()), num)


def test_cotan_h_zero_zero_is_the_plain_energy(tmp_path):
    e = [Session.load(_cotan_file(tmp_path / f"c{k}.fe", h0), out=io.StringIO())
         .surface.evaluate().energy for k, h0 in enumerate((None, 0.0))]
    assert e[0] == e[1]


@pytest.mark.parametrize("h0", [0.5, 2.0, -1.0])
def test_cotan_h_zero_on_the_unit_sphere(tmp_path, h0):
    """Icospheres on the unit sphere: E → ∫(H − h0)² dA = 4π(1 − h0)² (H = 1
    with outward facets), the error shrinking about 4× per refinement."""
    exact = 4 * np.pi * (1 - h0) ** 2
    err = [abs(Session.load(_cotan_file(tmp_path / f"s{lv}.fe", h0, lv, False),
                            out=io.StringIO()).surface.evaluate().energy - exact)
           for lv in (2, 3)]
    assert err[1] < 0.01 * max(exact, 4 * np.pi) and err[1] < err[0] / 3
