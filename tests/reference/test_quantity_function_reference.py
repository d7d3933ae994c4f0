"""Quantity FUNCTIONs against evolver-nox-d: the names a FUNCTION may use
(issue 27: the constant ``pi`` was refused) and, in
``test_ade_hessian_steps``, ``hessian`` with a FUNCTION that is nonlinear
in its method instance's value (the area-difference-elasticity energy)."""
import io
import math

import pytest

import pyevolver
from reference import run_reference

TETRA = """
vertices
1 0 0 0
2 1 0 0
3 0 1 0
4 0 0 1

edges
1 1 2
2 2 3
3 3 1
4 1 4
5 2 4
6 3 4

faces
1 -3 -2 -1
2 1 5 -4
3 2 6 -5
4 3 4 -6

bodies
1 1 2 3 4 volume 0.1666666666666667
"""

#: FUNCTIONs with constants, a quantity's value and built-in functions;
#: ``mci`` is not GLOBAL (value 0, as the issue's file), ``mcg`` is
TOPS = [
    "method_instance mci method mean_curvature_integral\n"
    "quantity ade energy function kk*pi*(mci.value - 1)^2\n",
    "method_instance mcg method mean_curvature_integral global\n"
    "quantity ade energy function kk*e*(mcg.value - 1)^2 + red\n",
    "method_instance mcg method mean_curvature_integral global\n"
    "quantity other info_only method facet_area global\n"
    "quantity ade energy function kk*(mcg.value - 1)^2 + other.value\n",
    "method_instance mcg method mean_curvature_integral global\n"
    "quantity ade energy function maximum(mcg.value, 3) + (kk > 1 ? pi : e)\n",
]


@pytest.mark.parametrize("top", TOPS)
def test_function_names_as_ref(evolver, tmp_path, top):
    path = tmp_path / "pi.fe"
    path.write_text("parameter kk = 2\n" + top + TETRA)
    show = 'printf "V %.17g %.17g\\n", total_energy, ade.value\n'
    ref = [float(x) for ln in run_reference(evolver, str(path), show, cwd=str(tmp_path))
           if ln.startswith("V ") for x in ln.split()[1:]]
    out = io.StringIO()
    s = pyevolver.load(str(path), out=out, err=io.StringIO())
    s.run(show)
    got = [float(x) for ln in out.getvalue().splitlines() if ln.startswith("V ")
           for x in ln.split()[1:]]
    assert len(ref) == 2 and got == pytest.approx(ref, rel=1e-13), (got, ref)


def test_issue_number(tmp_path):
    """The issue's file: REF prints total_energy 8.64921071096402 (``print
    total_energy`` in evolver-nox-d -p1), the area 3/2 + √3/2 plus
    2π(0 − 1)² (closed form; ``mci`` is on no element)."""
    path = tmp_path / "pi.fe"
    path.write_text("parameter kk = 2\n" + TOPS[0] + TETRA)
    s = pyevolver.load(str(path), out=io.StringIO(), err=io.StringIO())
    assert s.value("total_energy") == pytest.approx(8.64921071096402, rel=1e-14)
    assert s.value("total_energy") == pytest.approx(1.5 + math.sqrt(3) / 2 + 2 * math.pi,
                                                    rel=1e-14)
