"""Mesh commands: ``r``, ``u``, ``l``, ``K``, ``n``, ``O``, ``t``, ``w``,
``V``, ``j``, ``refine``/``edgeswap``/``delete`` of generated elements.

Each takes the session (duck-typed: ``surface``, ``totals``, ``settings``,
``counts``, ``note``, ``report``, ``_replace_surface``, ``_string_split``)
and changes its surface through the algorithms of :mod:`pyevolver.remesh`.
"""
from __future__ import annotations

import copy
import math

import numpy as np

from ..errors import CommandError, UnsupportedError
from ..remesh import string as SM
from ..remesh import string_mesh as SMESH
from ..remesh import delete_edges as DEL, edge_divide as ED, equiangulate as EQ
from ..remesh import notch as NO, pop as POP, vertex_average as VA
from ..remesh.quadratic import refine_quadratic
from ..remesh.refine import refine as _refine_all
from ..remesh.simplex import refine as refine_simplex
from . import fresh
from . import element_attrs, elements, variables
from .registry import register
from .values import ElemRef, SessionLike, as_float, is_true


def refine(session: SessionLike, echo=True):
    """``r``: refine every edge and facet (spec §8.1)."""
    s = session.surface
    if s.string:
        session._string_split(np.nonzero(~s.eattr["no_refine"])[0])
    elif s.simplex:
        session._replace_surface(refine_simplex(s))
        # REF multiplies the scale limit by 2^(k-2) (measured: 1 -> 2 -> 4 for
        # k = 3, 1 -> 4 -> 16 for k = 4, unchanged for k = 2)
        session.settings["scale_limit"] *= 2.0 ** (s.simplex - 2)
    elif s.order == 2:
        session._replace_surface(refine_quadratic(s))
    else:
        session._replace_surface(_refine_all(s))
    if "edge_divide_length" in session.settings:
        session.settings["edge_divide_length"] /= 2
    if "areaweed_area" in session.settings:
        session.settings["areaweed_area"] /= 4
    if session.settings.get("autochop_length"):
        # REF halves the autochop length at each r (autochop on or off;
        # not at `refine edges`): 100grain.fe 0.015 -> 0.0075
        session.settings["autochop_length"] /= 2
    if echo:
        session.note(counts_line(session))


def counts_line(session: SessionLike):
    """``Vertices: ..  Edges: ..`` as after ``r`` and ``c``."""
    s = session.surface
    return (f"Vertices: {s.nv}  Edges: {s.ne}  Facets: {s.n_facets}  "
            f"Bodies: {s.bodies.n}  "
            f"Facetedges: {variables.internal(session, 'facetedge_count'):.0f}\n")


def _replaced(session: SessionLike, result, count=None, note=None, echo=True):
    """Install the ``(new surface, n)`` a remesh operation returned; set
    the count ``count`` to ``n`` (REF: ``notch_count``, ``edge_delete_count``
    after ``t``, ... are the last such command's) and print ``note``
    (``{n}`` filled in)."""
    new, n = result
    if new is session.surface and fresh.is_fresh(session):
        session.reset_cg()              # (nothing changed: as the recalc would, no evaluation)
    else:
        session._replace_surface(new)
    if count is not None:
        set_count(session, count, n)
    if echo and note is not None:
        session.note(note.format(n=n))
    return n


def _divide(session: SessionLike, edges, choosers=None):
    """Bisect ``edges`` (the string model splits them); returns how many.
    ``choosers`` (``K``): per edge the facet that chose it (edge_divide)."""
    if session.surface.string:
        return session._string_split(np.asarray(edges, np.int64))
    return _replaced(session, ED.edge_divide(session.surface, edges, choosers))


def refine_edges(session: SessionLike, edges, echo=True):
    """``refine edges where ...``: bisect the given edges (spec §8)."""
    edges = np.asarray(edges, np.int64)
    n = _divide(session, np.unique(edges) if session.surface.string else edges)
    # refine_count follows edge_refine_count here, restarting with it
    restart = session.counts.get("reported edge_refine") and "Edges refined" not in session.pending
    session.counts["refine"] = (0 if restart else session.counts.get("refine", 0)) + n
    add_reported(session, "edge_refine", "Edges refined", n, echo)


def refine_facets(session: SessionLike, facets, echo=True):
    """``refine facets where ...``: split each facet into three at its
    centroid (REF's report "Facets refined: N")."""
    session.no_string("refine facets")
    f = np.unique(np.asarray(facets, np.int64))
    session._replace_surface(NO.split_facets_at_centre(session.surface, f))
    add_reported(session, "facet_refine", "Facets refined", len(f), echo)


def equiangulate(session: SessionLike, echo=True):
    """``u``: one equiangulation sweep (spec §8.2)."""
    if session.surface.string:
        raise CommandError("Cannot equiangulate string model.")      # REF's ERROR 2200
    n = _replaced(session, EQ.equiangulate(session.surface),
                  note="Edges switched in equiangulation: {n}\n", echo=echo)
    session.counts["equi"] = n                 # REF: the last sweep's flips
    return n


def edgeswap(session: SessionLike, edges, echo=True):
    """``edgeswap gen``: flip the listed edges that are diagonals of
    quadrilaterals, whatever the angles (manual: EDGESWAP)."""
    session.no_string("edgeswap")
    only = np.zeros(session.surface.ne, bool)
    only[np.asarray(edges, np.int64)] = True
    n = _replaced(session, EQ.equiangulate(session.surface, threshold=np.inf, only=only))
    if echo:
        session.report("Edges swapped", n)
    return n


def equiangulate_edges(session: SessionLike, edges):
    """``equiangulate edge_generator``: one equiangulation test of the listed
    edges, flipping those that pass (manual: EQUIANGULATE).  REF reports
    "Edges equiangulated: N" when the command ends (or at ``flush_counts``);
    ``equi_count`` adds up within a command and starts again after a report."""
    session.no_string("equiangulate")
    only = np.zeros(session.surface.ne, bool)
    only[np.asarray(edges, np.int64)] = True
    n = _replaced(session, EQ.equiangulate(session.surface, only=only))
    word = "Edges equiangulated"
    if word not in session.pending:         # reported since: the count starts again
        session.counts["equi"] = 0
    session.counts["equi"] = session.counts.get("equi", 0) + n
    session.report(word, n)
    return n


def flush_counts(session: SessionLike):
    """``flush_counts``: print the counts the running command has made
    nonzero (``Edges equiangulated: 28``) now instead of when it ends."""
    for word, n in session.pending.items():
        if n and word in ("Fixed", "Unfixed"):
            session.note(f"{word}: {n}\n")
        elif n:
            session.write(f"{word}: {n}\n")
    session.pending = {"Fixed": 0, "Unfixed": 0}


def _bisect(session: SessionLike, edges, echo, choosers=None):
    n = _divide(session, edges, choosers)
    if n or choosers is not None:                   # REF: each K (and l refining
        session.counts["refine"] = n                # something) sets refine_count
    if echo:
        session.note(f"New edges: {n}\n")
    return n


def edge_divide_long(session: SessionLike, length, echo=True):
    """``l L``: bisect every edge longer than ``L`` once (spec §8)."""
    n = _bisect(session, ED.long_edges(session.surface, length), echo)
    if n:                     # REF: l sets edge_refine_count too (a report's
        session.counts["edge_refine"] = n           # restart still pending)
    session.settings["edge_divide_length"] = length
    return n


def skinny(session: SessionLike, angle, echo=True):
    """``K θ``: bisect the longest edge of facets with an angle below θ."""
    s = session.surface
    if s.string:              # bisected one after the other (pyevolver.remesh.string_mesh)
        shifts: list = []
        R = SMESH.skinny_edges(s, angle, shifts)
        session._replace_surface(SMESH.split_in_order(s, R, SM.split_edges, shifts))
        session.counts["refine"] = len(R)
        if echo:
            session.note(f"New edges: {len(R)}\n")
        return len(R)
    edges, by = ED.skinny_edges(session.surface, angle, choosers=True)
    return _bisect(session, edges, echo, choosers=by)


def notch(session: SessionLike, angle, echo=True):
    """``n θ``: subdivide the facets on edges sharper than θ (spec §8)."""
    if session.surface.string:
        # REF: "Edges refined: N"; notch_count and refine_count set to N
        n = session._string_split(SMESH.notch_edges(session.surface, angle))
        if n:                 # REF: a notch refining nothing leaves the counts
            session.counts["notch"] = session.counts["refine"] = n
            if echo:
                session.note(f"Edges refined: {n}\n")
        return n
    return _replaced(session, NO.notch(session.surface, angle), "notch",
                     "Number of edges notched: {n}\n", echo)


def pop_edges(session: SessionLike, echo=True):
    """``O``: pop the edges with four facets (pyevolver.remesh.pop)."""
    n = _replaced(session, POP.pop_edges(session.surface), note="Edges popped: {n}\n",
                  echo=echo)
    session.counts["edge_pop"] = n             # REF: a later O with no pops prints 0
    return n


def set_count(session: SessionLike, key, n):
    """Set the count ``key`` (``notch_count``, ...) to ``n``."""
    session.counts[key] = n
    session.counts.pop("reported " + key, None)


def add_reported(session: SessionLike, key, word, n, echo=True):
    """A count REF reports when the command ends (``Edges refined: N``,
    ``Edges deleted: N``): within a command the counts add up (as they do
    onto a value another command set, e.g. ``l`` for ``edge_refine_count``);
    the first such command after the report starts again from 0; the
    report prints the total (measured on evolver-nox-d: ``refine edges where
    id < 5; refine edges where id < 9`` prints "Edges refined: 12" once, and
    a later command's count starts at 0)."""
    flag = "reported " + key
    if session.counts.get(flag) and word not in session.pending:
        session.counts[key] = 0
    session.counts[key] = session.counts.get(key, 0) + n
    session.counts[flag] = 1
    if echo:
        session.pending[word] = session.counts[key]


def delete_short_edges(session: SessionLike, length, echo=True):
    """``t L`` / ``edgeweed L``: delete edges shorter than ``L`` (spec §8.4)."""
    mod = SMESH if session.surface.string else DEL
    return _replaced(session, mod.delete_short_edges(session.surface, length), "edge_delete",
                     "Deleted edges: {n}\n", echo)


def delete_elements(session: SessionLike, kind, items, echo=True):
    """``delete edges ...`` / ``delete facets ...``: delete the edges (or,
    per facet, its shortest deletable side) as ``t`` / ``w`` do."""
    session.no_string("delete")
    fn = DEL.delete_edges if kind == "edge" else DEL.delete_facets
    return _replaced(session, fn(session.surface, items))


def jiggle(session: SessionLike, temperature=None, echo=True):
    """``j [T]``: move every vertex that is not FIXED or on a parametric
    boundary by a Gaussian displacement of deviation T × mean edge length
    (T defaults to ``jiggle_temperature``); vertices on constraints are
    projected back.  Seeded by ``random_seed`` (pyevolver's generator,
    so the numbers differ from the Evolver's)."""
    s = session.surface
    T = session.settings["jiggle_temperature"] if temperature is None else float(temperature)
    if not math.isfinite(T):
        raise CommandError(f"j: the temperature must be a finite number, got {T:g}")
    t = session.totals
    sigma = T * (float(np.mean(t.edge_length)) if s.ne else 0.0)
    move = ~s.vattr["fixed"]
    if "boundary" in s.vattr:
        move &= s.vattr["boundary"] == 0
    new = copy.copy(s)
    new.__dict__.pop("_lift_cache", None)
    new.X = s.X.copy()
    idx = np.nonzero(move)[0]
    new.X[idx, :s.sdim] += sigma * session.rng.standard_normal((len(idx), s.sdim))
    element_attrs.project_or_fail(session, new, idx)
    session._replace_surface(new)
    if echo:
        session.write("One jiggle done.\n")


def weed(session: SessionLike, area, echo=True):
    """``w A`` / ``areaweed A``: remove facets of area below ``A`` by
    deleting one of their edges, shortest first (spec §8.4)."""
    if session.surface.string:
        raise CommandError("Can only do area weed on soapfilm model.")   # REF's ERROR 1339
    # REF: w counts into facet_delete_count (edge_delete_count is t's)
    return _replaced(session, DEL.weed_small_facets(session.surface, area), "facet_delete",
                     "Skinny triangles weeded: {n}\n", echo)


def vertex_average(session: SessionLike, mode="V", echo=True):
    """``V``, ``rawv``, ``rawestv``: vertex averaging (spec §8.3)."""
    if session.surface.string:
        session._replace_surface(SM.vertex_average(session.surface, mode))
    else:
        now = session.totals if fresh.is_fresh(session) else None    # (no new evaluation)
        session._replace_surface(VA.vertex_average(session.surface, mode, now))
    if echo:
        session.note("Vertex averaging done.\n")


# -- the commands ---------------------------------------------------------------
FAMILY = "remesh"


def linear_only(session: SessionLike, what: str) -> None:
    """Refuse ``what`` by name in the quadratic model (pyevolver's mesh
    operations other than ``r`` do not carry the edge midpoints)."""
    if getattr(session.surface, "order", 1) == 2:
        raise UnsupportedError(f"{what} in the quadratic model",
                               "only r is implemented there; M 1 returns to the linear model")


@register("r", usage="r [n]", help="refine every edge and facet (n times)", family=FAMILY)
def _r(interp, raw, arg):
    for _ in range(1 if arg is None else interp.count(arg)):
        interp.tick()
        refine(interp.session)


@register("j", usage="j [temperature]", help="jiggle the vertices", family=FAMILY)
def _j(interp, raw, arg):
    linear_only(interp.session, "j (jiggle)")
    jiggle(interp.session,
           None if arg is None else as_float(interp.value(arg), f"the argument of {raw}"))


def _needs_value(interp, raw, arg, example):
    if arg is None:
        raise CommandError(f"{raw} needs a value (for example: {raw} {example})")
    return as_float(interp.value(arg), f"the argument of {raw}")


@register("t", "edgeweed", usage="t length", help="delete edges shorter than length",
          family=FAMILY)
def _t(interp, raw, arg):
    linear_only(interp.session, "t (edge weeding)")
    delete_short_edges(interp.session, _needs_value(interp, raw, arg, "0.01"))


@register("w", "areaweed", usage="w area", help="weed facets smaller than area",
          family=FAMILY)
def _w(interp, raw, arg):
    linear_only(interp.session, "w (area weeding)")
    weed(interp.session, _needs_value(interp, raw, arg, "0.01"))


@register("l", "edge_divide", usage="l length", help="bisect edges longer than length",
          family=FAMILY)
def _l(interp, raw, arg):
    linear_only(interp.session, "l (edge division)")
    edge_divide_long(interp.session, _needs_value(interp, raw, arg, "0.3"))


@register("K", usage="K angle", help="bisect skinny triangles", family=FAMILY)
def _k(interp, raw, arg):
    linear_only(interp.session, "K (skinny triangles)")
    skinny(interp.session, _needs_value(interp, raw, arg, "0.3"))


@register("n", "notch", usage="n angle", help="notch edges sharper than angle",
          family=FAMILY)
def _n(interp, raw, arg):
    linear_only(interp.session, "n (notching)")
    notch(interp.session, _needs_value(interp, raw, arg, "0.3"))


@register("V", "rawv", "rawestv", usage="V | rawv | rawestv", help="vertex averaging",
          family=FAMILY)
def _v_average(interp, raw, arg):
    linear_only(interp.session, "vertex averaging")
    vertex_average(interp.session, {"V": "V", "rawv": "raw", "rawestv": "rawest"}[raw])


@register("O", usage="O", help="pop edges with four facets", family=FAMILY)
def _o(interp, raw, arg):
    linear_only(interp.session, "O (popping)")
    pop_edges(interp.session)


@register("u", "equiangulate", usage="u", help="one equiangulation sweep", family=FAMILY)
def _u(interp, raw, arg):
    linear_only(interp.session, "u (equiangulation)")
    equiangulate(interp.session)


@register("refine", usage="refine edges|facets [where ...]", statement="refine",
          help="bisect the edges, or split the facets at their centres", family=FAMILY)
def _x_refine(interp, node):
    linear_only(interp.session, "refine")
    s = interp.session
    els = elements.generate(s, node[1], interp.env)
    kinds = {el.kind for el in els}
    if kinds - {"edge", "facet"}:
        raise UnsupportedError("refine of " + ", ".join(sorted(kinds - {"edge", "facet"}))
                               + "s", "'refine edges' and 'refine facets' are supported")
    if kinds == {"facet"}:
        refine_facets(s, [el.i for el in els])
    else:
        refine_edges(s, [el.i for el in els])


@register("edgeswap", usage="edgeswap edges [where ...]", statement="edgeswap",
          help="flip the edges that are quadrilateral diagonals", family=FAMILY)
def _x_edgeswap(interp, node):
    edgeswap(interp.session, _edges_of(interp, node, "edgeswap"))


def _edges_of(interp, node, word):
    """Indices of the edges a ``word edges [where ...]`` command names
    (linear model only; anything but edges is an error)."""
    linear_only(interp.session, word)
    els = elements.generate(interp.session, node[1], interp.env)
    if {el.kind for el in els} - {"edge"}:
        raise CommandError(f"{word} needs edges (for example: {word} edge[3])")
    return [el.i for el in els]


@register("equiangulate", usage="equiangulate edges [where ...]", statement="equiangulate",
          help="flip the given edges where that improves equiangularity", family=FAMILY)
def _x_equiangulate(interp, node):
    equiangulate_edges(interp.session, _edges_of(interp, node, "equiangulate"))


@register("flush_counts", usage="flush_counts", help="print the pending counts now",
          family=FAMILY, arg="none")
def _flush_counts(interp, raw, arg):
    flush_counts(interp.session)


@register("delete", usage="delete edges|facets [where ...]", statement="delete",
          help="delete edges (facets: their shortest side)", family=FAMILY)
def _x_delete(interp, node):
    linear_only(interp.session, "delete")
    s = interp.session
    gen = node[1]
    if gen.kind not in ("edge", "facet"):
        raise CommandError("delete needs edges or facets (for example: "
                           "delete edges where length < 0.01)")
    n = 0
    if gen.where is None or gen.base[0] != "all":
        n = delete_elements(s, gen.kind, [el.i for el in elements.generate(s, gen, interp.env)])
    else:
        # `delete edges where cond`: like the Evolver, visit the elements
        # in id order and test cond when each is reached, on the surface
        # the earlier deletions left (a merge can make a later edge short)
        hits = 0
        for eid in s.surface.ids(gen.kind).tolist():
            hit = np.nonzero(s.surface.ids(gen.kind) == eid)[0]
            if not len(hit):
                continue
            el = ElemRef(gen.kind, int(hit[0]))
            with interp.env.element(el, gen.var):
                v = gen.where.ev(interp.env)
            if is_true(v):
                hits += 1
                n += delete_elements(s, gen.kind, [el.i])
        s.counts["where"] = hits
    add_reported(s, f"{gen.kind}_delete", f"{'Edges' if gen.kind == 'edge' else 'Facets'} deleted",
                 n)
