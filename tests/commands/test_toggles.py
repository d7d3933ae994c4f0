"""Direct tests of pyevolver.commands.toggles: REF's toggle messages (live),
shared states of synonyms, refused toggles, graphics words."""
import io
import os

import pytest

from pyevolver import Session
from pyevolver.commands.toggles import (TOGGLE_ALIASES, TOGGLE_REFUSED, TOGGLES, graphics_toggle,
                                        toggle)
from pyevolver.errors import UnsupportedError
from pyevolver.expr import nodes as N

from reference import run_reference

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")

SCRIPT = """conj_grad on
check_increase
check_increase off
ribiere off
hessian_normal off
ysmp
ysmp off
autochop on
autochop off
quietgo on
quietgo off
itdebug
itdebug off
approx_curv on
print approx_curv
sparse_constraints off
gravity off
verbose
kusner off
interp_bdry_param
linear_metric
linear_metric off
view_4d
print little_endian
big_endian
print little_endian
quiet
conj_grad off
quiet off
"""


def session():
    return Session.load(CUBE, out=io.StringIO(), err=io.StringIO())


def test_toggle_messages_match_reference(evolver):
    ref = [l for l in run_reference(evolver, CUBE, SCRIPT) if l.strip()]
    s = session()
    s.run(SCRIPT)
    ours = [l for l in s.out.getvalue().split("\n") if l.strip()]
    assert ours == ref


def test_toggle_function_and_synonyms():
    s = session()
    toggle(s.interp, "approx_curv", N.Var("on"))
    assert s.toggles["approx_curv"] == 1 and s.toggles["approximate_curvature"] == 1
    toggle(s.interp, "approximate_curvature", N.Var("off"))
    assert s.toggles["approx_curv"] == 0
    toggle(s.interp, "check_increase", None)            # bare: on
    assert s.toggles["check_increase"] == 1
    toggle(s.interp, "check_increase", N.Num(0.0))
    assert s.toggles["check_increase"] == 0
    for alias, key in TOGGLE_ALIASES.items():
        assert alias in TOGGLES and key in TOGGLES


def test_refused_toggles_name_themselves_and_keep_state():
    s = session()
    for name in sorted(TOGGLE_REFUSED):
        before = dict(s.toggles)
        with pytest.raises(UnsupportedError, match=name):
            toggle(s.interp, name, N.Var("on"))
        assert s.toggles == before
    with pytest.raises(UnsupportedError, match="autopop"):
        toggle(s.interp, "autopop", None)


def test_graphics_toggle():
    assert graphics_toggle("transforms off")[:2] == ("bare", "transforms")
    assert graphics_toggle("transforms off")[2].name == "off"
    assert graphics_toggle("clipped") == ("bare", "clipped", None)
    assert graphics_toggle("show_expr facets where 1") is None   # a graphics command
    # geomview and a bare show are commands of pyevolver.commands.display
    assert graphics_toggle("geomview on") == ("bare", "geomview", None)
    assert graphics_toggle("show") == ("bare", "show", None)
    assert graphics_toggle("transforms 3") is None
