#!/usr/bin/env python3
"""Mesh-upkeep benchmark (issues 4, 24): one ``r``, one ``u`` sweep and one
``V`` on a surface of 81,920 facets, pyevolver vs. evolver-nox-d, in CPU time.

Surfaces (made by ``make_icosphere.py`` if missing): the level-6 icosphere
(``r``: 81,920 -> 327,680 facets) and the same sphere with its vertices moved
tangentially by 0.3 of the mean edge length (seed 0), on which ``u`` has
thousands of edges to flip (7,720) and ``V`` moves every vertex.

For each command and program, fresh children run ``load; printf ...; q``
and ``load; CMD; printf ...; q``, alternating programs and runs; the command's
cost is the difference of the children's CPU times (user + system, from
``os.wait4``), the median of ``--repeat`` pairs.  Both programs' report
lines (counts after ``r``, flips of ``u``) and total areas after the command
are printed and must agree (the script exits 2 when they do not).  Ratios
are pyevolver / evolver: below 1 means pyevolver is faster.  Issue 24's
goals: ``u`` at most 1.0, ``r`` and ``V`` at most 0.5.

    PYTHONPATH=. python benchmarks/bench_mesh.py [--level 6] [--repeat 3]
        [--pyevolver ROOT] [--label after] [--doc docs/performance.md]

``--doc`` writes the table into that Markdown file between the markers
``<!-- bench_mesh LABEL -->`` and ``<!-- /bench_mesh LABEL -->``.
"""
import argparse
import re
import statistics
import sys

from _common import REPO, cpu_run, icosphere_file, pyevolver_env, write_doc

PRINT = 'printf "AREA %.17g\\n", total_area\n'
COMMANDS = (("r", 0.0, 0.5), ("u", 0.3, 1.0), ("V", 0.3, 0.5))


def report(out):
    """(the command's report line or '', the area after it)."""
    lines = [ln.replace("Enter command:", "").strip() for ln in out.splitlines()]
    rep = [ln for ln in lines if ln.startswith(("Vertices:", "Edges switched"))]
    area = re.findall(r"AREA (\S+)", out)
    if not area:
        raise SystemExit("no AREA line in:\n" + out[-800:])
    return (rep[-1] if rep else ""), float(area[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--level", type=int, default=6)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--evolver", default="evolver-nox-d")
    ap.add_argument("--pyevolver", default=REPO, help="checkout whose pyevolver runs")
    ap.add_argument("--commands", nargs="+", default=[c for c, _, _ in COMMANDS])
    ap.add_argument("--label", default="after")
    ap.add_argument("--doc", default=None, help="Markdown file to write the table into")
    a = ap.parse_args()
    programs = {"py": ([sys.executable, "-m", "pyevolver"], pyevolver_env(a.pyevolver)),
                "ref": ([a.evolver], None)}
    rows, bad = [], False
    for cmd, jitter, goal in COMMANDS:
        if cmd not in a.commands:
            continue
        f = icosphere_file(a.level, jitter)
        cpu = {k: [] for k in programs}
        res = {}
        for prog, env in programs.values():          # warm-up (caches, compiled modules)
            cpu_run(prog + [f], "q\nq\n", env)
        for _ in range(a.repeat):
            for name, (prog, env) in programs.items():
                base = cpu_run(prog + [f], PRINT + "q\nq\n", env)
                full = cpu_run(prog + [f], f"{cmd}\n{PRINT}q\nq\n", env)
                cpu[name].append(full[0] - base[0])
                res[name] = report(full[2])
        (prep, parea), (rrep, rarea) = res["py"], res["ref"]
        same = prep == rrep and abs(parea - rarea) <= 1e-12 * abs(rarea)
        bad |= not same
        py, ref = statistics.median(cpu["py"]), statistics.median(cpu["ref"])
        rows.append((cmd, 20 * 4 ** a.level, py, ref, goal, prep or "-", same))
        print(f"{cmd}: ratio {py / ref if ref > 0 else float('inf'):.2f}, same as REF: {same}",
              file=sys.stderr)
    head = (f"| command ({a.label}) | facets | pyevolver CPU [s] | Evolver CPU [s] | ratio | "
            "goal | report (same as REF) |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for cmd, nf, py, ref, goal, rep, same in rows:
        r = py / ref if ref > 0 else float("inf")
        lines.append(f"| `{cmd}` | {nf:,} | {py:.3f} | {ref:.3f} | {r:.2f} | "
                     f"≤ {goal:g} {'met' if r <= goal else 'missed'} | {rep} ({same}) |")
    text = "\n".join(lines)
    print(text)
    if a.doc:
        write_doc(a.doc, f"bench_mesh {a.label}", text)
    if bad:
        sys.exit(2)


if __name__ == "__main__":
    main()
