"""pyevolver.limits: the nesting depth of parsed trees."""
from pyevolver.expr import nodes as N
from pyevolver.limits import MAX_NESTING, nesting_depth


def test_depth_of_nodes_tuples_and_leaves():
    assert nesting_depth(1.0) == 1
    assert nesting_depth(("a", [1, 2], "s")) == 2
    e = N.Num(1.0)
    for _ in range(5):
        e = N.Neg(e)
    assert nesting_depth(e) == 6


def test_a_tree_deeper_than_python_recursion_is_measured_and_cut():
    e = N.Num(1.0)
    for _ in range(50_000):
        e = N.Neg(e)
    assert nesting_depth(e) == MAX_NESTING + 1
    assert nesting_depth(e, limit=10) == 11
