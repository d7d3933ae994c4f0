"""pyevolver.commands.group_guard: in a symmetry group other than the torus
the commands that would need the group elements are refused by name (the
surface unchanged), the group-aware ones run; the torus group is untouched."""
import os

import pytest

import pyevolver
from conftest import example
from pyevolver.commands import group_guard
from pyevolver.errors import PyEvolverError

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "symmetry_groups")


@pytest.mark.parametrize("word", sorted(group_guard.WORDS))
def test_words_refused(word):
    sess = pyevolver.load(os.path.join(DATA, "cubocta.fe"))
    with pytest.raises(PyEvolverError, match=f'in SYMMETRY_GROUP "cubocta"'):
        group_guard.check(sess, word)


def test_group_aware_commands_run():
    sess = pyevolver.load(os.path.join(DATA, "cubocta.fe"))
    e0 = sess.value("total_energy")
    sess.run("g 2\nr\ng 1\nconvert_to_quantities")
    assert sess.value("total_energy") < e0
    for word in ("g", "r", "j", "list", "dump", "print"):
        group_guard.check(sess, word)
    qt = pyevolver.load(os.path.join(DATA, "quarter_turn.fe"))
    group_guard.check(qt, "g10")
    with pytest.raises(PyEvolverError, match="`r` in SYMMETRY_GROUP \"quarter_turn\""):
        group_guard.check(qt, "r")


def test_torus_group_untouched():
    sess = pyevolver.load(example("symtest.fe"))
    for word in ("t", "u", "V", "hessian"):
        group_guard.check(sess, word)
    group_guard.check(sess, "delete", statement=True)
