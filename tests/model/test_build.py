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


@pytest.mark.parametrize("raw", [[[3, 1], [2, 4]], [3, 1, 2], [[1, 5]], [0, 1], [-2], [[2, 2], [4, 6]]])
def test_ids_one_to_n_map_as_any_ids(raw):
    # ids 1..n in order take a shortcut (no sorted copy): the same positions and messages
    fast = IdMap([1, 2, 3, 4], "vertex", "f.fe", [1, 2, 3, 4])
    slow = IdMap([4, 1, 2, 3], "vertex", "f.fe", [1, 2, 3, 4])     # positions: id 4 -> 0
    assert fast.order is None and slow.order is not None
    lines, users = [7, 8], [11, 12]
    try:
        got = fast.lookup(raw, lines, "edge", users)
    except DatafileError as exc:
        with pytest.raises(DatafileError) as ref:
            slow.lookup(raw, lines, "edge", users)
        assert (str(exc), exc.line) == (str(ref.value), ref.value.line)
        return
    want = slow.lookup(raw, lines, "edge", users)
    assert got.dtype == want.dtype == np.int64
    assert np.array_equal(np.where(want == 0, 3, want - 1), got)   # the two numberings


def test_string_model_repr():
    text = "string\nspace_dimension 2\nvertices\n1 0 0\n2 1 0\nedges\n1 1 2\n"
    s = build_surface(read_datafile("s.fe", text))
    assert "string" in repr(s) and s.n_facets == 0 and np.allclose(s.X[:, 2], 0)
