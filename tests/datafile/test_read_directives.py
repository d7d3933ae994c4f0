"""``#include`` and ``#define`` in a datafile's read section, and
``keep_macros``: pyevolver prints what evolver-nox-d prints (run live).

The Evolver runs an ``#include``d command file in place, warns that
``#define`` is valid only in the top section (and still defines the macro
with ``keep_macros``), and with ``keep_macros`` expands the top section's
macros in the read section and in commands typed later.
"""
import io
import os

import pytest

from pyevolver import Session

from reference import run_reference

HERE = os.path.dirname(os.path.dirname(__file__))
CUBE = os.path.join(HERE, "..", "datafiles", "cube.fe")


def _cube(top="", read=""):
    with open(CUBE, encoding="utf-8") as fh:
        text = fh.read()
    text = text[:text.index("\nread")] + "\n"
    at = text.index("\nvertices")
    return text[:at] + "\n" + top + text[at:] + "read\n" + read


def _numbers(lines):
    out = []
    for ln in lines:
        try:
            out.append(float(ln))
        except ValueError:
            pass
    return out


def _both(evolver, tmp_path, text, commands=""):
    path = tmp_path / "d.fe"
    path.write_text(text)
    ref = _numbers(run_reference(evolver, str(path), commands, cwd=str(tmp_path)))
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        s = Session.load(str(path), out=out, err=err)
        if commands:
            s.run(commands, stop_on_error=False)
    finally:
        os.chdir(cwd)
    return _numbers(out.getvalue().split("\n")), ref, err.getvalue()


def test_include_in_read_section(evolver, tmp_path):
    sub = tmp_path / "cmds"
    sub.mkdir()
    (sub / "setup.cmd").write_text("print 42\nzz := 7\n")
    got, ref, _ = _both(evolver, tmp_path, _cube(read='#include "cmds/setup.cmd"\nprint zz*2\n'))
    assert ref == [42.0, 14.0]
    assert got == ref


def test_keep_macros_in_read_section_and_commands(evolver, tmp_path):
    text = _cube(top="#define SEVEN 7\nkeep_macros\n",
                 read="print SEVEN\n#define EIGHT 8\nprint EIGHT\n")
    got, ref, err = _both(evolver, tmp_path, text, "print SEVEN*EIGHT\n")
    assert ref == [7.0, 8.0, 56.0]
    assert got == ref
    assert "WARNING 2853: #define valid only in top of datafile." in err
    assert "d.fe:" in err


def test_define_in_read_section_without_keep_macros(evolver, tmp_path):
    text = _cube(top="#define SEVEN 7\nPARAMETER pp = SEVEN\n",
                 read="#define EIGHT 8\nprint pp\nprint EIGHT\n")
    got, ref, err = _both(evolver, tmp_path, text)
    # REF: the top macro made pp; the read section's macro is not defined,
    # and the command using it fails
    assert ref == [7.0]
    assert got == ref
    assert "WARNING 2853" in err and "eight" in err.lower()


@pytest.mark.parametrize("top", ["#define SEVEN 7\n"])
def test_top_macros_not_expanded_in_read_section_by_default(evolver, tmp_path, top):
    got, ref, err = _both(evolver, tmp_path, _cube(top=top, read="print SEVEN\nprint 3\n"))
    # REF stops the read section at the first error
    assert ref == []
    assert "seven" in err.lower()
