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

import pytest

from pyevolver import Session

from reference import run_reference

CUBE_Q = """
QUANTITY qa ENERGY MODULUS 1 METHOD facet_area GLOBAL
METHOD_INSTANCE mi METHOD facet_area GLOBAL
QUANTITY qb ENERGY FUNCTION mi.value^2
vertices
1 0 0 0
2 1 0 0
3 1 1 0
4 0 1 0
5 0 0 1
6 1 0 1
7 1 1 1
8 0 1 1
edges
1 1 2
2 2 3
3 3 4
4 4 1
5 5 6
6 6 7
7 7 8
8 8 5
9 1 5
10 2 6
11 3 7
12 4 8
faces
1 1 10 -5 -9
2 2 11 -6 -10
3 3 12 -7 -11
4 4 9 -8 -12
5 5 6 7 8
6 -4 -3 -2 -1
bodies
1 1 2 3 4 5 6 volume 1
"""

CASES = [
    ("qa.modulus := 3", ["total_energy", "qa.value"]),
    ("mi.modulus := 2", ["total_energy", "qb.value", "mi.value"]),
]


def _values(lines):
    return [float(ln.split()[1]) for ln in lines if ln.startswith("V ")]


@pytest.mark.parametrize("change,exprs", CASES)
def test_value_after_modulus_change_is_fresh(evolver, tmp_path, change, exprs):
    path = tmp_path / "q.fe"
    path.write_text(CUBE_Q)
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
