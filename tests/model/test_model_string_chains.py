"""pyevolver.model.string: facets of the string model as edge chains
(incidences, chain vertices of closed and open chains, facets of an edge,
REF's facet-edge count), vertex edge rings, refusals."""
import io

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.errors import CommandError, UnsupportedError
from pyevolver.methods.registry import REGISTRY
from pyevolver.model import string as MS

TEXT = """STRING
SPACE_DIMENSION 2
vertices
1 0 0
2 1 0
3 1 1
4 0 1
5 2 0.5
edges
1 1 2
2 2 3
3 3 4
4 4 1
5 2 5
6 5 3
7 5 1
faces
1 1 2 3 4
2 5 6 -2
3 3 4
"""


@pytest.fixture
def s(tmp_path):
    p = tmp_path / "chains.fe"
    p.write_text(TEXT)
    return Session.load(str(p), out=io.StringIO()).surface


def test_facet_entries_follow_the_chains(s):
    owner, e, sgn, tail, head = MS.facet_entries(s)
    assert owner.tolist() == [0, 0, 0, 0, 1, 1, 1, 2, 2]
    assert e.tolist() == [0, 1, 2, 3, 4, 5, 1, 2, 3]
    assert sgn.tolist() == [1, 1, 1, 1, 1, 1, -1, 1, 1]
    # consecutive edges of a chain meet: head of one = tail of the next
    for f in range(3):
        k = np.nonzero(owner == f)[0]
        assert np.array_equal(head[k[:-1]], tail[k[1:]])
    assert head[6] == 1 and tail[6] == 2                   # edge 2 backwards in facet 2
    Pt, Ph = MS.chain_points(s)
    assert np.array_equal(Pt, s.X[tail]) and np.array_equal(Ph, s.X[head])


def test_chain_vertices_closed_and_open(s):
    assert MS.chain_vertices(s, 0) == [0, 1, 2, 3]           # closed: n vertices
    assert MS.chain_vertices(s, 1) == [1, 4, 2]
    assert MS.chain_vertices(s, 2) == [2, 3, 0]              # open: n + 1
    assert MS.chain_vertices(s, 2, sign=-1) == [0, 3, 2]
    assert MS.chain(s, 1).tolist() == [4, 5, ~1]


def test_facets_of_an_edge_and_facetedge_count(s):
    assert MS.facets_of_edge(s, 1) == [(0, 1), (1, -1)]
    assert MS.facets_of_edge(s, 2) == [(0, 1), (2, 1)]
    assert MS.facets_of_edge(s, 6) == []
    # 9 (facet, edge) incidences and one for edge 7, on no facet
    assert MS.facetedge_count(s) == 10


def test_vertex_edge_ring_order(s):
    # vertex 1: its first edge (edge 1, as tail), then the others newest first
    assert MS.vertex_edges(s, 0) == [(0, 1), (6, -1), (3, -1)]
    assert MS.vertex_edges(s, 4) == [(4, -1), (6, 1), (5, 1)]


def test_refusals_and_string_methods(s):
    with pytest.raises(CommandError, match="needs facets"):
        MS.check_no_facets_needed(s, "refine")
    with pytest.raises(UnsupportedError):
        MS.refuse("hessian_seek")
    for name in MS.STRING_METHODS:
        assert REGISTRY[name].etype in ("vertex", "edge")
