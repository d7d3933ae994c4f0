"""pyevolver.model.records: per-element records and topology queries."""
import numpy as np

from pyevolver.datafile.reader import read_datafile
from pyevolver.model.build import build_surface
from pyevolver.model.formulas import LocatedFormula, located
from pyevolver.model.records import (along_first, convex_edges, edge_facets, edge_first_facet,
                                     vertex_edge_rank)
from pyevolver.errors import PyEvolverError


def cube():
    return build_surface(read_datafile("datafiles/cube.fe"))


def test_closed_surface_edges_have_two_facets():
    s = cube()
    ef, ek, val = edge_facets(s)
    assert np.all(val == 2) and np.all(ef >= 0)
    idx, _, _ = s.topology()
    for e in range(s.ne):                     # the recorded facets do hold the edge
        for f, k in zip(ef[e], ek[e]):
            assert idx[f, k] == e


def test_first_facet_and_ranks():
    s = cube()
    first = edge_first_facet(s)
    assert first.shape == (s.ne,)
    # the datafile's 12 edges have a first facet; the edges to the face
    # centres are -1 (unknown: the facet order decides)
    assert np.all(first[:12] >= 0) and np.all(first[12:] == -1)
    rank = vertex_edge_rank(s)
    assert rank.shape == (s.ne, 2)
    assert convex_edges(s) == []


def test_located_names_the_declaration():
    try:
        with located("constraint 3", 17):
            raise PyEvolverError("division by zero")
    except PyEvolverError as exc:
        assert exc.line == 17 and str(exc).startswith("constraint 3:")

    class F:
        def values(self, *a):
            raise PyEvolverError("bad")
    try:
        LocatedFormula(F(), "boundary 1", 4).values()
    except PyEvolverError as exc:
        assert exc.line == 4



def test_rings_recorded_as_a_function_are_computed_once_when_read():
    from pyevolver.model.records import record_vertex_rings
    s = cube()
    rank = vertex_edge_rank(s)
    assert not rank.flags.writeable                       # the loaded order, kept
    assert vertex_edge_rank(s) is rank
    calls = []

    def later():
        calls.append(1)
        return rank + 0
    record_vertex_rings(s, later)
    assert not calls                                      # not computed yet
    assert np.array_equal(vertex_edge_rank(s), rank)
    assert np.array_equal(vertex_edge_rank(s), rank)
    assert calls == [1]                                   # once
    s.E = s.E[:, ::-1].copy()                             # the edges changed: not used
    vertex_edge_rank(s)
    assert calls == [1] and s._rings[1] is not rank


def test_lazy_rings_do_not_chain_surfaces():
    # K bisects in rounds, each a new surface: a round's lazy rings are
    # settled when the next round records its own (no chain kept alive)
    from pyevolver.remesh.refine import refine
    s1 = refine(cube())
    assert callable(s1._rings[1])
    s2 = refine(s1)
    assert not callable(s1._rings[1]) and callable(s2._rings[1])
    assert not callable(s1._along_first[2]) and callable(s2._along_first[2])
    assert along_first(s2).shape == (s2.ne,) and not callable(s2._along_first[2])
    assert vertex_edge_rank(s2).shape == (s2.ne, 2)


def _rings_by_rule(s):
    """The loaded ring order as the docstring states it, vertex by vertex:
    the lowest-numbered edge first, then the others newest (highest id)
    first."""
    ids = list(s.ids("edge"))
    want = np.empty((s.ne, 2), np.int64)
    for v in range(s.nv):
        ends = [(e, k) for e in range(s.ne) for k in (0, 1) if s.E[e, k] == v]
        ends.sort(key=lambda ek: ids[ek[0]])
        ring = ends[:1] + sorted(ends[1:], key=lambda ek: -ids[ek[0]])
        for pos, (e, k) in enumerate(ring):
            want[e, k] = pos
    return want


def test_loaded_rings_follow_the_rule_with_ids_in_any_order():
    s = cube()
    assert np.array_equal(vertex_edge_rank(s), _rings_by_rule(s))
    t = cube()
    ids = np.asarray(t.ids("edge"))
    perm = np.random.default_rng(3).permutation(len(ids))
    t.eattr["id"] = (ids[perm] * 7).astype(np.int64)     # (gapped ids, not in order)
    assert np.array_equal(vertex_edge_rank(t), _rings_by_rule(t))
