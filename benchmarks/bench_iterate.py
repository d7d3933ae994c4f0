#!/usr/bin/env python3
"""Per-iteration benchmark: seconds per ``g`` step and per ``hessian`` step,
pyevolver vs. evolver-nox-d, on icospheres with a fixed body volume.

For each level (default 4, 5, 6 = 5,120, 20,480, 81,920 facets; data made by
``make_icosphere.py`` if missing) and each program, in fresh processes:

* evolver-nox-d: wall time of ``load; g K; q`` minus that of ``load; q``
  (best of ``--repeat``), divided by K; the same with ``hessian``;
* pyevolver: in one child process, load, one warm-up ``g 1``, then the wall
  time of ``g K`` / K, then one ``hessian`` (modules imported beforehand, as
  start-up is subtracted from the Evolver's times too).

Both programs' final energies after ``g K`` are printed; they agree to the
first lines' 1e-9 on these files.  Prints a table with ratios
(pyevolver / evolver); a ratio below 1 means pyevolver is faster.

    PYTHONPATH=/work/main python benchmarks/bench_iterate.py [--levels 4 5 6] [--steps 5]

Goals (issue 3): not slower than the Evolver at 5,120 facets, at least 3x
faster at 81,920; cost per iteration linear in the facet count.
"""
import argparse
import os
import subprocess
import sys

from _common import REPO, bending_file, icosphere_file, wall

CHILD = r"""
import io, sys, time
from pyevolver import Session
import pyevolver.evolve.hessian   # module import (scipy.sparse.linalg, ~0.1 s) is start-up
s = Session.load(sys.argv[1], out=io.StringIO())
k = int(sys.argv[2])
s.g(1)
t0 = time.perf_counter(); s.g(k); t1 = time.perf_counter()
e = s.total_energy
t2 = time.perf_counter()
if sys.argv[3] == "1":
    s.hessian(echo=False)
t3 = time.perf_counter()
print((t1 - t0) / k, t3 - t2, repr(e))
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[4, 5, 6])
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--evolver", default="evolver-nox-d")
    ap.add_argument("--vesicle", action="store_true",
                    help="issue 5: star_perp_sq_mean_curvature energy, area fixed by a "
                         "quantity and the body volume fixed (no hessian column)")
    ap.add_argument("--bending", action="store_true",
                    help="star_perp_sq_mean_curvature energy plus unit surface tension, "
                         "body volume fixed (no fixed quantity, so REF's hessian runs too)")
    a = ap.parse_args()
    env = dict(os.environ)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    rows = []
    for lev in a.levels:
        f = bending_file(lev) if a.bending else icosphere_file(lev, vesicle=a.vesicle)
        nf = 20 * 4 ** lev
        base, _ = wall([a.evolver, "-p1", f], "q\nq\n", a.repeat)
        gk, out = wall([a.evolver, "-p1", f], f"g 1\ng {a.steps}\nq\nq\n", a.repeat)
        g1, _ = wall([a.evolver, "-p1", f], "g 1\nq\nq\n", a.repeat)
        # the Hessian single-threaded (REF's -p1 Hessian loses terms)
        g1s = g1 if a.vesicle else wall([a.evolver, f], "g 1\nq\nq\n", a.repeat)[0]
        hs = g1s if a.vesicle else wall([a.evolver, f], "g 1\nhessian\nq\nq\n",
                                        a.repeat)[0]
        ref_g = (gk - g1) / a.steps
        ref_h = hs - g1s
        ref_e = [l for l in out.splitlines() if "energy:" in l][-1].split("energy:")[1].split()[0]
        p = subprocess.run([sys.executable, "-c", CHILD, f, str(a.steps),
                            "0" if a.vesicle else "1"], capture_output=True,
                           text=True, env=env, timeout=3600)
        if p.returncode != 0:
            raise SystemExit("pyevolver failed: " + p.stderr[-800:])
        py_g, py_h, py_e = p.stdout.split()
        rows.append((nf, float(py_g), ref_g, float(py_h), ref_h, float(py_e), float(ref_e)))
        print(f"level {lev}: {nf} facets done", file=sys.stderr)
    print(f"{'facets':>8} {'py g [s]':>10} {'evolver g':>10} {'ratio':>7} "
          f"{'py hess':>9} {'ev hess':>9} {'ratio':>7}  energy rel diff")
    for nf, pg, rg, ph, rh, pe, re_ in rows:
        hess = (f"{ph:9.3f} {rh:9.3f} {ph / rh:7.2f}" if rh > 0 else f"{'-':>9} {'-':>9} {'-':>7}")
        print(f"{nf:8d} {pg:10.4f} {rg:10.4f} {pg / rg:7.2f} {hess}  "
              f"{abs(pe - re_) / abs(re_):.1e}")
    if len(rows) > 1:
        a0, a1 = rows[0], rows[-1]
        print(f"per-facet cost growth (g), {a0[0]} -> {a1[0]} facets: "
              f"pyevolver x{(a1[1] / a1[0]) / (a0[1] / a0[0]):.2f}, "
              f"evolver x{(a1[2] / a1[0]) / (a0[2] / a0[0]):.2f}")


if __name__ == "__main__":
    main()
