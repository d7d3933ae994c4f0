"""Constraint commands: ``set gen constraint n``, ``unset gen constraint
n``, ``define constraint NAME formula: ...``, and the labels ``list``
prints for constraints and boundaries (a number, or the name given by
``define constraint``).  ``fix``/``unfix``: :mod:`pyevolver.commands.fixing`.
"""
from __future__ import annotations

import re

import numpy as np

from ..datafile.preprocess import Section
from ..datafile.reader import Reader
from ..errors import CommandError, UnsupportedError
from ..constraints import project_to_constraints
from .registry import register
from .values import SessionLike


def set_constraint(session: SessionLike, els, cid):
    """``set gen constraint n``: put the elements on level-set constraint
    ``n`` (a number or a name from ``define constraint``); vertices are
    projected onto it at once (REF)."""
    s = session.surface
    if isinstance(cid, str) or int(cid) not in s.constraints:
        raise CommandError(f"constraint {cid if isinstance(cid, str) else int(cid)} "
                           f"is not defined")
    cid = int(cid)
    moved = []
    order = getattr(s, "con_order", None)
    for el in els:
        if order is not None and el.kind in ("vertex", "edge"):
            # REF lists a constraint set later after the element's others
            table = s.vcon if el.kind == "vertex" else s.econ
            had = [c for c in sorted(table) if table[c][el.i] and c != cid]
            seq = [c for c in order.get((el.kind, el.i), had) if c in had]
            order[(el.kind, el.i)] = seq + [c for c in had if c not in seq] + [cid]
        if el.kind == "vertex":
            m = s.vcon.setdefault(cid, np.zeros(s.nv, bool))
            m[el.i] = True
            moved.append(el.i)
        elif el.kind == "edge":
            s.econ.setdefault(cid, np.zeros(s.ne, np.int8))[el.i] = 1
        elif el.kind == "facet" and not s.string:
            s.fcon.setdefault(cid, np.zeros(s.nf, bool))[el.i] = True
        else:
            raise CommandError("constraints belong to vertices, edges and facets")
    if moved:
        project_to_constraints(s, np.array(moved, np.int64))


def define_constraint(session: SessionLike, text):
    """``define constraint NAME [flags] formula: expr [energy: ...] [content:
    ...]`` at run time: a level-set constraint numbered after the existing
    ones and known by its name (REF: ``list`` shows the name,
    ``on_constraint NAME`` and ``set ... constraint NAME`` use it)."""
    m = re.match(r"\s*define\s+constraint\s+([a-z_]\w*)(.*)\Z", text, re.I | re.S)
    if m is None:
        raise CommandError("define constraint: expected a name, e.g. "
                           "define constraint cc formula: x^2 + y^2 = 1")
    name, rest = m.group(1).lower(), m.group(2)
    arr = re.search(r"([a-z_]\w*)\s*\[", rest, re.I)
    if arr:
        raise UnsupportedError(f"array elements in constraint formulas ({arr.group(1)}[...] "
                               f"in constraint {name})")
    s = session.surface
    names = getattr(s, "constraint_names", {})
    cid = next((c for c, n in names.items() if n == name), None)
    if cid is None:
        if name in session.variables or name in session.commands:
            raise CommandError(f"define constraint: '{name}' is already a variable or command")
        cid = max(s.constraints, default=0) + 1
    reader = Reader("<define constraint>", "")
    reader.scene.parameters = {k: v for k, v in session.variables.items()
                               if isinstance(v, float)}
    reader._top(Section("top", f"constraint {cid} {rest}\n", 1, [1]))
    decl = reader.scene.constraints[cid]
    s.constraints = {**s.constraints, cid: decl}
    s.constraint_names = {**names, cid: name}
    if "global" in decl.flags:
        s.vcon[cid] = np.ones(s.nv, bool)
        s.econ[cid] = np.ones(s.ne, np.int8)
        project_to_constraints(s, np.arange(s.nv))


def constraint_label(session: SessionLike, cid):
    """A constraint's number, or its name when defined at run time."""
    return getattr(session.surface, "constraint_names", {}).get(cid, str(cid))


def in_order(session: SessionLike, kind, i, cons):
    """An element's constraints in the order REF lists them: as the
    datafile line gave them, then those set later, in turn (``cons``:
    the constraints it is on, by number)."""
    order = getattr(session.surface, "con_order", None)
    seq = order.get((kind, i)) if order else None
    if not seq or len(cons) < 2:
        return cons
    first = [c for c in seq if c in cons]
    return first + [c for c in cons if c not in first]


def record_order(session: SessionLike, scene, surface):
    """The datafile order of the constraints of vertices and edges named
    with several (see :meth:`_in_order`)."""
    order = {}
    for kind, blk, n in (("vertex", scene.vertices, surface.nv),
                         ("edge", scene.edges, surface.ne)):
        for pos, attrs in blk.attrs.items():
            cids = [int(abs(v)) for kw, vals in attrs
                    if kw in ("constraint", "constraints") for v in vals]
            if len(cids) > 1 and cids != sorted(cids) and pos < n:
                order[(kind, pos)] = cids
    surface.con_order = order


def boundary_label(session: SessionLike, bid):
    """A boundary's number, or its name when declared by name."""
    return getattr(session.surface, "boundary_names", {}).get(bid, str(bid))


def unset_constraint(session: SessionLike, els, cid):
    """``unset gen constraint n``: take the elements off constraint ``n``."""
    s = session.surface
    if cid not in s.vcon and cid not in s.econ and cid not in s.fcon:
        return
    for el in els:
        table = {"vertex": s.vcon, "edge": s.econ, "facet": s.fcon}.get(el.kind)
        if table is None:
            raise CommandError("constraints belong to vertices, edges and facets")
        m = table.get(cid)
        if m is not None:
            m[el.i] = 0


# -- the commands -----------------------------------------------------------------------
@register("define constraint", usage="define constraint NAME formula: expr",
          statement="define_constraint", help="a level-set constraint at run time",
          family="constraints")
def _x_define_constraint(interp, node):
    define_constraint(interp.session, node[1])
