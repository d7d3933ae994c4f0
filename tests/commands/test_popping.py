"""The popping commands of the soap-film model (pyevolver.commands.popping):
``o`` and the ``pop`` statement, their reports and the pop counts, against
evolver-nox-d run live."""
import io

import pytest
from conftest import example
from reference import run_reference

from pyevolver import Session
from pyevolver.commands import popping
from pyevolver.errors import PyEvolverError


def _ours(path, cmds):
    out = io.StringIO()
    s = Session.load(path, out=out)
    s.run(cmds)
    return s, [ln for ln in out.getvalue().split("\n") if ln.strip()]


def _ref(evolver, path, cmds, tmp_path):
    return [ln for ln in run_reference(evolver, path, cmds, cwd=str(tmp_path)) if ln.strip()]


COUNTS = "print vertex_pop_count\nprint edge_pop_count\nprint pop_count\nprint vertex_count"


@pytest.mark.parametrize("name,pre", [("cube.fe", "g 5"), ("octa.fe", "g 5"),
                                      ("octa.fe", "g 5\nO\nprint edge_pop_count")])
def test_o_reports_and_counts(evolver, tmp_path, name, pre):
    """``o`` prints both counts; afterwards edge_pop_count is 0 even when it
    popped edges, vertex_pop_count and pop_count the vertices."""
    cmds = pre + "\no\n" + COUNTS
    ref = [ln for ln in _ref(evolver, example(name), cmds, tmp_path) if "area:" not in ln]
    _, ours = _ours(example(name), cmds)
    ours = [ln for ln in ours if "area:" not in ln]
    assert [ln.split() for ln in ours] == [ln.split() for ln in ref]


def test_pop_statement(evolver, tmp_path):
    """``pop edge[13]`` pops one edge; ``O`` the other five; a ``pop`` that
    finds nothing to pop prints nothing and sets its count to 0;
    ``pop_count`` is the sum of the vertex and edge counts."""
    cmds = "\n".join(["g 5", "pop edge[13]", "print pop_count", "O", "print pop_count",
                      "pop edge[13]", "print edge_pop_count", "print pop_count",
                      "pop vertex[2]", "print vertex_pop_count", "print pop_count",
                      "print edge_count"])
    ref = [ln for ln in _ref(evolver, example("octa.fe"), cmds, tmp_path) if "area:" not in ln]
    _, ours = _ours(example("octa.fe"), cmds)
    ours = [ln for ln in ours if "area:" not in ln]
    assert [ln.split() for ln in ours] == [ln.split() for ln in ref]


def test_pop_vertices_where(evolver, tmp_path):
    """``pop vertices where ...`` after the edges are popped: the centre."""
    cmds = "g 5\nO\npop vertices where id < 4\nprint vertex_pop_count\nprint vertex_count\n" \
           "print facet_count\ng 3"
    ref = _ref(evolver, example("octa.fe"), cmds, tmp_path)
    _, ours = _ours(example("octa.fe"), cmds)
    assert [ln.split()[:4] for ln in ours] == [ln.split()[:4] for ln in ref]


def test_pop_needs_vertices_or_edges():
    s = Session.load(example("cube.fe"), out=io.StringIO())
    with pytest.raises(PyEvolverError, match="vertices or edges"):
        s.run("pop facet[1]")


def test_pop_vertex_on_four_facet_edges_is_refused():
    """The Evolver pops such a vertex directly; pyevolver refuses (``o``
    pops the edges first, then the vertex)."""
    s = Session.load(example("octa.fe"), out=io.StringIO())
    before = s.surface
    with pytest.raises(PyEvolverError, match="four or more facets"):
        s.run("pop vertex[1]")
    assert s.surface is before


def test_o_in_the_string_model_pops_the_four_edge_junction():
    """popstr.fe's junction of four edges becomes two triple junctions
    (pyevolver.remesh.string_pop; REF's positions in tests/remesh/test_string_pop.py)."""
    out = io.StringIO()
    s = Session.load(example("popstr.fe"), out=out)
    nv, ne = s.surface.nv, s.surface.ne
    s.run("o")
    assert "Vertices popped: 1" in out.getvalue()
    assert (s.surface.nv, s.surface.ne) == (nv + 1, ne + 1)


def test_kraynik_toggle_default():
    """kraynikpopvertex is on in a fresh session (as in the Evolver)."""
    s = Session.load(example("cube.fe"), out=io.StringIO())
    assert popping._kraynik(s) is True
    s.run("kraynikpopvertex off")
    assert popping._kraynik(s) is False
