"""Helpers shared by the benchmark scripts (run as ``python benchmarks/X.py``)."""
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def icosphere_file(level, jitter=0.0, vesicle=False):
    """Path of a ``make_icosphere.py`` surface in benchmarks/data (made if missing)."""
    tag = (f"_jitter{jitter:g}" if jitter else "") + ("_vesicle" if vesicle else "")
    path = os.path.join(HERE, "data", f"icosphere_{20 * 4 ** level}{tag}.fe")
    if not os.path.exists(path):
        args = [sys.executable, os.path.join(HERE, "make_icosphere.py"), "--level", str(level),
                "--out", path]
        if jitter:
            args += ["--jitter", str(jitter)]
        if vesicle:
            args += ["--vesicle"]
        subprocess.run(args, check=True)
    return path


def bending_file(level):
    """The level's vesicle icosphere without its fixed-area quantity and with
    facet tension 1 (``bench_iterate.py --bending``, ``bench_hessian.py``)."""
    vesicle = icosphere_file(level, vesicle=True)
    out = vesicle.replace("_vesicle.fe", "_bending.fe")
    if not os.path.exists(out):
        with open(vesicle) as fh:
            lines = [ln for ln in fh if not ln.startswith("quantity surf")]
        with open(out, "w") as fh:
            fh.write("".join(ln.replace("tension 0\n", "tension 1\n") for ln in lines))
    return out


def wall(cmd, stdin, repeat):
    """Best wall time of ``repeat`` runs of ``cmd`` with ``stdin``, and the
    last run's output; exits on a failed run."""
    best, out = None, ""
    for _ in range(repeat):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, input=stdin, capture_output=True, text=True, timeout=3600)
        dt = time.perf_counter() - t0
        if p.returncode != 0:
            raise SystemExit(f"{cmd[0]} failed: {p.stderr[-500:]}")
        best = dt if best is None else min(best, dt)
        out = p.stdout
    return best, out
