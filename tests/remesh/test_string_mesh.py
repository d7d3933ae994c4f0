"""``t``, ``K`` and ``n`` in the string model against evolver-nox-d
(pyevolver.remesh.string_mesh): element numbering, coordinates, wraps,
facet chains, counts and the ``g`` lines after them."""
import io
import os

import numpy as np
import pytest

import pyevolver
from pyevolver.errors import UnsupportedError
from pyevolver.remesh import string_mesh as SMESH
from pyevolver.remesh.string import split_edges
from conftest import example
from comparison import compare_transcripts

DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")
_compare = compare_transcripts


CASES = {
    "notch": ("string_notch.fe", "n 0.2\nlist vertices\nlist edges\nprint notch_count\n"
              "print refine_count\nn 0.5\nlist edges\nn 2\nprint notch_count\n"),
    "weed": ("string_weed.fe", "t 0.1\nprint edge_delete_count\nlist vertices\nlist edges\n"),
    "weed_body": ("string_weed_body.fe", "t 0.1\nlist vertices\nlist edges\nlist facets\n"
                  "print body[1].volume\ng 3\n"),
    "weed_torus": ("string_weed_torus.fe", "t 0.2\nlist vertices\nlist edges\n"),
    "dissolve": ("string_dissolve.fe", "t 0.1\nlist vertices\nlist edges\nlist facets\n"
                 "list bodies\ng 2\n"),
    "dissolve4": ("string_dissolve4.fe", "t 0.1\nlist vertices\nlist edges\nlist facets\n"
                  "g 2\n"),
    "skinny_torus": ("string_skinny_torus.fe", "K 1.5\nlist vertices\nlist edges\ng 2\n"),
    "skinny": ("string_skinny.fe", "K 0.6\nlist edges\nK 0.75\nlist edges\nlist vertices\n"
               "print refine_count\nK 3\nprint refine_count\n"),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_string_mesh_commands_match_reference(evolver, tmp_path, name):
    fe, script = CASES[name]
    _compare(evolver, os.path.join(DATA, fe), script, tmp_path)


def test_slidestr_after_g(evolver, tmp_path):
    _compare(evolver, example("slidestr.fe"),
             "g 5\nt 0.1\ng 3\nK 0.2\ng 2\nn 0.5\nlist edges\ng 3\nt 0.3\nlist vertices\ng 2\n",
             tmp_path, rtol=1e-8)


def test_100grain_skinny(evolver, tmp_path):
    _compare(evolver, example("100grain.fe"),
             "autopop off\nautochop off\nK 0.3\nlist vertices\nlist edges\ng 3\nK 0.3\ng 2\n",
             tmp_path, rtol=1e-8)


def test_100grain_weed_and_notch(evolver, tmp_path):
    _compare(evolver, example("100grain.fe"),
             "autopop off\nautochop off\nt 0.06\nprint total_energy\nlist vertices\nlist edges\n"
             "list facets\ng 3\nn 1.0\nprint vertex_count\ng 2\n", tmp_path, rtol=1e-8)


# ---------------------------------------------------------------------------
# closed forms and refusals


def _load(text, tmp_path):
    p = tmp_path / "s.fe"
    p.write_text(text)
    return pyevolver.load(str(p), out=io.StringIO())


def test_dihedral_is_the_angle_from_straightness(tmp_path):
    sess = _load("STRING\nSPACE_DIMENSION 2\nvertices\n1 0 0\n2 1 0\n3 1 1\n4 5 5\n"
                 "edges\n1 1 2\n2 2 3\n", tmp_path)
    d = SMESH.dihedral(sess.surface)
    assert np.allclose(d, [0, np.pi / 2, 0, 0])


def test_weed_deletes_a_loop_at_its_visit_as_ref(evolver, tmp_path):
    # edge 4 joins the ends of edge 1: after edge 1 goes it is a loop, deleted
    # (and counted) at its own visit; the vertex stays at edge 1's midpoint
    p = tmp_path / "loop.fe"
    p.write_text("STRING\nSPACE_DIMENSION 2\nvertices\n1 0 0\n2 0.05 0\n3 0 1\n"
                 "edges\n1 1 2\n2 2 3\n3 3 1\n4 2 1\n")
    out = _compare(evolver, str(p), "t 0.1\nlist vertices\nlist edges\ng 2\n", tmp_path)
    assert any("Deleted edges: 2" in line for line in out)


def test_skinny_refuses_one_edge_chains(tmp_path):
    sess = _load("STRING\nSPACE_DIMENSION 2\nvertices\n1 0 0\n2 1 0\nedges\n1 1 2\n"
                 "faces\n1 1\n", tmp_path)
    with pytest.raises(UnsupportedError, match="one edge"):
        SMESH.skinny_edges(sess.surface, 0.5)


def test_split_in_order_matches_one_by_one(tmp_path):
    sess = _load(open(os.path.join(DATA, "string_skinny.fe")).read(), tmp_path)
    s = sess.surface
    order = [2, 0, 0, 11, 5]               # repeated edge, then a half made earlier
    a = SMESH.split_in_order(s, order, split_edges)
    b = s
    for e in order:
        b = split_edges(b, np.array([e]))
    assert np.array_equal(a.E, b.E) and np.allclose(a.X, b.X)
    assert np.array_equal(a.sf_enc, b.sf_enc)


def test_100grain_t_after_autochop(evolver, tmp_path):
    # after g 5 the cells' sides are chains of chopped edges: deleting an
    # edge between a junction and a chain vertex leaves the junction in place
    _compare(evolver, example("100grain.fe"), "g 5\nt 0.02\ng 3\n", tmp_path)
