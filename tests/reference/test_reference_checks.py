"""The reference checks of ``shared/reference-checks`` (scripts copied to
``tests/data/checks``), run live through evolver-nox-d and pyevolver.

How outputs are compared (the checks' README):

* report lines (``Vertices: ..``, ``Edges switched: ..``, ...) and the
  integers of ``RESULT`` lines: exactly;
* ``g`` progress lines: the first three of every block within 1e-9 relative
  in area and energy and to 4 significant digits in scale; lines printed
  once REF's energy has converged to round-off (equal to the line before to
  1e-13) are round-off noise in both programs and are not compared;
* ``hessian`` lines and ``RESULT`` numbers: 1e-8 relative (pressures 1e-6;
  1e-12 in the mesh-upkeep checks 02, 04, 05, 16),
  with an absolute floor of 1e-12 for coordinates that are zero up to
  round-off; a ``scale=`` printed after convergence is noise and skipped.
"""
import os
import re

import pytest

from conftest import example
from reference import run_reference
from comparison import run_pyevolver
from tolerances import PRINTED, STEPS

CHECKS = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data", "checks")

# issue 3 (evolve) and issue 4 (mesh upkeep) checks that pyevolver runs today
RUN = {
    "01_cube_g10": "cube.fe",
    "02_cube_refine_counts": "cube.fe",
    "03_cube_fixed_scale": "cube.fe",
    "04_quad_equi_V": "quad.fe",
    "05_cube_V_rawv_rawestv": "cube.fe",
    "06_cube_pressure_hessian": "cube.fe",
    "07_mound": "mound.fe",
    "08_catbody": "catbody.fe",
    "09_twointor": "twointor.fe",
    "16_mesh_ops": "cube.fe",
    "19_column": "column.fe",
    "20_qmound_quantity": "qmound.fe",
    # issue 5 (curvature energies): datafiles written for the checks, copied here
    "10_curvature_methods": "icosa_curv.fe",
    "11_blob_h0": "blob.fe",
    "12_blob_noh0": "blob0.fe",
    # bending under fixed area and volume: REF's restoring loop fails to
    # converge on the first step (WARNING 1055) and pyevolver follows it
    "13_vesicle": "vesicle.fe",
    # ADE: bending with h_zero under fixed area, volume and ∫H dA
    "14_vesicle_ade": "vesicle_ade.fe",
    "15_legacy_sqcurv": "icosa_legacy.fe",
    "21_legacy_toggles": "blob_legacy.fe",
}
CURVATURE = {"10_curvature_methods", "11_blob_h0", "12_blob_noh0", "15_legacy_sqcurv",
             "21_legacy_toggles"}

_NUM = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_PROGRESS = re.compile(r"^\s*(\d+)\.\s+area:\s*(\S+)\s+energy:\s*(\S+)(?:\s+scale:\s*(\S+))?")


def _classify(lines):
    """Split output into progress lines (with their block position) and the rest."""
    prog, other = [], []
    pos = 0
    prev_n = None
    for ln in lines:
        m = _PROGRESS.match(ln)
        if m:
            n = int(m.group(1))
            pos = pos + 1 if prev_n is not None and n == prev_n - 1 else 0
            prev_n = n
            prog.append((pos, float(m.group(2)), float(m.group(3)),
                         None if m.group(4) is None else float(m.group(4))))
            continue
        prev_n = None
        s = ln.strip()
        if not s or s.startswith(("Element memory", "Total data memory", "Enter command")):
            continue
        other.append(s)
    return prog, other


def _close(a, b, rtol, atol=1e-12):
    return abs(a - b) <= rtol * max(abs(a), abs(b)) + atol


def _compare_progress(ours, ref):
    assert len(ours) == len(ref), f"{len(ours)} progress lines, REF {len(ref)}"
    last_e = None
    for k, (o, r) in enumerate(zip(ours, ref)):
        pos, area, energy, scale = r
        converged = last_e is not None and pos > 0 and abs(energy - last_e) <= 1e-13 * abs(energy)
        last_e = energy
        if converged:
            continue
        if pos < 3:
            tol = STEPS
            assert _close(o[1], area, tol), (k, o, r)
            assert _close(o[2], energy, tol), (k, o, r)
            if scale is not None:
                assert _close(o[3], scale, 1e-4, 1e-12), (k, o, r)


# mesh-upkeep checks: numbers after each operation within 1e-12 (issue 4)
MESH = {"02_cube_refine_counts", "04_quad_equi_V", "05_cube_V_rawv_rawestv", "16_mesh_ops",
        "17_pop"}


def _compare_other(ours, ref, rtol_result=1e-8):
    assert len(ours) == len(ref), "\n".join(ours) + "\n---- REF\n" + "\n".join(ref)
    table_pressure = False        # rows under a `v` header ending in "pressure"
    for o, r in zip(ours, ref):
        if not _NUM.findall(r):
            table_pressure = r.split()[-1:] == ["pressure"]
        wo, wr = _NUM.split(o), _NUM.split(r)
        assert [w.strip() for w in wo] == [w.strip() for w in wr], (o, r)
        no, nr = _NUM.findall(o), _NUM.findall(r)
        names = [w.strip().split()[-1] if w.strip() else "" for w in wr[:-1]]
        for j, (name, a, b) in enumerate(zip(names, no, nr)):
            if table_pressure and j == len(nr) - 1:
                name = "pressure"
            if name.startswith("scale"):
                continue                                   # noise once converged
            # counts and ids exactly; a float that %g printed without a point on
            # one side only ("1" against 0.999999999999999: check 06's volume,
            # restored to 1 in REF and to 1 - 1e-15 in pyevolver) as a number
            if not any("." in x or "e" in x.lower() for x in (a, b)):
                assert a == b, (o, r)
                continue
            rtol = 1e-6 if "pressure" in name or "pressure" in r.split()[0:1] else rtol_result
            assert _close(float(a), float(b), rtol), (name, o, r)


@pytest.mark.parametrize("check", sorted(RUN))
def test_reference_check(evolver, check, tmp_path):
    with open(os.path.join(CHECKS, check + ".cmd")) as fh:
        script = fh.read()
    script = script.rsplit("q\nq", 1)[0]
    own = os.path.join(CHECKS, RUN[check])
    datafile = own if os.path.exists(own) else example(RUN[check])
    ref = run_reference(evolver, datafile, script, cwd=str(tmp_path), timeout=300)
    code, out, err = run_pyevolver(datafile, script + "q\n", cwd=str(tmp_path))
    assert code == 0, err
    # stderr holds only the warnings REF also writes there (check 13)
    assert all(not l.strip() or l.startswith(("WARNING 1055", "Total difference"))
               for l in err.splitlines()), err
    po, oo = _classify(out)
    pr, orr = _classify(ref)
    # REF's line editor wraps the echo of long input lines; drop the pieces
    cmd_lines = [c.strip() for c in script.splitlines() if c.strip()]
    orr = [l for l in orr if l.startswith("RESULT") or
           not any(c.endswith(l) and c != l for c in cmd_lines)]
    _compare_progress(po, pr)
    _compare_other(oo, orr, PRINTED if check in MESH | CURVATURE else 1e-8)
