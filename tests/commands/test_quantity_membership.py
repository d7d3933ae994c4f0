"""``set vv quantityname`` / ``set facet[3] quantity name`` / ``unset ...``
(REF manual, "set ... quantityname"): elements put on or taken off a
non-global named quantity, including through a ``foreach`` variable, with
its effect on the quantity's value, on the energy and on ``g`` and ``r``.
Compared with the Evolver run live on a cube carrying three quantities."""
import os

from comparison import _same, run_pyevolver
from conftest import EXAMPLES
from reference import run_reference

HEAD = """quantity gb energy method star_gauss_curvature
quantity va info_only method vertex_scalar_integral
scalar_integrand: z+1
quantity fa energy modulus 2 method facet_area
"""

SCRIPT = """printf "%.15g %.15g %.15g %.15g\\n", gb.value, va.value, fa.value, total_energy
set vertex[1] gb
foreach vertex vv where id < 4 do set vv va
set facet[3] fa
printf "%.15g %.15g %.15g %.15g\\n", gb.value, va.value, fa.value, total_energy
foreach vertex vv do {if id > 4 then set vv gb}
unset vertex[2] va
unset facet[3] fa
set facet[5] quantity fa
printf "%.15g %.15g %.15g %.15g\\n", gb.value, va.value, fa.value, total_energy
g 3
printf "%.15g %.15g %.15g %.15g\\n", gb.value, va.value, fa.value, total_energy
foreach facet ff where id==7 do set ff fa
unset vertex[6] gb
r
g 2
printf "%.15g %.15g %.15g %.15g\\n", gb.value, va.value, fa.value, total_energy
"""


def test_set_and_unset_a_named_quantity_on_elements(evolver, tmp_path):
    cube = open(os.path.join(EXAMPLES, "cube.fe")).read()
    fe = tmp_path / "q.fe"
    fe.write_text(HEAD + cube[cube.index("vertices"):])
    ref = [ln for ln in run_reference(evolver, str(fe), SCRIPT, cwd=str(tmp_path))
           if len(ln.split()) == 4 and "." in ln and ":" not in ln]
    code, out, err = run_pyevolver(str(fe), SCRIPT + "q\n", cwd=str(tmp_path))
    ours = [ln for ln in out if len(ln.split()) == 4 and "." in ln and ":" not in ln]
    assert len(ref) == 4, ref           # the first line (0 0 0 6) has no "."
    assert _same(ours, ref, rtol=1e-10), (ours, ref, err)
    assert "not supported" not in err, err
