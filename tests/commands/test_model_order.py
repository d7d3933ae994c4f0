"""M, quadratic, linear and lagrange (pyevolver.commands.model_order):
REF's messages, the internal variables, the commands refused in the
quadratic model."""
import io

import pytest

import pyevolver
from comparison import _same
from conftest import example
from pyevolver.commands import model_order
from pyevolver.errors import CommandError, UnsupportedError
from reference import run_reference


def _session():
    out = io.StringIO()
    return pyevolver.load(example("cube.fe"), out=out, err=out), out


def test_messages_and_variables():
    sess, out = _session()
    sess.run("M 2; M 2; quadratic; print lagrange_order; print quadratic; linear; print linear")
    lines = [l.strip() for l in out.getvalue().split("\n") if l.strip()]
    assert lines == ["Changing to QUADRATIC model. (was LINEAR)", "Model already QUADRATIC.",
                     "2", "1", "Changing to LINEAR model. (was QUADRATIC)", "1"]
    assert sess.surface.order == 1 and sess.surface.nv == 14


@pytest.mark.parametrize("cmd", ["u", "V", "t 0.1", "w 0.1", "K 0.1", "n 0.1", "O", "l 0.1",
                                 "j", "lagrange 2", "M 3"])
def test_refused_in_the_quadratic_model(cmd):
    sess, out = _session()
    sess.run("M 2")
    with pytest.raises(CommandError, match="not supported in pyevolver.*(quadratic|Lagrange)"):
        sess.run(cmd)
    assert sess.surface.order == 2 and sess.surface.nv == 50


def test_set_order_refuses_lagrange():
    sess, _ = _session()
    with pytest.raises(UnsupportedError, match="Lagrange"):
        model_order.set_order(sess, 3)


def test_counts_after_m2_as_ref(evolver):
    script = "M 2\nprint vertex_count\nprint edge_count\nprint facet_count\nr\n"
    ref = run_reference(evolver, example("cube.fe"), script)
    sess, out = _session()
    sess.run(script.replace("\n", ";"))
    ref = [l for l in ref if "memory" not in l]          # REF's allocator report after r
    assert _same(out.getvalue().split("\n"), ref), (out.getvalue(), ref)
