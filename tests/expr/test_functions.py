"""pyevolver.expr.functions and .transform: the language's numeric layer."""
import math

import numpy as np
import pytest

from pyevolver.errors import ExpressionError
from pyevolver.expr import functions as FN
from pyevolver.expr import nodes as N
from pyevolver.expr.transform import expr_grammar, parse_number, unescape


def test_constants_and_colours():
    assert FN.CONSTANTS["pi"] == math.pi and FN.CONSTANTS["red"] == 4.0
    assert N.CONSTANTS is FN.CONSTANTS          # the nodes' names are the functions'


def test_evolver_operator_conventions():
    assert math.isnan(FN.BINOPS["%"](5.0, 0.0))
    assert FN.BINOPS["%"](-1.0, 3.0) == 2.0
    assert FN.BINOPS["idiv"](7.9, 2.0) == 3.0
    with pytest.raises(ExpressionError):
        FN.BINOPS["idiv"](1.0, 0.0)
    assert FN.BINOPS["^"](0.0, -1.0) == math.inf
    assert math.isnan(FN.BINOPS["^"](-8.0, 1 / 3))


def test_clipped_inverse_trigonometry():
    assert FN.FUNC1["acos"](1 + 1e-15) == 0.0
    assert FN.FUNC1["asin"](-2.0) == -math.pi / 2


def test_elliptic_integrals_and_their_domains():
    assert FN.FUNC1["elliptick"](0.0) == pytest.approx(math.pi / 2)
    assert FN.FUNC1["elliptice"](1.0) == pytest.approx(1.0)
    with pytest.raises(ExpressionError):
        FN.FUNC1["elliptick"](1.0)


def test_array_values_and_numbers():
    a = FN.array_value([1, 2])
    assert isinstance(a, FN.ArrayValue) and a.dtype == float
    assert FN.is_number(2) and FN.is_number(np.float64(1)) and not FN.is_number("2")
    assert FN._what("s") == "a string" and FN._what(np.zeros((2, 3))) == "an array of shape [2, 3]"


def test_number_tokens_and_escapes():
    assert parse_number("1d3") == 1000.0
    assert parse_number("0x1F") == 31.0
    assert parse_number("101b") == 5.0
    assert unescape(r"a\tb\n\"") == 'a\tb\n"'
    assert expr_grammar().startswith("// The expression language shared")


def test_formula_over_arrays_and_its_derivatives():
    f = N.Formula(N.Bin("*", N.Var("x1"), N.Var("y")))     # x1 is x
    coords = {"x": np.array([1.0, 2.0]), "y": np.array([3.0, 4.0]), "z": np.zeros(2)}
    env = N.MapEnv({})
    assert np.allclose(f.values(env, coords, 2), [3.0, 8.0])
    assert np.allclose(f.gradient(env, coords, 2), [[3, 1, 0], [4, 2, 0]])
    H = f.hessian(env, coords, 2)
    assert H.shape == (2, 3, 3) and np.allclose(H[:, 0, 1], 1) and np.allclose(H[:, 0, 0], 0)


def test_map_env_falls_back_to_the_parent_then_the_constants():
    env = N.MapEnv({"a": 1.0}, N.MapEnv({"b": 2.0}))
    assert env.lookup("a") == 1.0 and env.lookup("b") == 2.0 and env.lookup("pi") == math.pi
    with pytest.raises(ExpressionError):
        env.lookup("nope")


def test_log_domain_as_the_evolver():
    """REF: `print log(-1)` is ERROR 1425, `print log(0)` prints -inf; in an
    element integrand a log of zero or a negative number is ERROR 1264
    (slidestr.fe under `U`, tests/reference/test_iterate_reference.py) —
    except in the rows an element-wise ``?:`` discards."""
    log = lambda a: N.Func("log", [a])
    assert log(N.Num(0.0)).ev({}) == -math.inf
    with pytest.raises(ExpressionError, match="log of negative number"):
        log(N.Num(-1.0)).ev({})

    class Arr(N.Node):
        def __init__(self, v):
            self.v = v

        def ev(self, env):
            return self.v

    v = np.array([2.0, 0.0, -1.0])
    with pytest.raises(ExpressionError, match="Log of zero or negative number"):
        log(Arr(v)).ev({})
    out = N.Cond(Arr(v > 0), log(Arr(v)), N.Num(0.0)).ev({})
    np.testing.assert_array_equal(out, [math.log(2.0), 0.0, 0.0])


def test_wrap_compose_and_inverse_of_the_torus_group():
    from pyevolver.expr.functions import FUNC1, FUNC2
    import numpy as np
    assert FUNC2["wrap_compose"](64.0, 31.0) == 95          # +y then -x
    assert FUNC1["wrap_inverse"](95.0) == 1985               # +x -y
    assert FUNC1["wrap_inverse"](126977.0) == 4127           # -x +z
    codes = np.array([0.0, 1.0, 1984.0, 4096.0])
    assert (FUNC2["wrap_compose"](codes, FUNC1["wrap_inverse"](codes)) == 0).all()
