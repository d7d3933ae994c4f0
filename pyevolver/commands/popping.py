"""Popping commands of the soap-film model: ``o`` (pop the non-minimal
edges, then the non-minimal vertices) and the ``pop`` statement
(``pop vertex[3]``, ``pop edges where valence == 4``).

REF's reports and counts, as measured with evolver-nox-d:

- ``o`` prints ``Edges popped: N`` (the four-facet edges it pops first, as
  ``O`` does) and ``Vertices popped: M``; afterwards ``vertex_pop_count`` is
  ``M`` and ``edge_pop_count`` is 0.
- ``pop`` of vertices prints ``Vertices popped: M`` and sets
  ``vertex_pop_count``; of edges ``Edges popped: N`` and ``edge_pop_count``;
  nothing is printed when nothing was popped.
- ``pop_count`` is ``vertex_pop_count + edge_pop_count``.

The string model's ``o`` is not handled here (:func:`string_o`).
"""
from __future__ import annotations

from ..errors import CommandError, UnsupportedError
from ..remesh import pop as POP, string_pop as SPOP, vpop as VP
from . import elements
from .registry import register
from .remesh import linear_only
from .values import SessionLike

FAMILY = "mesh"


def string_o(session: SessionLike, items=None, echo_zero=True):
    """``o`` / ``pop vertex ...`` in the string model: vertices with more
    than three edges are split into triple junctions
    (:func:`pyevolver.remesh.string_pop.pop_vertices`)."""
    new, n = SPOP.pop_vertices(session.surface, items)
    session._replace_surface(new)
    session.counts["vertex_pop"] = n
    if n or echo_zero:                          # REF: pop is silent when nothing popped
        session.write(f"Vertices popped: {n}\n")
    return n


def _kraynik(session: SessionLike):
    """The ``kraynikpopvertex`` toggle (on by default in the Evolver)."""
    return bool(session.toggles.get("kraynikpopvertex", 1))


def _set_counts(session: SessionLike, vertices=None, edges=None):
    """Set the counts a pop command reports (``pop_count`` is their sum)."""
    if vertices is not None:
        session.counts["vertex_pop"] = vertices
    if edges is not None:
        session.counts["edge_pop"] = edges


def pop_all(session: SessionLike, echo=True):
    """``o``: pop the edges with four or more facets, then the non-minimal
    vertices (pyevolver.remesh.pop, pyevolver.remesh.vpop).  Nothing changes
    when either step is refused."""
    s0 = session.surface
    s1, ne_ = POP.pop_edges(s0)
    s2, nv_ = VP.pop_vertices(s1, kraynik=_kraynik(session))
    if s2 is not s0:
        session._replace_surface(s2)
    _set_counts(session, vertices=nv_, edges=0)
    if echo:
        session.note(f"Edges popped: {ne_}\nVertices popped: {nv_}\n")
    return ne_, nv_


def pop_listed(session: SessionLike, kind, items, echo=True):
    """``pop vertex[...]`` / ``pop edges ...``: pop those of the listed
    elements that are not minimal."""
    s0 = session.surface
    if kind == "vertex":
        s1, n = VP.pop_vertices(s0, which=items, kraynik=_kraynik(session))
        if s1 is not s0:
            session._replace_surface(s1)
        _set_counts(session, vertices=n)
        if echo and n:
            session.note(f"Vertices popped: {n}\n")
        return n
    s1, n = POP.pop_edges(s0, which=items)
    if s1 is not s0:
        session._replace_surface(s1)
    _set_counts(session, edges=n)
    if echo and n:
        session.note(f"Edges popped: {n}\n")
    return n


@register("o", usage="o", help="pop non-minimal edges and vertices", family=FAMILY)
def _o(interp, raw, arg):
    session = interp.session
    if session.surface.string:
        return string_o(session)
    linear_only(session, "o (popping)")
    pop_all(session)


@register("pop", usage="pop vertices|edges [where ...]", statement="pop",
          help="pop the listed non-minimal vertices or edges", family=FAMILY)
def _x_pop(interp, node):
    session = interp.session
    els = elements.generate(session, node[1], interp.env)
    if session.surface.string:
        if any(el.kind != "vertex" for el in els):
            raise UnsupportedError("pop of edges in the string model", "only vertices pop there")
        string_o(session, [el.i for el in els], echo_zero=False)
        return
    linear_only(session, "pop")
    kinds = {el.kind for el in els}
    if kinds - {"vertex", "edge"}:
        raise CommandError("pop needs vertices or edges (for example: pop vertex[3])")
    if not els:
        return
    kind = els[0].kind
    pop_listed(session, kind, [el.i for el in els])
