"""Element and quantity attributes: reading ``vv.x``, ``ee.length``,
``body[1].volume``, ``q.value`` (:func:`get_attr`), assigning them
(:func:`set_attr`) and the ``set``/``unset`` commands on generated elements
(:func:`set_elements`).  The extra attributes live in
:mod:`pyevolver.commands.attributes`.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import CommandError, ExpressionError, UnsupportedError, did_you_mean
from ..expr import nodes as N
from ..geometry import kernels
from ..model import records as MS
from ..constraints import project_to_constraints
from . import attributes as A
from . import constraints, elements
from .registry import register
from .columns import COORDS, column_values
from .values import _KIND, ElemRef, QRef, SessionLike, as_float, as_int

# the coordinates past the third (SPACE_DIMENSION > 3), by column
_HIGH_COORDS = {"w": 3, "x4": 3, "x5": 4, "x6": 5, "x7": 6, "x8": 7, "x9": 8}


#: The built-in attribute names of :func:`get_attr` (for "did you mean").
ATTRIBUTE_NAMES = (
    "area", "backbody", "backcolor", "color", "colour", "density", "edge_vector", "fixed",
    "frontbody", "frontcolor", "hit_constraint", "id", "length", "no_refine", "oid",
    "on_boundary", "on_constraint", "on_method_instance", "on_quantity", "orientation",
    "original", "p1", "p2", "pressure", "show", "target", "tension", "valence",
    "vertex_normal", "vertexnormal", "volconst", "volume", "x", "y", "z")


def get_attr(session: SessionLike, base, name, idx):
    """The value of ``base.name`` (``idx``: its index, a number or a tuple)."""
    if isinstance(base, A.ConstraintAt):
        return A.constraint_attr(session, base, name, idx)
    if name in ("on_quantity", "on_method_instance"):
        return A.on_quantity(session, base, name, idx)
    if idx is not None:                     # indices are integers (C truncation)
        idx = tuple(as_int(j, f"the index of '{name}'") for j in idx) \
            if isinstance(idx, tuple) else as_int(idx, f"the index of '{name}'")
    if isinstance(base, QRef):
        return _quantity_attr(session, base.name, name)
    if not isinstance(base, ElemRef):
        raise ExpressionError(f"'.{name}' needs an element or a quantity")
    s = session.surface
    t = session.totals
    k, i = base.kind, base.i
    elements.check_alive(session, base)
    if name in ("id", "oid"):
        eid = float(s.element_id(k, i)) if k in ("vertex", "edge", "facet") else float(i + 1)
        return eid if name == "id" else eid * base.sign
    if name == "original":
        arr = {"vertex": s.vattr, "edge": s.eattr, "facet": s.fattr}.get(k, {}).get("original")
        if k == "body":
            return float(s.bodies.original[i])
        return float(arr[i]) if arr is not None else 0.0     # 0: no original (REF)
    if (k, name) in s.extra:
        arr = s.extra[(k, name)]
        conv = int if session.attr_types.get((k, name)) == "integer" else float
        if arr.ndim == 1:
            return conv(arr[i])
        return conv(arr[(i,) + attr_pos(k, name, arr, idx)])
    if name == "show":          # the default show criteria (graphics are not drawn)
        if k == "facet":
            return 1.0
        if k == "edge":
            return float(bool(s.eattr["fixed"][i]) or
                         len(elements.sub_elements(session, base, "facet")) != 2)
    v = A.element_attr(session, base, name, idx)
    if v is not A.MISSING:
        return v
    if k in ("vertex", "edge", "facet") and _HIGH_COORDS.get(name, 0) >= s.sdim or \
            s.sdim == 2 and name in ("z", "x3") and k in ("vertex", "edge", "facet"):
        raise ExpressionError("Coordinate dimension exceeds space dimension.")  # REF 2475
    if name in _HIGH_COORDS and k in ("vertex", "edge"):     # x4 .. x9 (w = x4)
        j = _HIGH_COORDS[name]
        return float(s.X[i, j] if k == "vertex" else t.edge_vec[i, j] * base.sign)
    if k == "vertex":
        coords = {"x": 0, "y": 1, "z": 2, "x1": 0, "x2": 1, "x3": 2}
        if name == "x" and idx is not None:          # x[2] is y
            j = int(idx) if not isinstance(idx, tuple) else -1
            if j < 1 or j > s.sdim:
                raise ExpressionError(f"vertex x[{j}]: index outside 1..{s.sdim}")
            return float(s.X[i, j - 1])
        if name in coords:
            return float(s.X[i, coords[name]])
        if name == "__x" and idx is not None:
            return float(s.X[i, int(idx) - 1])
        if name == "__x":
            return N.array_value(s.X[i, :s.sdim])
        if name == "fixed":
            return float(s.vattr["fixed"][i])
        if name in ("on_constraint", "hit_constraint"):
            m = s.vcon.get(int(idx))
            return float(m[i]) if m is not None else 0.0
        if name == "on_boundary":
            b = s.vattr.get("boundary")
            return float(b is not None and b[i] == int(idx))
        if name == "valence":
            if s.simplex:           # REF: the number of facets at the vertex
                return float(np.count_nonzero((s.SF == i).any(axis=1)))
            return float(np.count_nonzero((s.E == i).any(axis=1)))
        if name in ("vertexnormal", "vertex_normal") and s.simplex:
            raise UnsupportedError(f"{name} in the simplex model")
        if name in ("vertexnormal", "vertex_normal"):
            if isinstance(idx, tuple):
                raise ExpressionError(f"vertex {name} is a vector; index it as {name}[i]")
            if s.nf == 0:
                raise UnsupportedError("vertex_normal in the string model")
            nrm = kernels.vertex_normals(s.F, t.facet_N2, s.nv, MS.vertex_facet_rank(s))[i]
            if idx is None:
                return N.array_value(nrm)
            j = int(idx)
            if j < 1 or j > s.sdim:
                raise ExpressionError(f"{name}[{j}]: index outside 1..{s.sdim}")
            return float(nrm[j - 1])
        if name in ("p1", "p2") and "params" in s.vattr:
            return float(s.vattr["params"][i, int(name[1]) - 1])
    elif k == "edge":
        if name == "length":
            return float(t.edge_length[i])
        if name in ("x", "y", "z"):
            return float(t.edge_vec[i, "xyz".index(name)] * base.sign)
        if name == "edge_vector":
            if idx is None:
                return N.array_value(t.edge_vec[i, :s.sdim] * base.sign)
            if isinstance(idx, tuple):
                raise ExpressionError("edge_vector takes one index")
            j = int(idx)
            if j < 1 or j > s.sdim:
                raise ExpressionError(f"edge_vector[{j}]: index outside 1..{s.sdim}")
            return float(t.edge_vec[i, j - 1] * base.sign)
        if name in ("tension", "density"):
            return float(s.edge_tension[i])
        if name == "fixed":
            return float(s.eattr["fixed"][i])
        if name == "no_refine":
            return float(s.eattr["no_refine"][i])
        if name in ("on_constraint", "hit_constraint"):
            m = s.econ.get(int(idx))
            return float(m[i] != 0) if m is not None else 0.0
        if name == "on_boundary":
            b = s.eattr.get("boundary")
            return float(b is not None and b[i] == int(idx))
        if name == "valence":
            return float(len(elements.sub_elements(session, base, "facet")))
        if name == "orientation":
            return float(base.sign)
        if name in ("color", "colour"):
            c = s.eattr.get("color")
            return float(c[i]) if c is not None else 0.0
    elif k == "facet":
        if name == "area":
            return float((t.sfacet_area if s.string else t.facet_area)[i])
        if s.simplex and name in ("x", "y", "z", "valence"):
            if name == "valence":
                return 0.0          # REF
            raise CommandError("Internal error: Trying to take normal in simplex model.")
        if s.string and name in ("x", "y", "z", "valence"):
            if name == "valence":
                return float(s.sf_ptr[i + 1] - s.sf_ptr[i])
            raise UnsupportedError(f"facet normal ({name}) in the string model")
        if name in ("x", "y", "z"):
            j = "xyz".index(name)
            if s.periods is None and s.sdim == 3:
                # the Evolver's order of operations: (side 1) x (side 2), so
                # signed zeros come out as in its exporters' output
                a, b, c = s.X[s.F[i]]
                return float(0.5 * np.cross(b - a, c - b)[j] * base.sign)
            return float(0.5 * t.facet_N2[i, j] * base.sign)
        if name in ("tension", "density"):
            return float(s.facet_tension[i])
        if name == "fixed":
            return float(s.fattr["fixed"][i])
        if name in ("on_constraint", "hit_constraint"):
            m = s.fcon.get(int(idx))
            return float(m[i]) if m is not None else 0.0
        if name in ("color", "colour", "frontcolor", "backcolor"):
            key = name.replace("colour", "color")
            c = s.fattr.get("backcolor" if key == "backcolor" else "frontcolor")
            if c is None:
                c = s.fattr.get("color")
            return float(c[i]) if c is not None else 15.0     # white (REF default)
        if name == "valence":
            return 3.0
        if name in ("frontbody", "backbody"):
            # the body the facet bounds positively (front) or negatively
            col = s.bodies.facet_matrix[:, i].tocoo()
            want = 1 if name == "frontbody" else -1
            hit = [int(b) + 1 for b, v in zip(col.row, col.data) if np.sign(v) == want]
            return float(hit[0]) if hit else 0.0
    elif k == "body":
        b = s.bodies
        if name == "volume":
            return float(t.volumes[i])
        if name == "target":
            return float(b.target[i]) if not math.isnan(b.target[i]) else \
                A.unset_value(session, i, "target", 0.0)
        if name == "volconst":
            return float(b.volconst[i])
        if name == "pressure":
            if not math.isnan(b.pressure[i]):
                return float(b.pressure[i])
            return A.unset_value(session, i, "pressure", float(b.lagrange[i]))
        if name == "density":
            return float(b.density[i])
        if name == "fixed":
            return float(not math.isnan(b.target[i]))
    if name in _KIND and idx is not None:       # ff.edge[2], ee.vertex[1]
        kind = _KIND[name]
        if kind == "facetedge":
            raise UnsupportedError("facetedge elements")
        subs = elements.sub_elements(session, base, kind)
        j = int(idx)
        if j < 1 or j > len(subs):
            eid = s.element_id(k, i) if k in ("vertex", "edge", "facet") else i + 1
            raise ExpressionError(f"{base}.{kind}[{j}] does not exist ({k} {eid} has "
                                  f"{len(subs)} {kind}{'s' if len(subs) != 1 else ''})")
        return subs[j - 1]
    if name in s.quantities and k in ("vertex", "edge", "facet"):
        return A.element_quantity_value(session, base, name)
    known = list(ATTRIBUTE_NAMES) + list(_KIND) + list(s.quantities) + [
        a for (kk, a) in s.extra if kk == k]
    raise ExpressionError(f"{k} has no attribute '{name}'" + did_you_mean(name, known))


def attr_pos(k, name, arr, idx):
    """0-based position inside an array attribute from 1-based indices."""
    if idx is None:
        raise ExpressionError(f"{k} attribute '{name}' is an array; index it as "
                              f"{name}[i]")
    idx = idx if isinstance(idx, tuple) else (idx,)
    if len(idx) != arr.ndim - 1:
        raise ExpressionError(f"{k} attribute '{name}' needs {arr.ndim - 1} "
                              f"ind{'ices' if arr.ndim > 2 else 'ex'}, got {len(idx)}")
    pos = []
    for j, n in zip(idx, arr.shape[1:]):
        if isinstance(j, str) or int(j) < 1 or int(j) > n:
            raise ExpressionError(f"{k} attribute {name}[{j}]: index outside 1..{n}")
        pos.append(int(j) - 1)
    return tuple(pos)


def _quantity_attr(session: SessionLike, qname, name):
    q = session.surface.quantities[qname]
    if q.kind == "instance" and name not in ("value", "modulus"):
        raise ExpressionError(f"method instance {qname} has no attribute '{name}' "
                              f"(possible method instance attributes: value, modulus)")
    if name == "value":
        return float(session.totals.quantity_values[qname])
    if name == "target":
        return float(q.target)
    if name == "modulus":
        return float(q.modulus)
    if name == "pressure":
        return float(q.pressure)
    if name == "tolerance":
        return float(q.tolerance)
    return A.quantity_attr(session, q, name)


def set_attr(session: SessionLike, base, name, idx, value):
    """Assign ``base.name[idx] := value``."""
    if idx is not None:
        idx = tuple(as_int(j, f"the index of '{name}'") for j in idx) \
            if isinstance(idx, tuple) else as_int(idx, f"the index of '{name}'")
    if isinstance(value, str):
        raise CommandError(f"cannot assign a string to '.{name}'")
    s = session.surface
    if isinstance(value, N.ArrayValue):
        key = (getattr(base, "kind", None), name)
        arr = s.extra.get(key)
        if arr is None or idx is not None or arr.shape[1:] != value.shape:
            raise CommandError(f"cannot assign an array of shape {list(value.shape)} to "
                               f"'.{name}'")
        arr[base.i] = np.asarray(value)
        return
    value = as_float(value, f"the value of '.{name}'")
    if isinstance(base, QRef):
        q = s.quantities[base.name]
        if name in ("target", "modulus", "tolerance"):
            setattr(q, name, value)
            return
        raise CommandError(f"quantity attribute '{name}' is read-only")
    if not isinstance(base, ElemRef):
        raise CommandError(f"'.{name}' needs an element or a quantity")
    elements.check_alive(session, base)
    k, i = base.kind, base.i
    if (k, name) not in s.extra and A.set_element_attr(session, base, name, idx, value):
        return
    if (k, name) in s.extra:
        arr = s.extra[(k, name)]
        if session.attr_types.get((k, name)) == "integer":
            value = float(int(value))            # C conversion truncates
        if arr.ndim == 1:
            arr[i] = value
        elif idx is None:
            arr[i] = value                  # every entry (REF: set vertex vec 0)
        else:
            arr[(i,) + attr_pos(k, name, arr, idx)] = value
        return
    if k == "vertex" and name in ("x", "y", "z", "x1", "x2", "x3", *_HIGH_COORDS):
        j = {"x": 0, "y": 1, "z": 2, "x1": 0, "x2": 1, "x3": 2, **_HIGH_COORDS}[name]
        if j >= s.sdim and j >= 3:
            raise CommandError("Coordinate dimension exceeds space dimension.")
        if name == "x" and idx is not None:
            j = int(idx) - 1 if not isinstance(idx, tuple) else -1
            if j < 0 or j >= s.sdim:
                raise CommandError(f"vertex x[{j + 1}]: index outside 1..{s.sdim}")
        if not math.isfinite(value):
            raise CommandError(f"vertex coordinates must be finite numbers, got {value:g}")
        s.X[i, j] = value
        A.cache(session).touch(session)           # attributes read the live coordinates
        return
    if k == "body":
        b = s.bodies
        if name == "target":
            b.target[i] = value
            b.pressure[i] = np.nan
            return
        if name == "volconst":
            b.volconst[i] = value
            return
        if name == "pressure":
            b.pressure[i] = value
            b.target[i] = np.nan
            return
        if name == "density":
            b.density[i] = value
            if value:           # REF: a body density switches gravity on
                session.toggles["gravity"] = 1
            return
    if k == "facet" and name in ("tension", "density"):
        s.fattr["tension"][i] = value
        return
    if k in ("edge", "facet") and name in ("color", "colour", "frontcolor", "backcolor"):
        attrs, n = (s.eattr, s.ne) if k == "edge" else (s.fattr, elements.count(session, k))
        name = name.replace("colour", "color")
        default = 0 if k == "edge" else 15
        value = as_int(value, f"a {name}")
        if abs(value) > 2**31 - 1:
            raise CommandError(f"{name} {value} is out of range")
        if "color" not in attrs:
            attrs["color"] = np.full(n, default, np.int64)
        if name == "color":
            for key in ("color", "frontcolor", "backcolor"):
                if key in attrs:
                    attrs[key][i] = int(value)
        elif name == "frontcolor":
            if k == "facet" and "backcolor" not in attrs:    # the back keeps its colour
                attrs["backcolor"] = attrs["color"].copy()
            for key in ("color", "frontcolor"):
                if key in attrs:
                    attrs[key][i] = int(value)
        else:
            if name not in attrs:
                attrs[name] = attrs["color"].copy()
            attrs[name][i] = int(value)
        return
    if k in ("vertex", "edge", "facet") and name in ("fixed", "no_refine"):
        attrs = {"vertex": s.vattr, "edge": s.eattr, "facet": s.fattr}[k]
        if name not in attrs:
            attrs[name] = np.zeros(elements.count(session, k), bool)
        attrs[name][i] = bool(value)
        return
    if k == "edge" and name in ("tension", "density"):
        s.eattr.setdefault("tension", np.zeros(s.ne))[i] = value
        return
    raise CommandError(f"cannot assign to {k} attribute '{name}'")


def set_elements(session: SessionLike, gen, attr, expr, env, unset, idx=None):
    """``set gen attr expr`` / ``unset gen attr``: every value computed first, then assigned."""
    els = elements.generate(session, gen, env)
    # a foreach variable (set vv gbend) has its kind only at run time
    kind = gen.kind if gen.kind is not None or not els else els[0].kind
    qname = A.membership_name(session, kind, attr, expr)
    if qname is not None:
        A.set_membership(session, kind, els, qname, not unset)
        return
    if A.is_flag(gen.kind, attr) and (expr is None or unset):
        for el in els:         # boolean attributes: set = 1, unset = 0
            set_attr(session, el, attr, None, 0.0 if unset else 1.0)
        return
    if attr in ("fixed", "no_refine") and (expr is None or unset):
        if gen.kind == "body":
            raise CommandError(f"bodies cannot be {'un' if unset else ''}set {attr}; "
                               f"use 'set body target expr' / 'unset body target'")
        for el in els:
            set_attr(session, el, attr, None, 0.0 if unset else 1.0)
        return
    if unset:
        if attr == "boundary" and expr is not None:
            A.unset_boundary(session, els, session.interp.value(expr))
            return
        if attr in ("constraint",) and expr is not None:
            constraints.unset_constraint(session, els, int(session.interp.value(expr)))
            return
        if attr == "density" and gen.kind == "body":
            return      # REF: neither the printed density nor the energy changes
        if attr in ("target", "pressure") and gen.kind == "body":
            b = session.surface.bodies
            arr = getattr(b, attr)
            for el in els:      # REF still prints the old value (volfixed 0)
                A.remember_unset(session, el.i, attr, arr[el.i])
                arr[el.i] = np.nan
            return
        if (gen.kind, attr) in session.surface.extra:
            for el in els:
                set_attr(session, el, attr, None, 0.0)
            return
        raise UnsupportedError(f"unset {gen.kind} {attr}")
    if expr is None:
        raise UnsupportedError(f"set {gen.kind} {attr} (without a value)")
    if attr == "constraint":
        constraints.set_constraint(session, els, session.interp.value(expr))
        A.cache(session).touch(session)           # projected vertices moved
        return
    # compute every value first, then assign (like the Evolver's set)
    if idx is None and attr in COORDS and ("vertex", attr) not in session.surface.extra:
        col = column_values(session, gen, els, expr, env)     # (plain arithmetic at once)
        if col is not None:
            ii, vals = col
            set_attr(session, els[0], attr, None, float(vals[0]))   # (its checks, once)
            session.surface.X[ii, COORDS[attr]] = vals
            project_or_fail(session, session.surface, ii)
            A.cache(session).touch(session)
            return
    vals = []
    ix = None if idx is None else session.interp.value(idx)
    for el in els:
        session.interp.tick()
        with env.element(el, gen.var):
            vals.append(session.interp.value(expr))
    for el, v in zip(els, vals):
        set_attr(session, el, attr, ix, v)
    if gen.kind == "vertex" and attr in ("x", "y", "z"):
        project_or_fail(session, session.surface, np.array([e.i for e in els], np.int64))
        A.cache(session).touch(session)


def project_or_fail(session: SessionLike, surface, idx):
    """Project vertices to their constraints; a projection that diverges
    fails the command (which leaves the surface as it was)."""
    bad = project_to_constraints(surface, idx)
    if len(bad):
        vid = surface.ids("vertex")[bad[0]]
        raise CommandError(f"the projection of vertex {vid} onto its constraints "
                           f"diverges")


# -- the set and unset commands -------------------------------------------------------
def _quantity_gen(interp, gen):
    """The quantity or method instance a ``set``/``unset`` names, if any."""
    s = interp.session.surface
    if gen.base[0] == "var" and s is not None and gen.base[1] in s.quantities \
            and interp.var_elem(gen.base[1]) is None:
        return gen.base[1]
    return None


@register("set", usage="set gen attr value [where ...] | set NAME attr value",
          statement="set", help="assign an attribute of elements or a quantity",
          family="element_attrs")
def _x_set(interp, node):
    idx = node[4] if len(node) > 4 else None
    if node[1].base == ("var", "quantity") and interp.var_elem("quantity") is None:
        raise CommandError("set quantity NAME ...: write set NAME target value (the "
                           "Evolver reads 'set quantity' as a syntax error)")
    qname = _quantity_gen(interp, node[1])
    if qname is not None:
        if node[1].where is not None or node[1].var is not None or idx is not None:
            raise CommandError(f"set {qname}: expected set {qname} attribute [value]")
        value = None if node[3] is None else interp.value(node[3])
        A.set_quantity(interp.session, qname, node[2], value)
        return
    set_elements(interp.session, node[1], node[2], node[3], interp.env, unset=False, idx=idx)


@register("unset", usage="unset gen attr [value]", statement="unset",
          help="clear an attribute of elements", family="element_attrs")
def _x_unset(interp, node):
    qname = _quantity_gen(interp, node[1])
    if qname is not None:
        raise CommandError(f"unset {qname}: a quantity is not an element (REF: syntax "
                           f"error); use unfix {qname} or set {qname} info_only")
    set_elements(interp.session, node[1], node[2], node[3], interp.env, unset=True)
