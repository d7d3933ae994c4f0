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


#: The prolate start of bench_hessian.py and bench_iterate.py: the sphere
#: stretched along z, its body's target set to the new volume, two steps.
PROLATE = "set vertex z z*1.5\nset body target body[1].volume\ng 2\n"


def pyevolver_env(root):
    """Environment whose ``python -m pyevolver`` is the checkout at ``root``
    (compiled modules cached in /tmp when the environment forbids writing
    them, as an installed package has them)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.abspath(root)
    env["PYTHONSAFEPATH"] = "1"     # (else -m and -c put the working directory's package first)
    if env.pop("PYTHONDONTWRITEBYTECODE", None) is not None:
        env.setdefault("PYTHONPYCACHEPREFIX", os.path.join("/tmp", "pyevolver_bench_pycache"))
    return env


def cpu_run(cmd, stdin, env=None):
    """Run ``cmd`` with ``stdin``: (CPU seconds user + system of the child
    from ``os.wait4``, its peak RSS in MB, its output); exits on a failure."""
    p = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, env=env)
    p.stdin.write(stdin)
    p.stdin.close()
    out = p.stdout.read()
    p.stdout.close()
    _, status, ru = os.wait4(p.pid, 0)
    p.returncode = os.waitstatus_to_exitcode(status)    # tell Popen it is reaped
    if p.returncode != 0:
        raise SystemExit(f"{cmd[0]} failed: {out[-800:]}")
    return ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024.0, out


def write_doc(path, tag, text):
    """Put ``text`` into the Markdown file ``path`` between the markers
    ``<!-- TAG -->`` and ``<!-- /TAG -->`` (appended when missing)."""
    begin, end = f"<!-- {tag} -->", f"<!-- /{tag} -->"
    old = open(path).read() if os.path.exists(path) else ""
    block = f"{begin}\n{text}\n{end}"
    if begin in old and end in old:
        new = old[:old.index(begin)] + block + old[old.index(end) + len(end):]
    else:
        new = old.rstrip("\n") + "\n\n" + block + "\n"
    with open(path, "w") as fh:
        fh.write(new)


def shifted_hessian(path, prefix):
    """The ``hessian`` step's matrix on the surface of ``path`` after the
    commands ``prefix``: ``(hs, A, perm, Ap)`` with ``hs`` the system
    (``hessian_normal``), ``A = K + δI`` (CSC, δ = 1e-8 × the mean |diagonal|),
    ``perm`` the step's nested-dissection order and ``Ap`` A in that order."""
    import io
    import numpy as np
    import scipy.sparse as sp
    from pyevolver import Session
    from pyevolver.evolve import hessian_nd
    from pyevolver.evolve.ordering import nested_dissection
    s = Session.load(path, out=io.StringIO())
    s.run(prefix)
    hs = hessian_nd.system(s.iterator, True)
    K = hs.K.tocsc()
    n = K.shape[0]
    A = (K + 1e-8 * float(np.abs(K.diagonal()).mean()) * sp.identity(n, format="csc")).tocsc()
    perm = nested_dissection(hs.points, A)
    return hs, A, perm, A.tocsr()[perm][:, perm].tocsc()
