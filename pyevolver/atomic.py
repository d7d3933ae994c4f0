"""Atomic file writes: a temporary file in the target's folder, renamed over
the target only when writing succeeded.

A reader (or a sweep resumed after a crash) therefore sees either the old
file or the complete new one, never a half-written file; a failed write
leaves the old file as it was and no temporary file behind.
"""
from __future__ import annotations

import contextlib
import os
import secrets


@contextlib.contextmanager
def atomic_path(path, suffix=".tmp"):
    """Yield the name of a fresh temporary file next to ``path``; when the
    block ends without an exception it is renamed to ``path`` (``os.replace``,
    atomic on POSIX and Windows), else removed.

    For writers that want a file name (meshio, matplotlib's ``savefig``).
    """
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    while True:
        tmp = os.path.join(folder, f".{os.path.basename(path)}.{secrets.token_hex(4)}{suffix}")
        try:
            # mode 0666 less the umask, as open() would give the file itself
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
            break
        except FileExistsError:
            continue
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise


@contextlib.contextmanager
def atomic_write(path, mode="w", **kwargs):
    """``open(path, mode, **kwargs)`` written atomically: yields the file
    object of a temporary file that replaces ``path`` when the block ends
    without an exception (flushed and fsynced first)."""
    if not mode.startswith("w"):
        raise ValueError(f"atomic_write: mode must be 'w' or 'wb', not {mode!r}")
    with atomic_path(path) as tmp, open(tmp, mode, **kwargs) as fh:
        yield fh
        fh.flush()
        os.fsync(fh.fileno())
