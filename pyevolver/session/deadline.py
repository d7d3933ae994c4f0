"""One time limit over everything a session runs, and SIGTERM as Ctrl-C.

``--timeout`` (``Session.time_limit``, or ``timeout=`` of the Python API)
covers loading a datafile (reading, building, the first evaluation and its
``read`` section) and every command, a single long one included (one
``hessian`` step, ``r`` on a large mesh).  Two mechanisms work together:

* the interpreter's ``tick`` between loop passes, calls and iterations
  (:meth:`pyevolver.commands.interpreter.Interpreter.tick`), which raises
  :class:`~pyevolver.commands.values.TimeLimitExceeded`;
* a real-time alarm (``SIGALRM``, main thread only) whose handler raises
  :class:`Alarm` wherever Python code is running: inside the datafile
  reader, a solver or a remeshing step.  :class:`Alarm` derives from
  ``BaseException`` (as ``KeyboardInterrupt`` does), so the numerical code's
  ``except Exception`` fallbacks cannot swallow it; the command wrapper
  (:meth:`pyevolver.session.core.Session.run_one`) restores the surface and
  reports the limit as a located error.

A long call into compiled code (one sparse factorization) ends before the
alarm is handled; the limit is then passed by that call's length.  Where
there is no ``SIGALRM`` (Windows) or off the main thread, only the ticks
apply.
"""
from __future__ import annotations

import contextlib
import signal
import threading
import time
from typing import Any, Iterator


class Alarm(BaseException):
    """The time limit passed (raised by the ``SIGALRM`` handler)."""


# set by the SIGTERM handler: the CLI exits with 128 + SIGTERM
terminated = {"hit": False}


def _usable() -> bool:
    return hasattr(signal, "setitimer") and \
        threading.current_thread() is threading.main_thread()


def _raise_alarm(signum, frame):
    raise Alarm()


@contextlib.contextmanager
def alarm(seconds: float | None) -> Iterator[None]:
    """Raise :class:`Alarm` in the block once ``seconds`` have passed.

    ``None``, off the main thread or when an outer block has armed the
    alarm already (the outer limit holds): nothing is armed.
    """
    if not seconds or not _usable() or signal.getitimer(signal.ITIMER_REAL)[0] > 0:
        yield
        return
    old = signal.signal(signal.SIGALRM, _raise_alarm)
    signal.setitimer(signal.ITIMER_REAL, float(seconds))
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@contextlib.contextmanager
def limit(session: Any) -> Iterator[None]:
    """The session's time limit over the block: the interpreter's deadline
    (commands run inside share it) and the alarm."""
    seconds = session.time_limit
    interp = session.interp
    outer = interp.deadline is None
    if not seconds or not outer:
        yield
        return
    interp.deadline = time.monotonic() + seconds
    try:
        with alarm(seconds):
            yield
    finally:
        interp.deadline = None


@contextlib.contextmanager
def override(session: Any, seconds: float | None) -> Iterator[None]:
    """``timeout=`` of an API call: ``session.time_limit`` is ``seconds``
    in the block (``None``: unchanged)."""
    if seconds is None:
        yield
        return
    if not seconds > 0:
        raise ValueError(f"timeout must be a positive number of seconds, not {seconds!r}")
    old = session.time_limit
    session.time_limit = float(seconds)
    try:
        yield
    finally:
        session.time_limit = old


def message(session: Any, what: str = "the command") -> str:
    """The text of a passed limit."""
    return (f"{what} ran longer than {session.time_limit:g} s (the time limit) "
            f"and was stopped")


@contextlib.contextmanager
def deferred_sigint():
    """Ctrl-C (SIGINT) only sets ``flag["hit"]`` while the block runs (so a
    ``g`` or ``bfgs`` run can stop at the end of a complete iteration); the
    previous handler is restored after.  Outside the main thread, a no-op."""
    flag = {"hit": False}
    old = None
    if threading.current_thread() is threading.main_thread():
        def handler(signum, frame):
            flag["hit"] = True
        try:
            old = signal.signal(signal.SIGINT, handler)
        except (ValueError, OSError):
            old = None
    try:
        yield flag
    finally:
        if old is not None:
            signal.signal(signal.SIGINT, old)


def _raise_interrupt(signum, frame):
    terminated["hit"] = True
    raise KeyboardInterrupt()


def handle_sigterm() -> None:
    """SIGTERM stops the program as Ctrl-C does (the running command is
    undone, files are never half-written); for the CLI's main thread."""
    if threading.current_thread() is threading.main_thread():
        with contextlib.suppress(ValueError, OSError, AttributeError):
            signal.signal(signal.SIGTERM, _raise_interrupt)
