"""pyevolver.remesh.group_refine: `r` in a symmetry group keeps every
facet's corners where they were (the midpoints halve the group edge
vectors) and gives the new edges REF's codes (around an axial point too;
REF's `list edges` after `r` is compared in tests/model/test_symmetry_groups.py)."""
import os

import numpy as np
import pytest

import pyevolver
from pyevolver.model.groups import group_of
from pyevolver.remesh import group_refine as GR
from pyevolver.remesh.refine import refine

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "symmetry_groups")


@pytest.mark.parametrize("name", ["rotate", "cubocta", "cubelat", "screw_symmetry",
                                  "rotate_axial"])
def test_refine_keeps_area_and_halves_edges(name):
    s = pyevolver.load(os.path.join(DATA, name + ".fe")).surface
    group = group_of(s)
    ev = GR.edge_vectors(s, group)
    t = refine(s)
    assert t.evaluate().total_area == pytest.approx(s.evaluate().total_area, rel=1e-12)
    ev2 = GR.edge_vectors(t, group)
    # each old edge: tail half (code 0) and head half (the old code), half as long
    assert np.allclose(ev2[:s.ne], ev / 2)
    assert not t.eattr["wrap_code"][:s.ne].any()
    assert np.allclose(np.linalg.norm(ev2[s.ne:s.ne + s.ne], axis=1),
                       np.linalg.norm(ev, axis=1) / 2)


def test_axial_facet_new_edge():
    """The facet (2, 4, -1) at the axial point: the midpoint of its last
    edge is reached through all three edges' elements (-1), not the identity."""
    s = pyevolver.load(os.path.join(DATA, "rotate_axial.fe")).surface
    t = refine(s)
    E, W = t.E, t.eattr["wrap_code"]
    mid = {e: s.nv + e for e in range(s.ne)}
    k = np.nonzero((E[:, 0] == mid[1]) & (E[:, 1] == mid[0]))[0]
    assert len(k) == 1 and W[k[0]] == -1


def test_quarter_turn_codes_along_the_rim(evolver):
    """quarter_turn (REF's product not associative): the new edges' codes
    composed along each facet's rim the short way are REF's after `r`
    (`r` itself stays refused there: commands.group_guard)."""
    import re
    from reference import run_reference
    path = os.path.join(DATA, "quarter_turn.fe")
    ref = run_reference(evolver, path, "r\nlist edges\n")
    codes = [int(m.group(1)) for m in (re.search(r"wrap (-?\d+)", ln) for ln in ref) if m]
    t = refine(pyevolver.load(path).surface)
    assert len(codes) == t.ne > 100
    assert list(t.eattr["wrap_code"]) == codes
    assert len(set(codes)) > 3
