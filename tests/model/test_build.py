"""pyevolver.model.build and pyevolver.model.surface: Scene -> Surface."""
import numpy as np
import pytest

from pyevolver.datafile.reader import read_datafile
from pyevolver.errors import DatafileError
from pyevolver.model.build import build_surface
from pyevolver.model.ids import IdMap
from pyevolver.model.surface import Surface

CUBE = "datafiles/cube.fe"


def test_cube_counts_and_repr():
    s = build_surface(read_datafile(CUBE))
    assert isinstance(s, Surface)
    # each square face gets a centre vertex: 6 x 4 triangles
    assert (s.nv, s.ne, s.nf, s.bodies.n) == (14, 36, 24, 1)
    r = repr(s)
    assert "14 vertices" in r and "36 edges" in r and "24 facets" in r and "1 bodies" in r
    assert "soapfilm" in r and "space dimension 3" in r


def test_ids_are_one_based_and_original_kept():
    s = build_surface(read_datafile(CUBE))
    assert list(s.ids("vertex")) == list(range(1, 15))
    assert list(s.vattr["original"][:8]) == list(range(1, 9))


def test_undefined_vertex_is_a_located_datafile_error():
    text = "vertices\n1 0 0 0\nedges\n1 1 2\n"
    with pytest.raises(DatafileError) as exc:
        build_surface(read_datafile("bad.fe", text))
    assert exc.value.line == 4
    assert "vertex 2" in str(exc.value)


def test_idmap_lookup_and_duplicates():
    m = IdMap([5, 2, 9], "vertex", "f.fe", [1, 2, 3])
    assert list(m.lookup([9, 5], [1, 1], "edge", [1, 1])) == [2, 0]
    with pytest.raises(DatafileError, match="defined twice"):
        IdMap([1, 1], "vertex", "f.fe", [1, 2])


def test_string_model_repr():
    text = "string\nspace_dimension 2\nvertices\n1 0 0\n2 1 0\nedges\n1 1 2\n"
    s = build_surface(read_datafile("s.fe", text))
    assert "string" in repr(s) and s.n_facets == 0 and np.allclose(s.X[:, 2], 0)
