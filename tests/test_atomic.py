"""Atomic writes (pyevolver/atomic.py): the target is the old file or the
complete new one, never a part, and no temporary file stays behind; dump and
``>>``/``>>>`` use them."""
import io
import os

import pytest

from pyevolver.atomic import (NotRegularFile, atomic_append, atomic_path, atomic_write,
                              check_regular)
from pyevolver.errors import CommandError
from pyevolver.session.core import Session

CUBE = os.path.join(os.path.dirname(__file__), "..", "datafiles", "cube.fe")


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


class Boom(Exception):
    pass


def _leftovers(d):
    return sorted(p for p in os.listdir(d) if p.endswith(".tmp"))


def test_interrupt_leaves_nothing(tmp_path):
    q = tmp_path / "never.txt"
    with pytest.raises(KeyboardInterrupt):
        with atomic_write(q) as fh:
            fh.write("x")
            raise KeyboardInterrupt()
    assert not q.exists() and _leftovers(tmp_path) == []


def test_append_mode(tmp_path):
    p = tmp_path / "log.txt"
    with atomic_write(p, "a") as fh:
        fh.write("one\n")
    with atomic_write(p, "a") as fh:
        fh.write("two\n")
    assert p.read_text() == "one\ntwo\n"
    with pytest.raises(Boom):
        with atomic_write(p, "a") as fh:
            fh.write("three\n")
            raise Boom()
    assert p.read_text() == "one\ntwo\n"


def test_binary_and_permissions(tmp_path):
    p = tmp_path / "b.bin"
    p.write_bytes(b"\x00\x01")
    os.chmod(p, 0o640)
    with atomic_write(p, "ab") as fh:
        fh.write(b"\x02")
    assert p.read_bytes() == b"\x00\x01\x02"
    assert os.stat(p).st_mode & 0o777 == 0o640


def test_symlink_target_is_replaced(tmp_path):
    target = tmp_path / "real.txt"
    target.write_text("old")
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    with atomic_write(link) as fh:
        fh.write("new")
    assert link.is_symlink() and target.read_text() == "new"


def test_devices_and_directories_are_refused(tmp_path):
    for path in ("/dev/null", "/dev/zero", str(tmp_path)):
        if not os.path.exists(path):
            continue
        with pytest.raises(NotRegularFile):
            check_regular(path)
        with pytest.raises(NotRegularFile):
            with atomic_write(path) as fh:
                fh.write("x")
    check_regular(str(tmp_path / "missing.txt"))       # a new file is fine


def test_dump_is_atomic(tmp_path, monkeypatch):
    s = Session.load(CUBE, out=io.StringIO())
    out = tmp_path / "cube.dmp"
    out.write_text("previous dump\n")

    def crash(src, dst):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(os, "replace", crash)
    with pytest.raises(CommandError, match="cannot write"):
        s.dump(str(out))
    assert out.read_text() == "previous dump\n"
    assert _leftovers(tmp_path) == []
    monkeypatch.undo()
    s.dump(str(out))
    assert out.read_text().startswith("// ") or "vertices" in out.read_text()
    with pytest.raises(CommandError, match="not a regular file"):
        s.run('dump "/dev/null"')


def test_redirect_writes_nothing_when_the_command_fails(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    s = Session.load(CUBE, out=io.StringIO(), err=io.StringIO())
    s.run('{ print 1 } >>> "kept.txt"')
    assert (tmp_path / "kept.txt").read_text().split() == ["1"]
    s.run('{ print 2; print vertex[99].x } >> "kept.txt"', stop_on_error=False)
    s.run('{ print 3; abort } >>> "never.txt"', stop_on_error=False)
    assert (tmp_path / "kept.txt").read_text().split() == ["1"]
    assert not (tmp_path / "never.txt").exists()
    # control flow is not a failure: the output of a procedure that returns stays
    s.run('procedure pp() { { print 4; return } >> "kept.txt" }; pp()')
    assert (tmp_path / "kept.txt").read_text().split() == ["1", "4"]
    assert _leftovers(tmp_path) == []


@pytest.mark.parametrize("name", ["cube.vtu", "cube.fe"])
def test_export_is_atomic(tmp_path, monkeypatch, name):
    """``export``: a write that dies half way (KeyboardInterrupt inside
    meshio's writer or the dump) or a failing rename leaves the previous
    file and no temporary."""
    import meshio

    import pyevolver.datafile.writer as W
    s = Session.load(CUBE, out=io.StringIO(), err=io.StringIO())
    out = tmp_path / name
    out.write_text("previous export\n")

    def dies_half_way(path):
        with open(path, "w") as fh:
            fh.write("half")
        raise KeyboardInterrupt
    monkeypatch.setattr(meshio, "write", lambda path, *a, **k: dies_half_way(path))
    monkeypatch.setattr(W, "dump", lambda obj, path, *a, **k: dies_half_way(path))
    with pytest.raises(KeyboardInterrupt):
        s.export(str(out))
    assert out.read_text() == "previous export\n" and _leftovers(tmp_path) == []
    monkeypatch.undo()

    def crash(src, dst):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(os, "replace", crash)
    with pytest.raises(CommandError, match="cannot write"):
        s.run(f'export "{out}"')
    assert out.read_text() == "previous export\n" and _leftovers(tmp_path) == []
    monkeypatch.undo()
    s.run(f'export "{out}"')
    assert out.read_text() != "previous export\n" and sorted(os.listdir(tmp_path)) == [name]


def test_append_redirect_opens_in_append_mode(tmp_path, monkeypatch):
    """``>>`` appends to the file itself (same inode, nothing copied): the
    cost is what is written; 2,000 appends keep every line in order."""
    monkeypatch.chdir(tmp_path)
    s = Session.load(CUBE, out=io.StringIO(), err=io.StringIO())
    s.run('print 0 >> "app.txt"')
    inode = os.stat(tmp_path / "app.txt").st_ino
    s.run('for (ii := 1; ii <= 2000; ii += 1) { printf "%d\\n", ii >> "app.txt" }')
    assert os.stat(tmp_path / "app.txt").st_ino == inode
    assert (tmp_path / "app.txt").read_text().split() == [str(i) for i in range(2001)]
    with pytest.raises(CommandError, match="not a regular file"):
        s.run('print 1 >> "/dev/zero"')
    with pytest.raises(CommandError, match="not a regular file"):
        s.run(f'print 1 >> "{tmp_path}"')
    assert _leftovers(tmp_path) == []


def test_atomic_append_all_or_nothing(tmp_path, monkeypatch):
    p = tmp_path / "a.txt"
    p.write_text("old\n")
    with pytest.raises(RuntimeError):
        with atomic_append(str(p)) as fh:
            fh.write("half\n")
            raise RuntimeError
    assert p.read_text() == "old\n"
    new = tmp_path / "new.txt"
    with pytest.raises(RuntimeError):
        with atomic_append(str(new)) as fh:
            raise RuntimeError
    assert not new.exists()                      # a file it created is removed again
    real_write = os.write

    def short_then_full(fd, data):
        real_write(fd, bytes(data[:2]))
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(os, "write", short_then_full)
    with pytest.raises(OSError):
        with atomic_append(str(p)) as fh:
            fh.write("more text\n")
    monkeypatch.undo()
    assert p.read_text() == "old\n"              # cut back to its old length
    with atomic_append(str(p)) as fh:
        fh.write("x\n")
    assert p.read_text() == "old\nx\n"
