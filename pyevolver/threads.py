"""BLAS threads in the engine's hot paths.

numpy and scipy call OpenBLAS (or MKL), which by default starts one thread
per core for every product or factorization.  The engine's products are
small (3×3 blocks, a few columns of constraint gradients) and its sparse
work is single-threaded, so on a machine shared with other processes those
threads mostly wait for each other: a ``g`` step at 81,920 facets spent
1.3× the CPU time of one thread (docs/performance.md).  While a ``g`` or
``hessian`` step runs, the BLAS libraries are therefore limited (with
threadpoolctl) to :func:`setting` threads, one by default; outside the steps
the user's setting is untouched.

The environment variable ``PYEVOLVER_BLAS_THREADS`` sets the number: a
positive integer, or ``0`` / ``off`` to leave BLAS alone (then
``OPENBLAS_NUM_THREADS`` and friends decide, as for any numpy program).
"""
from __future__ import annotations

import functools
import os
import sys
from contextlib import contextmanager, nullcontext
from typing import Any, Callable, TypeVar

ENV = "PYEVOLVER_BLAS_THREADS"
DEFAULT = 1

_controller: Any = None
F = TypeVar("F", bound=Callable[..., Any])


def setting() -> int | None:
    """The BLAS thread limit of the steps (None: no limit)."""
    raw = os.environ.get(ENV, "").strip().lower()
    if raw == "":
        return DEFAULT
    if raw in ("0", "off", "none", "no"):
        return None
    try:
        n = int(raw)
    except ValueError:
        return DEFAULT
    return n if n > 0 else None


_modules_seen = -1


def _control():
    """A threadpoolctl controller of the BLAS libraries loaded now (made
    again when modules were imported since: scipy's linear algebra, which
    brings its own BLAS, is imported when first used; None without
    threadpoolctl)."""
    global _controller, _modules_seen
    if _controller is None or (_controller and len(sys.modules) != _modules_seen):
        try:
            from threadpoolctl import ThreadpoolController
        except ImportError:
            _controller = False
        else:
            _controller = ThreadpoolController()
            _modules_seen = len(sys.modules)
    return _controller or None


_depth = 0
_generation = 0
_late: list = []        # limits set inside a step on libraries loaded during it
_process = False        # the pyevolver program: limits, once set, stay (process_wide)
_kept: Any = None       # the controller whose libraries are limited for good


_BLAS_ENV = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def is_program() -> bool:
    """Whether this process is the ``pyevolver`` program (its console
    script, or ``python -m pyevolver``), not Python code importing it."""
    argv = list(getattr(sys, "orig_argv", None) or [])
    if "-m" in argv[:-1]:
        return argv[argv.index("-m") + 1].split(".")[0] == "pyevolver"
    name = os.path.splitext(os.path.basename(sys.argv[0]))[0] if sys.argv else ""
    return name in ("pyevolver", "pyevolver-script")       # (the latter: Windows launchers)


def program_start() -> None:
    """Run by ``import pyevolver`` before numpy loads: in the ``pyevolver``
    program, ``OPENBLAS_NUM_THREADS`` is set to :func:`setting` unless the
    user set a BLAS thread count (``OPENBLAS_NUM_THREADS``,
    ``GOTO_NUM_THREADS``, ``OMP_NUM_THREADS``, ``MKL_NUM_THREADS``) or
    ``PYEVOLVER_BLAS_THREADS=0``.  OpenBLAS starts its worker threads when
    it loads, and each spins for a while before sleeping (0.06 s of CPU
    time after ``import numpy`` here), again when scipy's own OpenBLAS
    loads with the first ``hessian``.  (Child processes inherit the
    variable.)"""
    if "numpy" in sys.modules or not is_program():
        return
    n = setting()
    if n is None or any(v in os.environ for v in _BLAS_ENV):
        return
    os.environ["OPENBLAS_NUM_THREADS"] = str(n)


def process_wide() -> None:
    """The ``pyevolver`` program owns its process: the limit is set at once
    and stays for the whole run instead of being lifted between steps.
    OpenBLAS's idle worker threads spin for a while after each product they
    shared, so numpy's products outside the steps (loading, evaluations,
    printing) cost CPU time of their own and woke the workers into the next
    step (in a ``hessian`` at 81,920 facets, a worker thread spent 0.1 s of
    CPU time, a quarter of the step's, while the step computed the
    nested-dissection order, which uses no BLAS).  (In Python, the API
    limits only inside the steps.)"""
    global _process
    _process = True
    n = setting()
    ctl = _control() if n is not None else None
    if ctl is not None:
        _keep(ctl, n)


def _keep(ctl, n) -> None:
    global _kept
    if ctl is not _kept:
        ctl.limit(limits=n, user_api="blas")      # (never restored)
        _kept = ctl


def libraries_loaded() -> None:
    """Note that a module linking its own BLAS was just loaded (scipy's
    SuperLU and linear algebra bring scipy's OpenBLAS, apart from numpy's):
    the next step's limit covers it, and a step running now limits it at
    once."""
    global _controller
    if _controller is False:
        return
    _controller = None
    n = setting() if _depth or _process else None
    if n is None:
        return
    ctl = _control()
    if ctl is None:
        return
    if _process:
        _keep(ctl, n)
    else:
        _late.append(ctl.limit(limits=n, user_api="blas"))


@contextmanager
def limited():
    """Context manager: BLAS limited to :func:`setting` threads inside
    (nested uses inside the first one change nothing: the steps of one
    ``g n`` run under one limit, set once).

    The depth count survives an interrupted nested use: a time limit
    (:mod:`pyevolver.session.deadline`) may stop a command between a nested
    use's entry and the ``with`` statement's exit, leaving its generator
    to be finished by the garbage collector later, after the outer use
    ended; such a late exit belongs to an older outer use (its
    ``generation``) and changes nothing."""
    global _depth, _generation
    if _depth:
        mine = _generation
        _depth += 1
        try:
            yield
        finally:
            if _generation == mine and _depth > 1:
                _depth -= 1
        return
    n = setting()
    ctl = _control() if n is not None else None
    if ctl is not None and _process:
        _keep(ctl, n)
        ctl = None
    with (nullcontext() if ctl is None else ctl.limit(limits=n, user_api="blas")):
        try:
            _generation += 1
            _depth = 1
            yield
        finally:
            while _late:                 # (before the outer limit restores its own)
                _late.pop().restore_original_limits()
            _depth = 0
            _generation += 1


def blas_limited(fn: F) -> F:
    """Decorator: run ``fn`` under :func:`limited`."""
    @functools.wraps(fn)
    def run(*args, **kwargs):
        if _depth:                      # (inside a limit already: each step of `g n`)
            return fn(*args, **kwargs)
        with limited():
            return fn(*args, **kwargs)
    return run  # type: ignore[return-value]
