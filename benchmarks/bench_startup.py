#!/usr/bin/env python3
"""Start-up benchmark (issue 24): ``printf 'q\\n' | pyevolver datafiles/cube.fe``.

Runs ``python -m pyevolver datafiles/cube.fe`` with stdin ``q``, the Evolver
(``evolver-nox-d -p1``) on the same file and the bare interpreters
(``python -c pass``, ``python -c "import numpy"``), alternating, ``--repeat``
times each; prints the median and best wall and CPU times (user + system of
the child).  Compiled modules are cached
as for an installed package (``_common.pyevolver_env``), after one warm-up
run each.  Issue 24's goal: 0.2 s of wall time for pyevolver.

    PYTHONPATH=. python benchmarks/bench_startup.py [--repeat 10] [--pyevolver ROOT]
        [--label after] [--doc docs/performance.md]

``--doc`` writes the table between ``<!-- bench_startup LABEL -->`` and
``<!-- /bench_startup LABEL -->``.
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import time

from _common import REPO, pyevolver_env, write_doc

GOAL = 0.2


def run(cmd, stdin, env):
    """Wall seconds of one child (which must succeed)."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, env=env, cwd=REPO)
    _, err = p.communicate(stdin.encode())
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise SystemExit(f"{cmd} failed: {err.decode()[-500:]}")
    return wall          # (the CPU time: from the children's total, measure())


def measure(cmd, stdin, env):
    """(wall seconds, CPU seconds of the child)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall = run(cmd, stdin, env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--evolver", default="evolver-nox-d")
    ap.add_argument("--pyevolver", default=REPO, help="checkout whose pyevolver runs")
    ap.add_argument("--label", default="after")
    ap.add_argument("--doc", default=None, help="Markdown file to write the table into")
    a = ap.parse_args()
    env = pyevolver_env(a.pyevolver)
    cube = os.path.join(REPO, "datafiles", "cube.fe")
    programs = {
        "`pyevolver datafiles/cube.fe`, `q`": ([sys.executable, "-m", "pyevolver", cube],
                                                 "q\n", env),
        "`evolver-nox-d -p1 datafiles/cube.fe`, `q`": ([a.evolver, "-p1", cube], "q\nq\n",
                                                         None),
        "`python -c pass`": ([sys.executable, "-c", "pass"], "", env),
        "`python -c \"import numpy\"`": ([sys.executable, "-c", "import numpy"], "", env),
    }
    for cmd, stdin, e in programs.values():         # warm-up (compiled modules, caches)
        run(cmd, stdin, e)
    res = {name: [] for name in programs}
    for _ in range(a.repeat):
        for name, (cmd, stdin, e) in programs.items():
            res[name].append(measure(cmd, stdin, e))
    lines = [f"| start-up ({a.label}) | wall median [s] | wall best [s] | CPU median [s] | "
             "CPU best [s] |", "|---|---|---|---|---|"]
    for name, rs in res.items():
        w, c = [r[0] for r in rs], [r[1] for r in rs]
        lines.append(f"| {name} | {statistics.median(w):.3f} | {min(w):.3f} | "
                     f"{statistics.median(c):.3f} | {min(c):.3f} |")
    first = next(iter(res.values()))
    best = min(r[0] for r in first)
    lines.append(f"| goal: pyevolver ≤ {GOAL:g} s of wall time | "
                 f"{'met' if statistics.median(r[0] for r in first) <= GOAL else 'missed'} | "
                 f"{'met' if best <= GOAL else 'missed'} | | |")
    text = "\n".join(lines)
    print(text)
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}", file=sys.stderr)
    if a.doc:
        write_doc(a.doc, f"bench_startup {a.label}", text)


if __name__ == "__main__":
    main()
