#!/usr/bin/env python3
"""Load benchmark: pyevolver vs. evolver-nox-d on the same datafile.

For one datafile (default: the level-6 icosphere, 81,920 facets, generated with
``make_icosphere.py`` if missing) this times, each in a fresh process:

* pyevolver: read the datafile, build the surface, evaluate it once;
* ``evolver-nox-d -p1 FILE`` with stdin ``print total_energy / q / q``;
* the interpreter baseline ``python -c "import numpy, scipy.sparse, lark"``.

The programs run alternately; the time is the CPU time (user + system) of
each child from ``os.wait4``, the median of ``--repeat`` runs (the best wall
time is printed too); peak memory is the child's ``ru_maxrss`` (max over
the runs).  The script prints a table with pyevolver/evolver ratios (with
and without the interpreter baseline) and checks that both programs report
the same energy (relative difference <= 1e-12).

Run from the repository root::

    PYTHONPATH=. python benchmarks/bench_load.py [FILE] [--repeat 3]
        [--pyevolver ROOT] [--label after] [--doc docs/performance.md]

``--pyevolver ROOT`` loads with the checkout at ROOT; ``--doc`` writes the
table between ``<!-- bench_load LABEL -->`` and ``<!-- /bench_load LABEL -->``.

Goals (issue 24): CPU time and peak memory at most 1.5 times evolver-nox-d's.
"""

import argparse
import importlib.util
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import threading
import time

from _common import write_doc

# NB: this script deliberately imports nothing heavy (no numpy): on Linux a
# vfork()ed child's ru_maxrss can include the parent's RSS, so keeping this
# process small keeps the children's peak-memory numbers honest.

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
DEFAULT_FILE = os.path.join(HERE, "data", "icosphere_81920.fe")

TIME_GOAL = 1.5      # issue 24 (CPU time, memory)
MEM_GOAL = 1.5
REL_TOL = 1e-12

PYEVOLVER_CODE = (
    "import sys\n"
    "from pyevolver.datafile.reader import read_datafile\n"
    "from pyevolver.model.build import build_surface\n"
    "s = build_surface(read_datafile(sys.argv[1]))\n"
    "t = s.evaluate()\n"
    "print(repr(t.energy), repr(t.total_area), s.nv, s.ne, s.nf)\n"
)
BASELINE_CODE = "import numpy, scipy.sparse, lark"
EVOLVER_INPUT = "print total_energy\nq\nq\n"

_FLOAT_LINE = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*$")


class RunResult:
    def __init__(self, seconds, maxrss_kb, returncode, stdout, stderr, timed_out, cpu=0.0):
        self.seconds = seconds
        self.cpu = cpu
        self.maxrss_kb = maxrss_kb
        self.returncode = returncode
        self.stdout = stdout
        self.stderr = stderr
        self.timed_out = timed_out


def run_child(cmd, stdin_text=None, env=None, timeout=None):
    """Run ``cmd`` once; wall seconds and the child's own peak RSS (os.wait4)."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdin=subprocess.PIPE if stdin_text is not None
                             else subprocess.DEVNULL,
                             stdout=out, stderr=err, env=env)
        killed = []
        timer = None
        if timeout:
            def _kill():
                killed.append(True)
                try:
                    p.kill()
                except OSError:
                    pass
            timer = threading.Timer(timeout, _kill)
            timer.start()
        try:
            if stdin_text is not None:
                try:
                    p.stdin.write(stdin_text.encode())
                    p.stdin.close()
                except BrokenPipeError:
                    pass
            _, status, ru = os.wait4(p.pid, 0)
        finally:
            if timer is not None:
                timer.cancel()
        t1 = time.perf_counter()
        p.returncode = os.waitstatus_to_exitcode(status)  # already reaped
        out.seek(0)
        err.seek(0)
        return RunResult(t1 - t0, ru.ru_maxrss, p.returncode,
                         out.read().decode(errors="replace"),
                         err.read().decode(errors="replace"), bool(killed),
                         ru.ru_utime + ru.ru_stime)


def bench_all(specs, repeat, timeout=None):
    """Run the programs ``specs`` (name -> (cmd, stdin, env)) alternately,
    ``repeat`` times each (a program stops at its first failure).  Returns
    name -> ((median CPU seconds, max peak MB, best wall seconds) or None,
    a run)."""
    runs = {name: [] for name in specs}
    for i in range(repeat):
        for name, (cmd, stdin_text, env) in specs.items():
            if runs[name] and (runs[name][-1].timed_out or runs[name][-1].returncode):
                continue
            r = run_child(cmd, stdin_text, env, timeout)
            runs[name].append(r)
            status = ("TIMEOUT" if r.timed_out else
                      f"exit {r.returncode}" if r.returncode else "ok")
            print(f"  {name:<10} run {i + 1}/{repeat}: CPU {r.cpu:8.3f} s, wall "
                  f"{r.seconds:8.3f} s {r.maxrss_kb / 1024:8.1f} MB  {status}", flush=True)
    out = {}
    for name, rs in runs.items():
        good = [r for r in rs if not r.timed_out and r.returncode == 0]
        if not good:
            out[name] = (None, rs[-1])
            continue
        cpus = sorted(r.cpu for r in good)
        med = cpus[len(cpus) // 2] if len(cpus) % 2 else 0.5 * (cpus[len(cpus) // 2 - 1]
                                                                 + cpus[len(cpus) // 2])
        best = min(good, key=lambda r: r.seconds)
        out[name] = ((med, max(r.maxrss_kb for r in good) / 1024.0, best.seconds), best)
    return out


def child_env(root=None):
    """Environment in which ``python -c 'import pyevolver'`` works (the
    checkout at ``root`` when given; compiled modules cached in /tmp when
    the environment forbids writing them, as an installed package has them)."""
    env = dict(os.environ)
    if env.pop("PYTHONDONTWRITEBYTECODE", None) is not None:
        env.setdefault("PYTHONPYCACHEPREFIX", os.path.join("/tmp", "pyevolver_bench_pycache"))
    if root is None and os.path.isdir(os.path.join(REPO, "pyevolver")):
        root = REPO                 # this checkout (as the other scripts), not an installed one
    if root is not None:
        env["PYTHONPATH"] = os.path.abspath(root)
        env["PYTHONSAFEPATH"] = "1"     # (else -c puts the working directory's package first)
    elif importlib.util.find_spec("pyevolver") is None and \
            os.path.isdir(os.path.join(REPO, "pyevolver")):
        env["PYTHONPATH"] = os.pathsep.join(
            [REPO] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p])
    return env


def evolver_energy(text):
    """The number printed by ``print total_energy`` (last lone float line)."""
    val = None
    for line in text.splitlines():
        line = line.replace("Enter command:", "")
        m = _FLOAT_LINE.match(line)
        if m:
            val = float(m.group(1))
    return val


def ratio(a, b):
    return a / b if b else float("inf")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("datafile", nargs="?", default=None,
                    help=f"datafile to load (default {os.path.relpath(DEFAULT_FILE)},"
                         " generated if missing)")
    ap.add_argument("--repeat", type=int, default=3, help="runs per program (best time)")
    ap.add_argument("--timeout", type=float, default=600.0,
                    help="seconds before a run is killed (0 = none)")
    ap.add_argument("--level", type=int, default=6,
                    help="icosphere level when generating the default file")
    ap.add_argument("--evolver", default=shutil.which("evolver-nox-d") or "/usr/bin/evolver-nox-d",
                    help="Surface Evolver binary")
    ap.add_argument("--python", default=sys.executable, help="Python for pyevolver runs")
    ap.add_argument("--strict", action="store_true",
                    help="exit 1 if a time/memory goal is missed")
    ap.add_argument("--pyevolver", default=None, help="checkout whose pyevolver runs")
    ap.add_argument("--label", default="after")
    ap.add_argument("--doc", default=None, help="Markdown file to write the table into")
    args = ap.parse_args(argv)

    path = args.datafile
    if path is None:
        path = DEFAULT_FILE if args.level == 6 else os.path.join(
            HERE, "data", f"icosphere_{20 * 4 ** args.level}.fe")
        if not os.path.exists(path):
            print(f"generating {path} ...", flush=True)
            subprocess.run([args.python, os.path.join(HERE, "make_icosphere.py"),
                            "--level", str(args.level), "--out", path], check=True)
    path = os.path.abspath(path)
    env = child_env(args.pyevolver)
    timeout = args.timeout or None

    print(f"datafile : {path} ({os.path.getsize(path) / 1e6:.1f} MB)")
    print(f"python   : {args.python}")
    print(f"evolver  : {args.evolver}")
    print(f"repeat   : {args.repeat}, timeout {timeout} s, cpus {os.cpu_count()}, "
          f"loadavg {' '.join(f'{x:.2f}' for x in os.getloadavg())}", flush=True)

    for cmd, stdin_text in (([args.evolver, "-p1", path], EVOLVER_INPUT),
                            ([args.python, "-c", BASELINE_CODE], None),
                            ([args.python, "-c", PYEVOLVER_CODE, path], None)):
        run_child(cmd, stdin_text, env, timeout)          # warm-up (file cache, modules)
    got = bench_all({"baseline": ([args.python, "-c", BASELINE_CODE], None, env),
                     "evolver": ([args.evolver, "-p1", path], EVOLVER_INPUT, env),
                     "pyevolver": ([args.python, "-c", PYEVOLVER_CODE, path], None, env)},
                    args.repeat, timeout)
    (res_base, r_base), (res_evo, r_evo), (res_py, r_py) = (
        got["baseline"], got["evolver"], got["pyevolver"])

    failed = False
    for name, res, r in (("baseline", res_base, r_base), ("evolver", res_evo, r_evo),
                         ("pyevolver", res_py, r_py)):
        if res is None:
            failed = True
            if r.timed_out:
                why = f"timed out after {timeout:g} s (killed by this script)"
            elif r.returncode < 0:
                why = f"killed by signal {-r.returncode} (not sent by this script)"
            else:
                why = f"exited with status {r.returncode}"
            print(f"\n{name} FAILED: {why}")
            tail = (r.stderr or r.stdout).strip().splitlines()[-8:]
            for line in tail:
                print("    " + line)

    print()
    print(f"{'program':<28} {'CPU s':>10} {'peak MB':>10} {'wall s':>10}")
    print("-" * 61)

    def row(label, res):
        if res is None:
            print(f"{label:<28} {'n/a':>10} {'n/a':>10}")
        else:
            print(f"{label:<28} {res[0]:>10.3f} {res[1]:>10.1f} {res[2]:>10.3f}")

    row("evolver-nox-d -p1", res_evo)
    row("pyevolver (total)", res_py)
    row("python+numpy+scipy+lark", res_base)
    if res_py and res_base:
        net = (res_py[0] - res_base[0], res_py[1] - res_base[1])
        print(f"{'pyevolver (minus baseline)':<28} {net[0]:>10.3f} {net[1]:>10.1f}")
    else:
        net = None

    goals_ok = True
    if res_py and res_evo:
        print()
        print(f"{'ratio pyevolver/evolver':<28} {'CPU time':>10} {'memory':>10}")
        print("-" * 50)
        tr, mr = ratio(res_py[0], res_evo[0]), ratio(res_py[1], res_evo[1])
        print(f"{'total':<28} {tr:>9.2f}x {mr:>9.2f}x")
        if net:
            print(f"{'minus interpreter baseline':<28} {ratio(net[0], res_evo[0]):>9.2f}x "
                  f"{ratio(net[1], res_evo[1]):>9.2f}x")
        t_ok, m_ok = tr <= TIME_GOAL, mr <= MEM_GOAL
        goals_ok = t_ok and m_ok
        print(f"goals (total): time <= {TIME_GOAL:g}x {'MET' if t_ok else 'MISSED'}, "
              f"memory <= {MEM_GOAL:g}x {'MET' if m_ok else 'MISSED'}")
        if args.doc:
            write_doc(args.doc, f"bench_load {args.label}", "\n".join([
                f"| load ({args.label}) | CPU [s] | peak [MB] | wall [s] |",
                "|---|---|---|---|",
                f"| pyevolver | {res_py[0]:.2f} | {res_py[1]:.0f} | {res_py[2]:.2f} |",
                f"| evolver-nox-d | {res_evo[0]:.2f} | {res_evo[1]:.0f} | {res_evo[2]:.2f} |",
                f"| python + numpy + scipy.sparse + lark alone | {res_base[0]:.2f} | "
                f"{res_base[1]:.0f} | {res_base[2]:.2f} |" if res_base else "| - | | | |",
                f"| ratio pyevolver / evolver-nox-d (goal ≤ {TIME_GOAL:g}, ≤ {MEM_GOAL:g}) | "
                f"{tr:.2f} {'met' if t_ok else 'missed'} | {mr:.2f} "
                f"{'met' if m_ok else 'missed'} | {res_py[2] / res_evo[2]:.2f} |"]))

    floor = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    print(f"(peak MB = child ru_maxrss via os.wait4; on Linux a child's value is at "
          f"least this\n script's own peak RSS, {floor:.1f} MB, because the spawn "
          f"shares/copies its memory)")

    # -- energy agreement ----------------------------------------------------
    print()
    e_evo = evolver_energy(r_evo.stdout) if res_evo else None
    e_py = area_py = None
    if res_py:
        toks = r_py.stdout.split()
        try:
            e_py, area_py = float(toks[0]), float(toks[1])
            print(f"pyevolver: energy {e_py!r}  area {area_py!r}  "
                  f"nv {toks[2]} ne {toks[3]} nf {toks[4]}")
        except (IndexError, ValueError):
            print(f"pyevolver: cannot parse output {r_py.stdout!r}")
            failed = True
    if res_evo:
        if e_evo is None:
            print(f"evolver  : cannot find energy in output {r_evo.stdout[-300:]!r}")
            failed = True
        else:
            print(f"evolver  : energy {e_evo!r}")
    if e_py is not None and e_evo is not None:
        rel = abs(e_py - e_evo) / max(abs(e_evo), 1e-300)
        ok = rel <= REL_TOL
        print(f"energy agreement: relative difference {rel:.3e} "
              f"({'OK' if ok else 'MISMATCH'}, tolerance {REL_TOL:g})")
        failed |= not ok

    if failed:
        return 2
    if args.strict and not goals_ok:
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
