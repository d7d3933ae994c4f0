"""Direct tests of pyevolver.commands.eigen: the forms the parser accepts
(``ritz(λ, n)``, ``eigenprobe λ``, ``eigenprobe(λ, n)``, ``lanczos λ``,
``lanczos(λ, n)``, ``saddle [max]``), the variables they set and their
refusals.  The numbers against the Evolver are in
tests/reference/test_eigen_reference.py."""
import io
import os
import re

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.commands import eigen
from pyevolver.commands.registry import COMMANDS
from pyevolver.errors import CommandError

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def session():
    out = io.StringIO()
    s = Session.load(CUBE, out=out, err=io.StringIO())
    return s, out


def test_registered_in_the_eigen_family():
    for word in ("eigenprobe", "ritz", "lanczos", "saddle"):
        assert COMMANDS[word].family == eigen.FAMILY
        assert COMMANDS[word].call is not None
    with pytest.raises(CommandError, match="not supported in pyevolver: command hessian_menu"):
        session()[0].run("hessian_menu")


def test_forms_and_variables():
    s, out = session()
    s.run("g 10")
    out.truncate(0)
    out.seek(0)
    s.run("ritz(1,2)")
    text = out.getvalue().split("\n")
    assert text[0] == "Eigencounts:    3 <,  0 ==,  10 > "
    vals = [float(x.split()[1]) for x in text[1:3]]
    assert re.fullmatch(r"  1\. +0\.\d{15}", text[1])
    assert np.allclose(s.arrays["eigenvalues"], vals, atol=1e-14, rtol=0)
    assert abs(s.value("last_eigenvalue") - vals[0]) < 1e-14
    for cmd in ("eigenprobe 1", "eigenprobe(1)", "eigenprobe(0.3, 40)", "lanczos 1",
                "lanczos(1, 3)", "saddle", "saddle 0.5"):
        s.run(cmd)
    assert abs(s.value("last_eigenvalue") - vals[0]) < 1e-9
    with pytest.raises(CommandError, match="read-only"):
        s.run("last_eigenvalue := 3")
    with pytest.raises(CommandError, match=re.escape(eigen.RITZ_SYNTAX)):
        s.run("ritz 1")
    with pytest.raises(CommandError, match=re.escape(eigen.RITZ_SYNTAX)):
        s.run("ritz(1)")


def test_needs_pressures_and_vertices():
    s, _ = session()
    X = s.surface.X.copy()
    for cmd in ("eigenprobe 0", "ritz(0,3)", "saddle"):
        with pytest.raises(CommandError, match="Pressures invalid"):
            s.run(cmd)
    assert np.array_equal(s.surface.X, X)


def test_saddle_function_reports_no_move_at_a_minimum():
    s, out = session()
    s.run("g 10")
    X = s.surface.X.copy()
    r = eigen.saddle(s)
    assert r.step is None and r.value > 0
    assert np.array_equal(s.surface.X, X)
    assert out.getvalue().endswith("Not a saddle point.\n")


def test_bad_arguments_are_refused():
    s, _ = session()
    s.run("g 5")
    X = s.surface.X.copy()
    for cmd, msg in (("ritz(1e308*10, 2)", "must be finite"), ("ritz(0, -1)", "negative"),
                     ("eigenprobe 1e308*10", "must be finite"),
                     ("saddle sqrt(1e308*10) - sqrt(1e308*10)", "not a number"),
                     ("ritz(1, 2, 3)", "at most 2")):
        with pytest.raises(CommandError, match=msg):
            s.run(cmd)
    assert np.array_equal(s.surface.X, X)
    s.run("ritz(0, 100)")                     # more than there are: all 13
    assert len(s.arrays["eigenvalues"]) == 13
