"""The C allocator's settings for large numpy temporaries (glibc only).

A ``g`` step allocates and frees arrays of a few hundred kilobytes to a few
megabytes dozens of times.  glibc serves blocks above its mmap threshold
(128 KiB at start, raised dynamically) with fresh ``mmap`` pages and gives
the heap's free top back to the system above its trim threshold, so the
same arrays are page-faulted in again and again; how often depends on the
order of earlier allocations.  Fixing the mmap threshold at 32 MiB (glibc's
maximum on 64-bit) and the trim threshold at 64 MiB keeps such blocks in the
heap: measured with ``benchmarks/bench_iterate.py`` on a 20,480-facet
sphere, a ``g`` step took 35–50 ms with the defaults and 18 ms with these
settings (the same with the Evolver's datafile, numbers unchanged).

:func:`tune_allocator` runs once at ``import pyevolver``.  It does nothing
off glibc, when the environment already sets ``MALLOC_MMAP_THRESHOLD_`` or
``MALLOC_TRIM_THRESHOLD_`` (the user's choice wins), or when
``PYEVOLVER_MALLOC=0``.

Loading a datafile is the other way round: its large blocks (the text, its
sections, the tables' arrays and the build's index arrays) are made once
and freed, and kept in the heap they raise the peak (bench_load.py: 94 MB
for the 81,920-facet sphere, 88 MB with these blocks mmapped, the Evolver
58 MB).  :func:`loading` (a decorator of the reader and of the surface
build) therefore lowers both thresholds to glibc's initial 128 KiB while it
runs and restores the settings above after.

:func:`give_back` returns the heap's free pages to the system (glibc's
``malloc_trim``).  Kept in the heap, the blocks that the ``g`` steps and the
Hessian's assembly freed count in the resident size while the sparse
factorization allocates its factors beside them (with its own ``malloc``).
Called before a large matrix is permuted and factored (pyevolver.evolve.symfactor),
it lowers the peak of ``hessian`` on the 81,920-facet sphere from 246 MB to
200 MB for a few milliseconds of CPU time (pages faulted in again).
"""
from __future__ import annotations

import contextlib
import ctypes
import functools
import os
import sys
from typing import Any, Callable, Iterator

M_TRIM_THRESHOLD = -1     # glibc's mallopt parameter numbers (malloc.h)
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD = 32 * 1024 * 1024
TRIM_THRESHOLD = 64 * 1024 * 1024

LOAD_THRESHOLD = 128 * 1024     # glibc's initial mmap threshold

_done: bool | None = None
_mallopt: Any = None
_trim: Any = None
_depth = 0


def tune_allocator() -> bool:
    """Set glibc's mmap and trim thresholds (see the module docstring).

    Returns
    -------
    bool
        True when the settings were applied (now or at an earlier call).
    """
    global _done
    if _done is not None:
        return _done
    _done = False
    if not sys.platform.startswith("linux") or os.environ.get("PYEVOLVER_MALLOC") == "0":
        return False
    if "MALLOC_MMAP_THRESHOLD_" in os.environ or "MALLOC_TRIM_THRESHOLD_" in os.environ:
        return False
    try:
        libc = ctypes.CDLL("libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):          # musl and other C libraries
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    _done = bool(mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)) and \
        bool(mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD))
    global _mallopt
    _mallopt = mallopt if _done else None
    return _done


@contextlib.contextmanager
def _loading() -> Iterator[None]:
    global _depth
    if _mallopt is None or _depth:
        yield
        return
    _depth += 1
    _mallopt(M_MMAP_THRESHOLD, LOAD_THRESHOLD)
    _mallopt(M_TRIM_THRESHOLD, LOAD_THRESHOLD)
    try:
        yield
    finally:
        _depth -= 1
        _mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)
        _mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD)


def loading(fn: Callable) -> Callable:
    """Decorate a loading step: while it runs, large blocks are mmapped and
    the heap's free top is given back (see the module docstring); nothing
    when :func:`tune_allocator` did not apply its settings."""
    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with _loading():
            return fn(*args, **kwargs)
    return wrapper


def give_back() -> None:
    """Return the heap's free pages to the system (see the module
    docstring); nothing off glibc, or when :func:`tune_allocator` was turned
    off (``PYEVOLVER_MALLOC=0``, the user's ``MALLOC_*`` variables)."""
    global _trim
    if _trim is None:
        _trim = False
        if _done:
            try:
                _trim = ctypes.CDLL("libc.so.6").malloc_trim
                _trim.argtypes = (ctypes.c_size_t,)
                _trim.restype = ctypes.c_int
            except (OSError, AttributeError):
                _trim = False
    if _trim:
        _trim(0)
