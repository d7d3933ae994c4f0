"""Session behaviour: state kept on errors, refusals by name, Python API."""
import io

import numpy as np
import pytest

from pyevolver import Session, CommandError

from conftest import example


def session(name="cube.fe"):
    return Session.load(example(name), out=io.StringIO(), err=io.StringIO())


def test_failing_command_leaves_state():
    s = session()
    s.run("aa := 5; bb := 7")
    X = s.surface.X.copy()
    with pytest.raises(CommandError):
        s.run("aa := 99; vertex[1].x := 3; print nosuchname")
    assert s.variables["aa"] == 5
    assert np.array_equal(s.surface.X, X)
    assert s.total_energy == 6


@pytest.mark.parametrize("cmd,word", [("o", "o"),
                                      ("lagrange 2", "lagrange"), ("quadratic", "quadratic"),
                                      ("refine vertex[1]", "refine")])
def test_later_features_refused_by_name(cmd, word):
    s = session()
    with pytest.raises(CommandError, match=f"not supported.*{word}"):
        s.run(cmd)


def test_syntax_error_is_located():
    s = session()
    with pytest.raises(CommandError, match=r"<command>:1:\d+: syntax error"):
        s.run("print (1 + ")


def test_python_api_values():
    s = session("catbody.fe")
    assert s.surface.nv == 18
    assert s.totals.volumes[0] == pytest.approx(2 * np.pi * 0.55, rel=1e-14)
    s.run("rmax := 2")
    assert s.variables["rmax"] == 2


def test_read_section_defines_commands():
    s = session("cube.fe")
    assert "gogo" in s.commands and "gogo2" in s.commands


def test_vertex_assignment_then_recalc():
    s = session()
    s.run("vertex[5].z := 2; recalc")
    assert s.total_area > 6
