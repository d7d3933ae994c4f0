#!/usr/bin/env python3
"""The ``hessian`` step against evolver-nox-d (issue 24): CPU time and peak
memory of each program, measured side by side.

Cases (icospheres of ``make_icosphere.py``, made prolate by
``set vertex z z*1.5`` with the body's target volume set to the new volume,
then ``g 2``):

* ``area``: facet tension 1 and the fixed body volume;
* ``bending``: ``star_perp_sq_mean_curvature`` plus facet tension 1 and the
  fixed body volume (``bench_iterate.py --bending``'s surfaces).

For each case, command (``hessian``, ``hessian_seek``) and program, the
children run ``PREFIX; q`` and ``PREFIX; COMMAND; printf ...; q`` in fresh
processes, alternating programs and runs; the command's cost is the
difference of the children's CPU times (user + system, from ``os.wait4``),
the median of ``--repeat`` pairs; the peak is the ``ru_maxrss`` of the run
with the command (load included, for both programs).  Each program's energy
after the command and the relative drift of the body volume from its target
are printed too.

    PYTHONPATH=. python benchmarks/bench_hessian.py [--levels 4 6] [--repeat 3]
        [--pyevolver ROOT] [--label after] [--doc docs/performance.md]

``--solvers`` times instead one factorization and solve of the shifted
Hessian ``K + δI`` of each surface (largest level) with each sparse solver
that is installed (SuperLU as pyevolver uses it, scikit-sparse's CHOLMOD,
qdldl, cholespy), in one child, and writes that table (label ``solvers``).

``--pyevolver ROOT`` runs the pyevolver found at ROOT (a checkout; default
this one), so that a before/after table comes from one script; ``--doc``
writes the table into that Markdown file between the markers
``<!-- bench_hessian LABEL -->`` and ``<!-- /bench_hessian LABEL -->``.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys

from _common import HERE, REPO, bending_file, cpu_run, icosphere_file, write_doc

PREFIX = "set vertex z z*1.5\nset body target body[1].volume\ng 2\n"
PRINT = 'printf "RESULT %.17g %.17g %.17g\\n", total_energy, body[1].volume, body[1].target\n'


SOLVERS = r"""
import io, sys, time
import numpy as np, scipy.sparse as sp
import scipy.sparse.linalg            # (imported before the clocks start)
from pyevolver.evolve import symfactor as SF
sys.path.insert(0, sys.argv[3])
from _common import shifted_hessian
hs, A, perm, Ap = shifted_hessian(sys.argv[1], sys.argv[2])
K = hs.K.tocsc()
n = K.shape[0]


def superlu():
    return SF.LDL(A, perm).solve(hs.rhs)


def cholmod():
    from sksparse import cholmod as C
    f = C.cholesky(Ap, mode="simplicial", ordering_method="natural")
    x = np.empty(n)
    x[perm] = f(hs.rhs[perm])
    return x


def qdldl():
    import qdldl as Q
    return Q.Solver(sp.triu(A, format="csc")).solve(hs.rhs)


def cholespy():
    import cholespy as C
    c = Ap.tocoo()
    f = C.CholeskySolverD(n, c.row.astype(np.int32), c.col.astype(np.int32), c.data,
                          C.MatrixType.COO)
    b = np.ascontiguousarray(hs.rhs[perm][:, None])
    x = np.zeros_like(b)
    f.solve(b, x)
    out = np.empty(n)
    out[perm] = x[:, 0]
    return out


for name, fn in [("SuperLU, symmetric mode, ND order (pyevolver)", superlu),
                 ("CHOLMOD simplicial LDLT, ND order (scikit-sparse)", cholmod),
                 ("qdldl (LDLT, its AMD order)", qdldl),
                 ("cholespy (CHOLMOD supernodal Cholesky, ND order)", cholespy)]:
    t0 = time.process_time()
    try:
        x = fn()
        cpu = time.process_time() - t0
        t0 = time.process_time()
        x = fn()                                  # the better of two runs
        cpu = min(cpu, time.process_time() - t0)
        res = np.linalg.norm(A @ x - hs.rhs) / np.linalg.norm(hs.rhs)
        print("SOLVER", name, "|", f"{cpu:.2f}", "|", f"residual {res:.0e}")
    except ImportError:
        print("SOLVER", name, "|", "-", "|", "not installed")
    except Exception as exc:
        print("SOLVER", name, "|", f"{time.process_time() - t0:.2f}", "|",
              "fails: " + str(exc).splitlines()[0][:60])
"""


def solvers(files, env):
    """Markdown table: CPU seconds of one factorization and solve of K + δI."""
    lines = ["| surface | factorization | CPU [s] | result |", "|---|---|---|---|"]
    for case, f in files:
        p = subprocess.run([sys.executable, "-c", SOLVERS, f, PREFIX, HERE], capture_output=True,
                           text=True, env=env, timeout=3600)
        for ln in p.stdout.splitlines():
            if ln.startswith("SOLVER "):
                name, cpu, what = ln[7:].split(" | ")
                lines.append(f"| {case} | {name} | {cpu} | {what} |")
        if p.returncode:
            raise SystemExit(p.stderr[-800:])
    return "\n".join(lines)


def result(out):
    """(energy, relative volume drift) from the RESULT line."""
    m = re.findall(r"RESULT (\S+) (\S+) (\S+)", out)
    if not m:
        raise SystemExit("no RESULT line in:\n" + out[-800:])
    e, v, t = (float(x) for x in m[-1])
    return e, abs(v - t) / abs(t)


def measure(programs, f, command, repeat):
    """{program: (median CPU of command, peak MB, energy, drift)}."""
    cpu = {k: [] for k in programs}
    peak = {k: 0.0 for k in programs}
    res = {}
    for _ in range(repeat):
        for name, (cmd, env) in programs.items():
            base = cpu_run(cmd + [f], PREFIX + "q\nq\n", env)
            full = cpu_run(cmd + [f], PREFIX + command + "\n" + PRINT + "q\nq\n", env)
            cpu[name].append(full[0] - base[0])
            peak[name] = max(peak[name], full[1])
            res[name] = result(full[2])
    return {k: (statistics.median(cpu[k]), peak[k]) + res[k] for k in programs}


def _ratio(a, b):
    """a / b to two places ("—" when the Evolver's cost measured 0)."""
    return f"{a / b:.2f}" if b > 0 else "—"


def table(rows, label):
    head = (f"| case ({label}) | facets | command | pyevolver CPU [s] | Evolver CPU [s] | ratio "
            "| pyevolver peak [MB] | Evolver peak [MB] | ratio | energy before | "
            "pyevolver energy | Evolver energy | pyevolver volume drift | Evolver volume drift |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for case, nf, cmd, py, ref, e0 in rows:
        lines.append(f"| {case} | {nf:,} | `{cmd}` | {py[0]:.2f} | {ref[0]:.2f} | "
                     f"{_ratio(py[0], ref[0])} | {py[1]:.0f} | {ref[1]:.0f} | "
                     f"{_ratio(py[1], ref[1])} | "
                     f"{e0:.10g} | {py[2]:.10g} | {ref[2]:.10g} | {py[3]:.1e} | {ref[3]:.1e} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[4, 6])
    ap.add_argument("--cases", nargs="+", default=["area", "bending"])
    ap.add_argument("--commands", nargs="+", default=["hessian", "hessian_seek"])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--evolver", default="evolver-nox-d")
    ap.add_argument("--pyevolver", default=REPO, help="checkout whose pyevolver runs")
    ap.add_argument("--label", default="after")
    ap.add_argument("--doc", default=None, help="Markdown file to write the table into")
    ap.add_argument("--solvers", action="store_true",
                    help="instead: time the sparse factorizations on the largest level")
    a = ap.parse_args()
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.abspath(a.pyevolver)
    env["PYTHONSAFEPATH"] = "1"     # (else -m puts the working directory's package first)
    programs = {"py": ([sys.executable, "-m", "pyevolver"], env),
                # REF single-threaded: with worker threads (-p1) its Hessian
                # of a method quantity loses terms (docs/differences.md)
                "ref": ([a.evolver], None)}
    if a.solvers:
        lev = max(a.levels)
        text = solvers([(f"area, {20 * 4 ** lev:,} facets", icosphere_file(lev)),
                        (f"bending, {20 * 4 ** lev:,} facets", bending_file(lev))], env)
        print(text)
        if a.doc:
            write_doc(a.doc, "bench_hessian solvers", text)
        return
    rows = []
    for lev in a.levels:
        for case in a.cases:
            f = icosphere_file(lev) if case == "area" else bending_file(lev)
            e0 = result(cpu_run([a.evolver, f], PREFIX + PRINT + "q\nq\n",
                                     None)[2])[0]
            for command in a.commands:
                m = measure(programs, f, command, a.repeat)
                rows.append((case, 20 * 4 ** lev, command, m["py"], m["ref"], e0))
                print(f"{case} {20 * 4 ** lev} {command}: CPU ratio "
                      f"{m['py'][0] / m['ref'][0]:.2f}, peak ratio {m['py'][1] / m['ref'][1]:.2f}",
                      file=sys.stderr)
    text = table(rows, a.label)
    print(text)
    if a.doc:
        write_doc(a.doc, f"bench_hessian {a.label}", text)


if __name__ == "__main__":
    main()
