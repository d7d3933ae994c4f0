"""Atomic writes (pyevolver/atomic.py): the target is the old file or the
complete new one, never a part, and no temporary file stays behind."""
import os

import pytest

from pyevolver.atomic import atomic_path, atomic_write


def test_atomic_write_replaces_on_success(tmp_path):
    p = tmp_path / "a.txt"
    p.write_text("old")
    with atomic_write(p) as fh:
        fh.write("new")
        assert p.read_text() == "old"          # not visible before the block ends
    assert p.read_text() == "new"
    assert os.listdir(tmp_path) == ["a.txt"]


def test_atomic_write_keeps_old_file_on_error(tmp_path):
    p = tmp_path / "a.txt"
    p.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_write(p) as fh:
            fh.write("half")
            raise RuntimeError("killed")
    assert p.read_text() == "old"
    assert os.listdir(tmp_path) == ["a.txt"]


def test_atomic_path_mode_follows_umask(tmp_path):
    old = os.umask(0o022)
    try:
        with atomic_path(tmp_path / "b.bin", ".bin") as tmp:
            assert tmp.endswith(".bin") and os.path.dirname(tmp) == str(tmp_path)
            with open(tmp, "wb") as fh:
                fh.write(b"x")
    finally:
        os.umask(old)
    assert (tmp_path / "b.bin").read_bytes() == b"x"
    assert oct(os.stat(tmp_path / "b.bin").st_mode & 0o777) == oct(0o644)


def test_atomic_write_refuses_append(tmp_path):
    with pytest.raises(ValueError):
        with atomic_write(tmp_path / "c", "a"):
            pass
