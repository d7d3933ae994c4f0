"""Atomic file output: a crash or Ctrl-C never leaves a half-written file.

Everything pyevolver writes (``dump``, ``export``, ``>>``/``>>>``
redirection, the studies' CSV files) goes through :func:`atomic_write`: the
text is written to a temporary file in the same directory, flushed to disk
and renamed over the target only when the block ends without an exception.
On an exception the temporary file is removed and the target is as it was.
"""
from __future__ import annotations

import contextlib
import os
import stat
import tempfile


class NotRegularFile(OSError):
    """The path names a device, FIFO, socket or directory."""


def check_regular(path, for_writing=True):
    """Raise :class:`NotRegularFile` when ``path`` exists and is not a
    regular file (``/dev/zero``, ``/dev/tty``, a FIFO, a directory): scripts
    read and write files only.  A missing path is fine for writing."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        if for_writing:
            return
        raise
    if not stat.S_ISREG(st.st_mode):
        what = "a directory" if stat.S_ISDIR(st.st_mode) else "a device or pipe"
        raise NotRegularFile(0, f"'{path}' is {what}, not a regular file")


@contextlib.contextmanager
def atomic_write(path, mode="w", encoding="latin-1", newline="", durable=True):
    """Open ``path`` for writing through a temporary file.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write.  If it exists it must be a regular file
        (:func:`check_regular`); a symbolic link is followed and the file it
        points to is replaced.
    mode : {"w", "a", "wb", "ab"}
        ``"w"`` replaces the file; ``"a"`` appends, by copying the existing
        contents into the temporary file first.  ``"b"`` for bytes.
    encoding, newline
        As for :func:`open` (text modes only).
    durable : bool
        Also ``fsync`` the file before the rename (survives a power cut, not
        only a crash; off for the many small appends of ``>>`` in a loop).

    Yields
    ------
    file object
        Write to it; the target changes only if the block completes.
    """
    if mode not in ("w", "a", "wb", "ab"):
        raise ValueError(f"atomic_write: mode must be 'w', 'a', 'wb' or 'ab', not {mode!r}")
    path = os.fspath(path)
    check_regular(path)
    target = os.path.realpath(path)
    directory = os.path.dirname(target) or "."
    binary = "b" in mode
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(target) + ".", suffix=".tmp",
                               dir=directory)
    try:
        with os.fdopen(fd, "wb" if binary else "w",
                       **({} if binary else {"encoding": encoding, "newline": newline})) as fh:
            if mode.startswith("a") and os.path.exists(target):
                with open(target, "rb") as old:
                    data = old.read()
                if binary:
                    fh.write(data)
                else:
                    fh.flush()
                    fh.buffer.write(data)
            yield fh
            fh.flush()
            if durable:
                os.fsync(fh.fileno())
        try:
            mode_bits = stat.S_IMODE(os.stat(target).st_mode)
        except FileNotFoundError:
            umask = os.umask(0)
            os.umask(umask)
            mode_bits = 0o666 & ~umask
        os.chmod(tmp, mode_bits)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
