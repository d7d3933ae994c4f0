"""Atomic file writes: a temporary file in the target's folder, renamed over
the target only when writing succeeded.

A reader (or a sweep resumed after a crash) therefore sees either the old
file or the complete new one, never a half-written file; a failed or
interrupted write (an exception, Ctrl-C) leaves the old file as it was and
no temporary file behind.  Everything pyevolver writes goes through here:
``dump``, ``export``, ``>>``/``>>>`` redirection, pictures, the sweeps' and
studies' files.  Devices, pipes and directories are refused
(:func:`check_regular`): scripts write regular files only.
"""
from __future__ import annotations

import contextlib
import io
from typing import IO, Any, Iterator
import os
import secrets
import stat


class NotRegularFile(OSError):
    """The path names a device, FIFO, socket or directory."""


def check_regular(path: str, for_writing: bool = True) -> None:
    """Raise :class:`NotRegularFile` when ``path`` exists and is not a
    regular file (``/dev/zero``, ``/dev/tty``, a FIFO, a directory).  A
    missing path is fine for writing (FileNotFoundError for reading)."""
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
def atomic_path(path: str, suffix: str = ".tmp") -> Iterator[str]:
    """Yield the name of a fresh temporary file next to ``path``; when the
    block ends without an exception it is renamed to ``path`` (``os.replace``,
    atomic on POSIX and Windows), else removed.

    For writers that want a file name (meshio, matplotlib's ``savefig``).
    A symbolic link is followed: the file it points to is replaced.  The
    new file keeps the permissions of the one it replaces (a new one gets
    0666 less the umask, as ``open`` would give it).
    """
    path = os.fspath(path)
    check_regular(path)
    target = os.path.realpath(path)
    folder = os.path.dirname(target)
    while True:
        tmp = os.path.join(folder, f".{os.path.basename(target)}.{secrets.token_hex(4)}{suffix}")
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
            break
        except FileExistsError:
            continue
    try:
        yield tmp
        with contextlib.suppress(FileNotFoundError):
            os.chmod(tmp, stat.S_IMODE(os.stat(target).st_mode))
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise


@contextlib.contextmanager
def atomic_write(path: str, mode: str = "w", *, durable: bool = True,
                 **kwargs: Any) -> Iterator[IO]:
    """``open(path, mode, **kwargs)`` written atomically.

    Parameters
    ----------
    path : str or os.PathLike
    mode : {"w", "wb", "a", "ab"}
        ``"w"`` replaces the file; ``"a"`` appends, by copying the existing
        contents into the temporary file first (for many small appends use
        :func:`atomic_append`, whose cost is what is written).
    durable : bool
        ``fsync`` the file before the rename (survives a power cut, not only
        a crash; off for the many small appends of ``>>`` in a loop).
    **kwargs
        For :func:`open` (``encoding``, ``newline``).

    Yields
    ------
    file object
        Of the temporary file, which replaces ``path`` when the block ends
        without an exception.
    """
    if mode not in ("w", "wb", "a", "ab"):
        raise ValueError(f"atomic_write: mode must be 'w', 'wb', 'a' or 'ab', not {mode!r}")
    with atomic_path(path) as tmp, open(tmp, "w" + mode[1:], **kwargs) as fh:
        if mode.startswith("a") and os.path.exists(path):
            with open(path, "rb") as old:
                data = old.read()
            if "b" in mode:
                fh.write(data)
            else:
                fh.flush()
                fh.buffer.write(data)
        yield fh
        fh.flush()
        if durable:
            os.fsync(fh.fileno())


@contextlib.contextmanager
def atomic_append(path: str, encoding: str = "utf-8",
                  newline: str | None = None) -> Iterator[IO]:
    """A text stream whose contents are appended to ``path`` when the block
    ends without an exception, all at once; nothing is appended when it
    fails (``>>`` redirection).

    The file is opened first in append mode (``O_APPEND``: devices, pipes and
    directories are refused, a missing file is created); the text is
    collected in memory and written with one ``write`` at the end, so the
    cost is linear in what is written, not in the file's size (16,000
    appends of a line: a fraction of a second).  A write that fails
    half-way (disk full) is cut back to the file's old length; a file this
    call created is removed again when the block fails.
    """
    path = os.fspath(path)
    check_regular(path)
    existed = os.path.exists(path)
    fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
    try:
        check_regular(path)                 # (a race: replaced by a device meanwhile)
        buf = io.StringIO(newline=newline)
        try:
            yield buf
        except BaseException:
            if not existed and os.fstat(fd).st_size == 0:
                with contextlib.suppress(OSError):
                    os.remove(path)
            raise
        data = buf.getvalue().encode(encoding)
        start = os.fstat(fd).st_size
        try:
            view = memoryview(data)
            while view:
                n = os.write(fd, view)
                view = view[n:]
        except BaseException:
            with contextlib.suppress(OSError):
                os.ftruncate(fd, start)
            raise
    finally:
        os.close(fd)
