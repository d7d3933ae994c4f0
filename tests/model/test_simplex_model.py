"""pyevolver.model.simplex: the simplex model's reader (facets as oriented
vertex lists, no edges) and what it refuses by name."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.errors import DatafileError
from pyevolver.model import simplex as SX

EX = "/usr/share/doc/evolver/examples/simplex3.fe"
DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")

HEAD = "SIMPLEX_REPRESENTATION\nSPACE_DIMENSION 4\nSURFACE_DIMENSION 3\n"
VERTS = "vertices\n1 0 0 0 0\n2 1 0 0 0\n3 0 1 0 0\n4 0 0 1 0\n5 0 0 0 1\n"
FACES = "faces\n1 2 3 4 5\n2 3 4 5 1\n3 4 5 1 2\n4 5 1 2 3\n5 1 2 3 4\n"


def _load_text(tmp_path, text):
    p = tmp_path / "sx.fe"
    p.write_text(text)
    return Session.load(str(p), out=io.StringIO(), err=io.StringIO())


def test_reads_vertex_lists(tmp_path):
    s = _load_text(tmp_path, HEAD + VERTS + FACES + "bodies\n1 1 2 3 4 5 volume 0.04\n").surface
    assert s.simplex == 3 and s.SF.shape == (5, 4) and s.ne == 0 and s.nf == 0
    assert s.n_facets == 5 and s.bodies.n == 1
    assert s.SF[0].tolist() == [1, 2, 3, 4]          # 0-based vertices of face 1: 2 3 4 5
    assert np.isclose(s.bodies.target[0], 0.04)
    assert "simplex" in repr(s)


def test_tetra_in_three_space():
    s = Session.load(os.path.join(DATA, "simplex_tetra.fe"), out=io.StringIO()).surface
    assert s.simplex == 2 and s.SF.shape == (4, 3)
    assert s.evaluate().volumes[0] == pytest.approx(1 / 6)


@pytest.mark.parametrize("extra,where,match", [
    ("constraint 1\nformula: x = 0\nenergy:\ne1: 0\ne2: 0\ne3: 0\n", "top",
     "constraint ENERGY and CONTENT integrals in the simplex model"),
    ("constraint 1 convex\nformula: x = 0\n", "top", "CONVEX constraints"),
    ("quantity q energy method vertex_scalar_integral\nscalar_integrand: x\n", "top",
     "named quantities in the simplex model"),
    ("TORUS\nPERIODS\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n", "top", "torus model"),
    ("QUADRATIC\n", "top", "quadratic model"),
    ("edges\n1 1 2\n", "edges", "edges section"),
])
def test_refused_by_name(tmp_path, extra, where, match):
    text = (HEAD + extra + VERTS + FACES) if where == "top" else (HEAD + VERTS + extra + FACES)
    with pytest.raises(DatafileError, match=match) as exc:
        _load_text(tmp_path, text)
    assert "not supported in pyevolver" in str(exc.value)


def test_bad_facets(tmp_path):
    with pytest.raises(DatafileError, match="needs 4 vertices"):
        _load_text(tmp_path, HEAD + VERTS + "faces\n1 1 2 3\n")
    with pytest.raises(DatafileError, match="listed twice"):
        _load_text(tmp_path, HEAD + VERTS + "faces\n1 1 2 3 3\n")
    with pytest.raises(DatafileError, match="vertex"):
        _load_text(tmp_path, HEAD + VERTS + "faces\n1 1 2 3 9\n")
    with pytest.raises(DatafileError, match="SURFACE_DIMENSION 5"):
        _load_text(tmp_path, HEAD.replace("3\n", "5\n").replace("SPACE_DIMENSION 4",
                                                                "SPACE_DIMENSION 6")
                   + "vertices\n1 0 0 0 0 0 0\n")
    with pytest.raises(DatafileError, match="bodies in SPACE_DIMENSION 5"):
        _load_text(tmp_path, HEAD.replace("SPACE_DIMENSION 4", "SPACE_DIMENSION 5")
                   + VERTS.replace(" 0\n", " 0 0\n").replace(" 1\n", " 1 0\n") + FACES
                   + "bodies\n1 1 2 3 4 5\n")


def test_dimension_helpers():
    class Sc:
        values = {"surface_dimension": 3.0}
    assert SX.simplex_dimension(Sc()) == 3 and SX.MAX_SIMPLEX_DIM == 4
