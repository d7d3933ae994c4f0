"""Expression language: arithmetic rules, symbolic derivatives, printf."""
import math

import numpy as np
import pytest

from pyevolver.expr import nodes as N
from pyevolver.commands.cformat import c_format, print_value
from pyevolver.commands.interpreter import parse_command


def expr_of(text):
    ast = parse_command(f"print {text}")
    return ast[1][0][1]


def ev(text, **vals):
    return expr_of(text).ev(N.MapEnv(vals))


def test_operators():
    assert ev("-7 % 3") == 2
    assert ev("7 idiv 2") == 3
    assert ev("-7 idiv 2") == -3
    assert ev("2^10") == 1024
    assert ev("-2^2") == -4
    assert ev("2**3") == 8
    assert ev("1 ? 5 : 6") == 5
    assert ev("3 -5") == -2
    assert ev("0x1F + 101b") == 36
    assert ev("2.5D1") == 25
    assert ev("!0 && (2 > 1)") == 1


FORMULAS = ["x^2 + y^2 + z^2", "sqrt(x^2+y^2+z^2)", "sin(x)*cos(y) + exp(z/3)",
            "x*y/(1 + z^2)", "atan2(y, x) + log(1 + x^2)", "abs(x - y) + x**1.5",
            "pow(x, 3) - maximum(y, z)", "tanh(x) + asin(y/4) + acos(z/5)", "x = y*z"]


@pytest.mark.parametrize("text", FORMULAS)
def test_symbolic_gradient_matches_finite_differences(text):
    from pyevolver.datafile.grammar import top_parser, _TOP
    tree = top_parser().parse(f"constraint 1 formula: {text}")
    decl = _TOP.transform(tree)[0]
    f = N.Formula(decl[3])
    rng = np.random.default_rng(1)
    P = rng.uniform(0.3, 1.5, size=(20, 3))
    coords = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
    g = f.gradient(N.MapEnv({}), coords, 20)
    h = 1e-6
    for k, nm in enumerate("xyz"):
        cp = dict(coords)
        cm = dict(coords)
        cp[nm] = coords[nm] + h
        cm[nm] = coords[nm] - h
        fd = (f.values(N.MapEnv({}), cp, 20) - f.values(N.MapEnv({}), cm, 20)) / (2 * h)
        assert np.allclose(g[:, k], fd, rtol=1e-7, atol=1e-8)


def test_printf_c_semantics():
    assert c_format("%d|%5.2f|%g|%s", [42.7, math.pi, 1e-5, "str"]) == "42| 3.14|1e-05|str"
    assert c_format("%x %o %c %%", [255, 8, 65]) == "ff 10 A %"
    assert c_format("%-4d|%04d", [-3.9, 7]) == "-3  |0007"
    assert print_value(1024.0) == " " * 16 + "1024"
    assert print_value(math.sqrt(2)) == "     1.4142135623731"
