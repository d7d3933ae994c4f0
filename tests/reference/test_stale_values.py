"""Where evolver-nox-d prints a stale value, pyevolver prints the right one.

REF does not recalculate after a quantity's or a method instance's modulus
changes: ``total_energy`` and ``q.value`` keep their old values until
something (``recalc``, ``g``) recomputes them.  pyevolver recomputes at once.
Each check runs the change in both programs: pyevolver's value right after
the change must equal REF's value after an explicit ``recalc`` (and REF's
value before ``recalc`` is shown to be the stale one, so the test documents
a real difference).  The list is in docs/differences.md.
"""
import io
import os

import pytest

from pyevolver import Session

from reference import run_reference

HERE = os.path.dirname(os.path.dirname(__file__))
TOP = """
QUANTITY qa ENERGY MODULUS 1 METHOD facet_area GLOBAL
METHOD_INSTANCE mi METHOD facet_area GLOBAL
QUANTITY qb ENERGY FUNCTION mi.value^2
"""


def _cube_q():
    """datafiles/cube.fe without its read section, with the quantities above."""
    with open(os.path.join(HERE, "..", "datafiles", "cube.fe"), encoding="utf-8") as fh:
        text = fh.read()
    return TOP + text[:text.index("\nread")] + "\n"

CASES = [
    ("qa.modulus := 3", ["total_energy", "qa.value"]),
    ("mi.modulus := 2", ["total_energy", "qb.value", "mi.value"]),
]


def _values(lines):
    return [float(ln.split()[1]) for ln in lines if ln.startswith("V ")]


@pytest.mark.parametrize("change,exprs", CASES)
def test_value_after_modulus_change_is_fresh(evolver, tmp_path, change, exprs):
    path = tmp_path / "q.fe"
    path.write_text(_cube_q())
    show = "".join(f'printf "V %.15g\\n", {e}\n' for e in exprs)
    ref = _values(run_reference(evolver, str(path), change + "\n" + show + "recalc\n" + show,
                                cwd=str(tmp_path)))
    stale, fresh = ref[:len(exprs)], ref[len(exprs):]
    assert stale != fresh, "REF no longer prints a stale value: update docs/differences.md"
    out = io.StringIO()
    s = Session.load(str(path), out=out)
    s.run(change + "\n" + show)
    got = _values(out.getvalue().splitlines())
    assert got == pytest.approx(fresh, rel=1e-12), (got, fresh, stale)
