#!/usr/bin/env python3
"""Per-iteration benchmark (issues 3, 5, 24): CPU time of one ``g`` step,
pyevolver vs. evolver-nox-d, on prolate icospheres with a fixed body volume.

Surfaces (``make_icosphere.py``, made if missing; default levels 2, 3, 5, 6
= 320, 1,280, 20,480, 81,920 facets), stretched as in ``bench_hessian.py``
(``set vertex z z*1.5``, the body's target set to the new volume, ``g 2``):

* ``area``: facet tension 1 and the fixed body volume;
* ``bending``: ``star_perp_sq_mean_curvature`` plus facet tension 1 and the
  fixed body volume;
* ``vesicle`` (issue 5; not in the default run): ``star_perp_sq_mean_curvature``,
  tension 0, the area fixed by a quantity and the body volume fixed.

For each surface and program, fresh children run ``PREFIX; printf; q`` and
``PREFIX; g K; printf; q``, alternating programs and runs; the cost of one ``g`` is
the difference of the children's CPU times (user + system, ``os.wait4``)
divided by K, the median of ``--repeat`` pairs.  K (``--steps``) is by default
about 400,000 / facets, between 5 and 1,000, so that the small surfaces'
steps are measured over a few tenths of a second.  The Evolver runs without
worker threads, pyevolver in the default environment.  Both programs'
energies after the steps are printed (they agree step for step).

    PYTHONPATH=. python benchmarks/bench_iterate.py [--levels 2 3 5 6] [--cases area bending]
        [--repeat 3] [--steps K] [--pyevolver ROOT] [--label after] [--doc docs/performance.md]

``--doc`` writes the table into that Markdown file between the markers
``<!-- bench_iterate LABEL -->`` and ``<!-- /bench_iterate LABEL -->``.
Issue 24's goals: ratio (pyevolver / Evolver) at most 1.0 up to 20,480
facets and at most 0.33 at 81,920 (the "goal" column).
"""
import argparse
import os
import re
import statistics
import sys

from _common import (PROLATE, REPO, bending_file, cpu_run, icosphere_file, pyevolver_env,
                     write_doc)

PRINT = 'printf "RESULT %.17g\\n", total_energy\n'
FILES = {"area": lambda lev: icosphere_file(lev), "bending": bending_file,
         "vesicle": lambda lev: icosphere_file(lev, vesicle=True)}


def goal(nf):
    return 0.33 if nf >= 81920 else 1.0


def energy(out):
    m = re.findall(r"RESULT (\S+)", out)
    if not m:
        raise SystemExit("no RESULT line in:\n" + out[-800:])
    return float(m[-1])


def measure(programs, f, k, repeat):
    """{program: (median CPU seconds per g, energy after the steps)}."""
    cpu = {name: [] for name in programs}
    res = {}
    for cmd, env in programs.values():          # warm-up (file caches, compiled modules)
        cpu_run(cmd + [f], "q\nq\n", env)
    for _ in range(repeat):
        for name, (cmd, env) in programs.items():
            base = cpu_run(cmd + [f], PROLATE + PRINT + "q\nq\n", env)
            full = cpu_run(cmd + [f], PROLATE + f"g {k}\n" + PRINT + "q\nq\n", env)
            cpu[name].append((full[0] - base[0]) / k)
            res[name] = energy(full[2])
    return {name: (statistics.median(cpu[name]), res[name]) for name in programs}


def table(rows, label):
    head = (f"| case ({label}) | facets | steps | pyevolver CPU per `g` [ms] | Evolver CPU per "
            "`g` [ms] | ratio | goal | pyevolver energy | Evolver energy |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for case, nf, k, py, ref in rows:
        r = py[0] / ref[0] if ref[0] > 0 else float("inf")
        lines.append(f"| {case} | {nf:,} | {k} | {1e3 * py[0]:.3f} | {1e3 * ref[0]:.3f} | "
                     f"{r:.2f} | ≤ {goal(nf):g} {'met' if r <= goal(nf) else 'missed'} | "
                     f"{py[1]:.12g} | {ref[1]:.12g} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[2, 3, 5, 6])
    ap.add_argument("--cases", nargs="+", default=["area", "bending"], choices=sorted(FILES))
    ap.add_argument("--steps", type=int, default=None,
                    help="g steps per run (default about 400,000 / facets, 5 to 1,000)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--evolver", default="evolver-nox-d")
    ap.add_argument("--pyevolver", default=REPO, help="checkout whose pyevolver runs")
    ap.add_argument("--vesicle", action="store_true", help="the same as --cases vesicle")
    ap.add_argument("--bending", action="store_true", help="the same as --cases bending")
    ap.add_argument("--label", default="after")
    ap.add_argument("--doc", default=None, help="Markdown file to write the table into")
    a = ap.parse_args()
    cases = ["vesicle"] * a.vesicle + ["bending"] * a.bending or a.cases
    programs = {"py": ([sys.executable, "-m", "pyevolver"], pyevolver_env(a.pyevolver)),
                "ref": ([a.evolver], None)}
    rows = []
    for lev in a.levels:
        nf = 20 * 4 ** lev
        k = a.steps or max(5, min(1000, round(400000 / nf)))
        for case in cases:
            m = measure(programs, FILES[case](lev), k, a.repeat)
            rows.append((case, nf, k, m["py"], m["ref"]))
            print(f"{case} {nf} facets: ratio {m['py'][0] / max(m['ref'][0], 1e-12):.2f}, "
                  f"energies {m['py'][1]!r} {m['ref'][1]!r}", file=sys.stderr)
    text = table(rows, a.label)
    print(text)
    bad = [r for r in rows if abs(r[3][1] - r[4][1]) > 1e-5 * max(1.0, abs(r[4][1]))]
    for case, nf, *_ in bad:
        print(f"energies differ: {case} {nf}", file=sys.stderr)
    if a.doc:
        write_doc(a.doc, f"bench_iterate {a.label}", text)
    if bad:
        sys.exit(2)


if __name__ == "__main__":
    main()
