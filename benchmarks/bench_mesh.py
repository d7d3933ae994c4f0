#!/usr/bin/env python3
"""Mesh-upkeep benchmark (issue 4): one ``r`` and one ``u`` sweep on a surface
of 81,920 facets, pyevolver vs. evolver-nox-d.

Surfaces (made by ``make_icosphere.py`` if missing): the level-6 icosphere
(``r``: 81,920 -> 327,680 facets) and the same sphere with its vertices moved
tangentially by 0.3 of the mean edge length (seed 0), on which ``u`` has
thousands of edges to flip (7,720).

* evolver-nox-d: wall time of ``load; CMD; q`` minus that of ``load; q``
  (best of ``--repeat`` fresh processes);
* pyevolver: in one child process, load, then the wall time of the
  command (``Session.refine`` / ``Session.equiangulate``; best of
  ``--repeat`` on fresh loads).

Both programs' report lines (counts after ``r``, flips of ``u``) and total
areas after the command are printed and must agree (the script exits 2 when
they do not).  Ratios are pyevolver / evolver: below 1 means pyevolver is
faster.  Goal (issue 4): no slower than the Evolver.

    PYTHONPATH=/work/main python benchmarks/bench_mesh.py [--level 6] [--repeat 3]
"""
import argparse
import os
import subprocess
import sys

from _common import REPO, icosphere_file, wall

CHILD = r"""
import io, sys, time
from pyevolver import Session
import pyevolver.remesh.refine, pyevolver.remesh.equiangulate   # imports are start-up
path, cmd, repeat = sys.argv[1], sys.argv[2], int(sys.argv[3])
best = None
for _ in range(repeat):
    out = io.StringIO()
    s = Session.load(path, out=out)
    t0 = time.perf_counter()
    if cmd == "r":
        s.refine()
    else:
        s.equiangulate()
    dt = time.perf_counter() - t0
    best = dt if best is None else min(best, dt)
print(best, repr(s.total_area))
print(out.getvalue().strip().splitlines()[-1])
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--level", type=int, default=6)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--evolver", default="evolver-nox-d")
    a = ap.parse_args()
    env = dict(os.environ)
    env["PYTHONPATH"] = REPO + os.pathsep + env.get("PYTHONPATH", "")
    rows, bad = [], False
    for cmd, jitter in (("r", 0.0), ("u", 0.3)):
        f = icosphere_file(a.level, jitter)
        base, _ = wall([a.evolver, "-p1", f], "q\nq\n", a.repeat)
        tot, out = wall([a.evolver, "-p1", f],
                        f'{cmd}\nprintf "AREA %.17g\\n", total_area\nq\nq\n', a.repeat)
        ref_t = tot - base
        lines = out.splitlines()
        ref_report = [l for l in lines if l.startswith(("Vertices:", "Edges switched"))][-1].strip()
        ref_area = float([l for l in lines if l.startswith("AREA")][-1].split()[1])
        p = subprocess.run([sys.executable, "-c", CHILD, f, cmd, str(a.repeat)],
                           capture_output=True, text=True, env=env, timeout=3600)
        if p.returncode != 0:
            raise SystemExit("pyevolver failed: " + p.stderr[-800:])
        first, report = p.stdout.strip().splitlines()
        py_t, py_area = (float(x) for x in first.split())
        same = report.strip() == ref_report and abs(py_area - ref_area) <= 1e-12 * ref_area
        bad |= not same
        rows.append((cmd, os.path.basename(f), py_t, ref_t, report.strip(), same))
    print(f"{'cmd':>3} {'surface':>32} {'pyevolver [s]':>14} {'evolver [s]':>12} {'ratio':>6}  "
          "report (same as REF?)")
    for cmd, name, pt, rt, rep, same in rows:
        print(f"{cmd:>3} {name:>32} {pt:14.3f} {rt:12.3f} {pt / rt:6.2f}  {rep} ({same})")
    if bad:
        sys.exit(2)


if __name__ == "__main__":
    main()
