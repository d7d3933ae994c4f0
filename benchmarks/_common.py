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
