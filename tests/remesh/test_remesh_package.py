"""Direct tests of the pyevolver.remesh package: what it exports."""
import os
import sys

import numpy as np

import pyevolver
import pyevolver.remesh as remesh
from pyevolver.remesh import grow, refine

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def test_exports():
    assert sorted(remesh.__all__) == ["grow", "refine"]
    # the names are the functions of the same-named modules
    assert refine is sys.modules["pyevolver.remesh.refine"].refine
    assert grow is sys.modules["pyevolver.remesh.grow"].grow
    assert callable(refine) and callable(grow)
    ns = {}
    exec("from pyevolver.remesh import *", ns)
    assert ns["refine"] is refine and ns["grow"] is grow


def test_exported_functions_work():
    s = pyevolver.load(CUBE).surface
    t = refine(s)
    assert (t.nv, t.ne, t.nf) == (50, 144, 96)
    g = grow(s, v_from_edge=np.array([0]))
    assert g.nv == s.nv + 1 and s.nv == 14
