"""Element attributes of the manual's list that the session's basic table
(:meth:`pyevolver.session.core.Session.get_attr`) does not hold: geometric ones
computed on whole arrays (:mod:`pyevolver.geometry.attributes`), graphics-only
ones (kept, without effect), and the internal ones refused by name.

:func:`element_attr` returns :data:`MISSING` for names it does not know;
:data:`ATTRIBUTES` lists what is supported and refused, for
docs/supported.md.
"""
from __future__ import annotations

import numpy as np

from ..methods import attributes as GA
from ..errors import ExpressionError, UnsupportedError
from ..expr import nodes as N
from ..methods import method_info
from ..methods import string_curvature as SC
from ..model.string import facets_of_edge
from ..constraints import boundary_eval
from . import elements
from .values import ElemRef, QRef, as_float, as_int

MISSING = object()

# graphics-only attributes: read-write, no number depends on them; values set
# at run time are kept per element (element index), the defaults otherwise
GRAPHICS = {
    ("facet", "opacity"): 1.0,
    ("facet", "no_display"): 0.0,
    ("facet", "nodisplay"): 0.0,
    ("facet", "no_transform"): 0.0,
    ("edge", "no_transform"): 0.0,
    ("body", "centerofmass"): 1.0,
}
_GRAPHICS_ALIAS = {"nodisplay": "no_display"}

# read-write flags that change numbers elsewhere in the Evolver: read as
# their default (pyevolver never sets them), setting them is refused by name
FLAGS_DEFAULT = {
    ("vertex", "mid_edge"): 0.0, ("vertex", "mid_facet"): 0.0,
    ("vertex", "axial_point"): 0.0, ("vertex", "triple_point"): 0.0,
    ("vertex", "tetra_point"): 0.0, ("vertex", "no_hessian_normal"): 0.0,
    ("edge", "noncontent"): 0.0, ("facet", "noncontent"): 0.0,
    ("facet", "orientation"): 1.0,
    ("facet", "phase"): 0.0, ("body", "phase"): 0.0,
}
SET_REFUSED = {
    "axial_point": "symmetry groups are not supported",
    "triple_point": "it changes effective_area motion, which pyevolver does not run",
    "tetra_point": "it changes effective_area motion, which pyevolver does not run",
    "no_hessian_normal": "per-vertex exemptions from hessian_normal",
    "noncontent": "elements left out of volumes",
    "orientation": "reversed signs of oriented integrals",
    "phase": "phasefiles are not supported",
    "mid_edge": "read-only", "mid_facet": "read-only",
    "frontbody": "changing a body's facets at run time",
    "backbody": "changing a body's facets at run time",
    "wrap": "changing torus wraps by hand",
}

# internal lists of the Evolver's data structure: refused by name
INTERNAL = {
    "v_method_list",
    "e_method_list", "f_method_list", "f_body_list", "f_next_bfacet", "f_next_vfacet",
    "raw_velocity", "v_boundary", "e_boundary", "f_boundary", "wrap_list",
}

READ_ONLY = {"mean_curvature", "sqcurve", "v_force", "v_oldx", "v_velocity", "dihedral",
             "volfixed", "valence", "facet_normal", "value_of_constraint"}

# documentation table: (kinds, name, status)
ATTRIBUTES = [
    ("vertex", "mean_curvature", "supported: 3 F·N/(2 N·N), F the area gradient and N the "
     "area-vector sum of the star, both projected onto the vertex's level-set constraints "
     "(not onto parametric boundaries), FIXED vertices included (REF's values, the torus "
     "model too; the manual's text, the area gradient over a third of the star area, is "
     "not what REF computes)"),
    ("vertex", "sqcurve", "supported: h² of `sq_mean_curvature` (of "
     "`eff_area_sq_mean_curvature` with `effective_area` on, of `normal_sq_mean_curvature` "
     "with `normal_curvature` on), 0 at FIXED and boundary vertices, as REF"),
    ("vertex", "mean_curvature (string model)", "supported: F·N/(N·N), F the difference of "
     "the unit vectors of the edge going out and the edge coming in, N half the xy "
     "rotation of the chord from the previous to the next vertex, the sign of the first "
     "edge of REF's vertex ring (REF's values, tension-free); 0 at ends"),
    ("vertex", "sqcurve (string model)", "0 without facets (REF's value, also after g); "
     "refused by name on strings with facets (REF prints numbers not reproduced)"),
    ("vertex", "dihedral", "string model: 2 asin(F/2), F the length of the sum of the unit "
     "edge vectors, clamped to π (REF); soapfilm model: REF's error \"Dihedral only for "
     "edges\""),
    ("edge", "dihedral", "supported: angle between the two facets' normals, 0 unless "
     "exactly two facets (REF's error in the string model); coplanar facets give 0 where "
     "REF's round-off gives up to 3e-8"),
    ("vertex", "value_of_constraint n", "supported: the constraint's formula at the vertex"),
    ("vertex", "hit_constraint n", "supported: on the constraint and, for a one-sided "
     "(NONNEGATIVE / NONPOSITIVE) constraint, at its boundary within "
     "`constraint_tolerance` (REF: 0 after `set vertex z 0.1` off the plane)"),
    ("vertex", "constraint[n].normal", "supported: the constraint's unit normal at the "
     "vertex (vector, or one component with [i])"),
    ("vertex", "p1, p2, p[i], p", "read and set: setting moves the vertex on its boundary "
     "at once "
     "(REF); `set vertex boundary n` refused by name, `unset vertex/edge/facet boundary n` "
     "supported"),
    ("facet", "facet_normal, x, y, z, x1..x3, x[i]", "supported (length = facet area)"),
    ("edge", "edge_vector, x, y, z, x1..x3, x[i]", "supported"),
    ("edge, facet", "length, area", "supported, from the live coordinates (a `set` of "
     "coordinates earlier in the same command counts, as in REF)"),
    ("edge", "wrap", "supported (REF's torus code, a 6-bit field per period: +x 1, -x 31, "
     "+y 64, -y 1984, +z 4096, -z 126976; the manual says 127040 for -z, REF prints "
     "126976)"),
    ("body", "volfixed", "supported; after `unset body target` (or `pressure`) the body "
     "still prints its old target (pressure), as REF"),
    ("vertex, edge, facet", "on_quantity q, on_method_instance m", "supported (global "
     "methods mark no elements, as REF)"),
    ("vertex, edge, facet", "named quantity or method instance as attribute (`ff.qname`)",
     "supported: the element's contribution (0 on elements the quantity does not cover); "
     "FUNCTION quantities refused by name"),
    ("vertex, edge, facet", "set gen quantity q, set gen method_instance m, set gen q, "
     "unset gen q", "supported: the elements join or leave the non-global methods of that "
     "element kind (global ones unchanged, as REF); REF's WARNING 1569 per element when the "
     "quantity has no method for that kind"),
    ("quantity", "value, target, modulus, pressure, tolerance, fixed, energy, info_only, "
     "conserved", "supported; `target`, `modulus`, `tolerance` assignable (`q.target := 2`, "
     "`set q target 2`), `set q fixed` (`energy`, `info_only`, `conserved`); `volconst` reads 0, "
     "setting it is refused by name; `parameter_1`, `element_modulus` refused by name"),
    ("method instance", "value, modulus", "supported (`set inst modulus 2`); other "
     "attributes rejected as REF"),
    ("facet, edge, body", "opacity, no_display / nodisplay, no_transform, centerofmass",
     "graphics only: read and set, no effect"),
    ("vertex, edge, facet, body", "mid_edge, mid_facet, axial_point, triple_point, "
     "tetra_point, no_hessian_normal, noncontent, orientation (facet), phase",
     "read as their defaults (0; orientation 1); setting another value refused by name "
     "(they change numbers: effective_area, hessian_normal, volumes, phases)"),
    ("vertex, edge", "bare", "read and set (bare on datafile lines is not kept by the "
     "datafile reader: it reads 0)"),
    ("vertex", "v_force, v_velocity, v_oldx", "supported: the force (minus the energy "
     "gradient, FIXED vertices included, not projected onto constraints), the motion "
     "direction (projected, after conjugate gradients) and the coordinates of the moving "
     "vertices (0 for FIXED ones) of the last `g` step; zeros before any, as REF"),
    ("vertex, edge, facet", "v_constraint_list, e_constraint_list, f_constraint_list",
     "supported as REF prints them: count, then the constraint numbers (a vertex's with bit "
     "31 set where it hits the constraint, so scripts mask with `imod 0x100000`), zero-padded "
     "to 4 entries; empty when no element of the kind is on a constraint"),
    ("vertex, edge, facet", "v_/e_/f_method_list, f_body_list, f_next_bfacet, wrap_list, "
     "raw_velocity", "refused by name (the Evolver's internal data structure)"),
    ("edge", "midv", "the midpoint's id in the quadratic model; REF's error in the linear one"),
    ("edge", "frontbody, backbody", "string model: the bodies of the facets along and "
     "against the edge; soapfilm model: REF's error"),
    ("facet, edge", "set frontbody / backbody / wrap, unset frontbody / backbody / bodies",
     "refused by name (changing bodies' facets or torus wraps at run time)"),
    ("facet", "bare", "REF's error: no bareness for facets or bodies"),
]


# attributes of one kind of element: REF's messages for the others
_ONLY = {
    "area": (("facet",), "Area only for facets."),
    "length": (("edge",), "Length only for edges."),
    "volume": (("body",), "Volume only for bodies."),
    "sqcurve": (("vertex",), "Square mean curvature only for vertices."),
    "mean_curvature": (("vertex",), "Mean_curvature only for vertices."),
    "facet_normal": (("facet",), "\"facet_normal\" is a facet attribute."),
    "edge_vector": (("edge",), "\"edge_vector\" is an edge attribute."),
    "volfixed": (("body",), "\"volfixed\" is a body attribute."),
    "value_of_constraint": (("vertex",), "\"value_of_constraint\" is a vertex attribute."),
}


def _session_store(session):
    st = session.__dict__.get("_attr_store")
    if st is None:
        st = session._attr_store = {}
    return st


def cache(session):
    """The session's :class:`~pyevolver.geometry.attributes.AttrCache`."""
    c = session.__dict__.get("_attr_cache")
    if c is None:
        c = session._attr_cache = GA.AttrCache()
    return c


def geometry(session):
    """Totals of the live coordinates (see :class:`AttrCache`)."""
    return cache(session).geometry(session)


def _vector_attr(vec, name, idx, whole, s):
    """An edge's or facet's vector attribute: ``whole`` (or ``x[i]``) the
    vector or its entry ``idx``; ``x``/``y``/``z``/``x1``... one coordinate."""
    if name == whole or (name == "x" and idx is not None):
        return _component(vec, idx, name)
    return _component(vec, _coord_index(name, s), name)


def _component(vec, idx, name):
    if idx is None:
        if np.issubdtype(np.asarray(vec).dtype, np.integer):    # printed with %d
            return np.asarray(vec, np.int64).view(N.ArrayValue)
        return N.array_value(np.asarray(vec, float))
    if isinstance(idx, tuple):
        raise ExpressionError(f"{name} takes one index")
    j = int(idx)
    if j < 1 or j > len(vec):
        raise ExpressionError(f"{name}[{j}]: index outside 1..{len(vec)}")
    return float(vec[j - 1])


def _constraint_id(session, idx, what):
    s = session.surface
    if idx is None or isinstance(idx, tuple):
        raise ExpressionError(f"{what} needs a constraint number or name "
                              f"(for example: vv.{what} 1)")
    cid = int(idx)
    if cid not in s.constraints:
        raise ExpressionError(f"{what}: constraint {cid} is not defined")
    return cid


def constraint_value(session, i, cid):
    """Value of constraint ``cid``'s formula at vertex ``i``."""
    s = session.surface
    c = s.constraints[cid]
    P = s.X[i:i + 1]
    coords = N.coord_dict(P)          # x y z (w x5 .. in SPACE_DIMENSION > 3)
    return float(np.asarray(c.formula.values(s.param_env(), coords, 1)).ravel()[0])


def constraint_normal(session, i, cid):
    """Unit normal (3,) of constraint ``cid`` at vertex ``i``."""
    s = session.surface
    c = s.constraints[cid]
    P = s.X[i:i + 1]
    coords = N.coord_dict(P)
    g = np.asarray(c.formula.gradient(s.param_env(), coords, 1, N.coord_names(P.shape[1])),
                   float).reshape(-1)[:s.sdim]
    n = np.linalg.norm(g)
    return g / n if n > 0 else g


def element_attr(session, base, name, idx):
    """Value of attribute ``name`` of element ``base`` (an ElemRef), or
    :data:`MISSING` when the name is not one of this module's."""
    s = session.surface
    k, i = base.kind, base.i
    if name in INTERNAL:
        raise UnsupportedError(f"the internal attribute {name}",
                               "the Evolver's own data structure")
    if name in _CONSTRAINT_LISTS:
        if k != _CONSTRAINT_LISTS[name]:
            raise ExpressionError(f"\"{name}\" is a {_CONSTRAINT_LISTS[name]} attribute, "
                                  f"not {k}.")
        return _component(constraint_list(session, k, i), idx, name)
    if (k, name) in GRAPHICS:
        key = (k, _GRAPHICS_ALIAS.get(name, name))
        return float(_session_store(session).get(key, {}).get(i, GRAPHICS[(k, name)]))
    if (k, name) == ("vertex", "mid_edge") and s.order == 2:
        return float(i >= s.nv - s.ne)           # the midpoints are the last ne vertices
    if k == "vertex" and name == "axial_point" and name in s.vattr:   # model.groups
        return float(s.vattr[name][i])
    if (k, name) in FLAGS_DEFAULT:
        return FLAGS_DEFAULT[(k, name)]
    only = _ONLY.get(name)
    if only is not None and k not in only[0] and (k, name) not in s.extra:
        raise ExpressionError(only[1])
    if name == "bare":
        if k in ("facet", "body"):
            raise ExpressionError("No bareness for facets or bodies.")
        return float(_session_store(session).get((k, "bare"), {}).get(i, 0.0))
    if k == "vertex":
        if name in ("v_force", "v_oldx", "v_velocity"):
            last = session.__dict__.get("_last_motion")      # set by Iterator.step
            slot = {"v_force": 1, "v_oldx": 2, "v_velocity": 3}[name]
            if last is None or last[0] is not s or len(last) <= slot or \
                    len(last[slot]) != s.nv:
                vec = np.zeros(s.sdim)          # REF: zeros before any g
            else:
                vec = last[slot][i, :s.sdim] + 0.0
            if isinstance(idx, tuple):
                raise ExpressionError(f"{name} takes one index")
            return _component(vec, idx, name)
        if name == "mean_curvature":
            fn = SC.string_mean_curvature if s.string else GA.vertex_mean_curvature
            return float(cache(session).get(session, name, fn)[i])
        if name == "sqcurve":
            if s.string and len(s.sf_ptr) <= 1:
                return 0.0              # REF: 0 on strings without facets (knotty.fe)
            _no_string(s, name)
            tg = session.toggles
            mode = ("norm" if tg.get("normal_curvature") else
                    "eff" if tg.get("effective_area") else "plain")
            arr = cache(session).get(session, f"sqcurve_{mode}",
                                     lambda ss, tt: GA.vertex_sqcurve(ss, tt, mode))
            return float(arr[i])
        if name == "dihedral":
            if not s.string:
                raise ExpressionError("Dihedral only for edges.")
            return float(cache(session).get(session, "vdihedral",
                                            GA.string_vertex_dihedral)[i])
        if name == "p":                 # the boundary parameters as an array
            bnd = s.vattr.get("boundary")
            if bnd is None or not bnd[i]:       # REF: as many zeros as the widest boundary
                par = s.vattr.get("params")
                vec = np.zeros(0 if par is None else par.shape[1])
            else:
                vec = s.vattr["params"][i, :s.boundaries[int(bnd[i])].nparams]
            return _component(vec, idx, name)
        if name == "hit_constraint" and idx is not None:
            cid = _constraint_id(session, idx, name)
            on = s.vcon.get(cid)
            if on is None or not on[i]:
                return 0.0
            flags = s.constraints[cid].flags
            if "nonnegative" not in flags and "nonpositive" not in flags:
                return 1.0
            # a one-sided constraint is hit where the vertex is on its boundary
            tol = float(session.settings.get("constraint_tolerance", 1e-12))
            return float(abs(constraint_value(session, i, cid)) <= tol)
        if name == "value_of_constraint":
            return constraint_value(session, i, _constraint_id(session, idx, name))
        if name == "constraint" and idx is not None:
            return ConstraintAt(i, _constraint_id(session, idx, "constraint[n]"))
    elif k == "edge":
        if name == "dihedral":
            if s.string:
                raise ExpressionError("Dihedral only for vertices.")
            return float(cache(session).get(session, "edihedral", GA.edge_dihedral)[i])
        if name in ("x", "y", "z", "x1", "x2", "x3", "edge_vector"):
            return _vector_attr(geometry(session).edge_vec[i, :s.sdim] * base.sign, name, idx,
                                "edge_vector", s)
        if name == "length":
            return float(geometry(session).edge_length[i])
        if name == "midv":
            if s.order != 2:
                raise ExpressionError("Cannot do MIDV except in QUADRATIC model.")
            return float(s.ids("vertex")[s.midv[i]])
        if name in ("frontbody", "backbody"):
            if not s.string:
                raise ExpressionError("Frontbody or backbody only for facets, or string "
                                      "model edges.")
            return float(_string_edge_body(session, base, name))
        if name == "wrap":
            return float(_torus_wrap(s, i))
    elif k == "facet":
        if s.string:
            return MISSING
        if name in ("x", "y", "z", "x1", "x2", "x3", "facet_normal"):
            return _vector_attr(_facet_normal(session, i) * base.sign, name, idx,
                                "facet_normal", s)
        if name == "area":
            return float(geometry(session).facet_area[i])
        if name == "no_refine":
            nr = s.fattr.get("no_refine")
            return float(bool(nr[i])) if nr is not None else 0.0
    elif k == "body":
        if name == "volfixed":
            return float(not np.isnan(s.bodies.target[i]))
        if name in ("actual_volume",):
            raise ExpressionError(f"\"{name}\" is not an attribute name (it is read from "
                                  f"the datafile only)")
    return MISSING


_CONSTRAINT_LISTS = {"v_constraint_list": "vertex", "e_constraint_list": "edge",
                     "f_constraint_list": "facet"}


def constraint_list(session, kind, i):
    """REF's ``v_constraint_list`` (``e_``, ``f_``): the number of
    constraints, then their numbers (a vertex's with bit 31 set where it hits
    the constraint, read as a signed 32-bit integer, so ``imod 0x100000``
    gives the number back), zero-padded to at least 4 entries; empty when no
    element of the kind is on a constraint."""
    s = session.surface
    masks = {"vertex": s.vcon, "edge": s.econ, "facet": s.fcon}[kind] or {}
    if not any(np.any(m) for m in masks.values()):
        return np.zeros(0, np.int64)
    cids = [c for c in sorted(masks) if masks[c][i]]
    out = [len(cids)]
    for c in cids:
        v = int(c)
        if kind == "vertex" and element_attr(session, _Ref(kind, i), "hit_constraint", c):
            v -= 2 ** 31                    # (c | 0x80000000) as a signed int
        out.append(v)
    return np.array(out + [0] * (4 - len(out)), np.int64)


class _Ref:
    """A plain element reference (kind, index) for internal attribute reads."""

    __slots__ = ("kind", "i", "sign")

    def __init__(self, kind, i):
        self.kind = kind
        self.i = i
        self.sign = 1


def _string_edge_body(session, base, name):
    """String model: the body of the facet running along the edge
    (``frontbody``) or against it (``backbody``); 0 when there is none."""
    s = session.surface
    want = (1 if name == "frontbody" else -1) * base.sign
    for f, g in facets_of_edge(s, base.i):
        if g == want:
            col = s.bodies.facet_matrix[:, f].tocoo()
            if len(col.row):
                return int(col.row[0]) + 1
    return 0


def _no_string(s, name):
    if s.string:
        raise UnsupportedError(f"vertex {name} in the string model")


def _coord_index(name, s):
    j = {"x": 1, "y": 2, "z": 3, "x1": 1, "x2": 2, "x3": 3}[name]
    if j > s.sdim:
        raise ExpressionError("Coordinate dimension exceeds space dimension.")
    return j


def _facet_normal(session, i):
    s = session.surface
    if s.periods is None and s.sdim == 3:
        a, b, c = s.X[s.F[i]]                  # (side 1) x (side 2), REF's order
        return 0.5 * np.cross(b - a, c - b)
    return 0.5 * geometry(session).facet_N2[i, :s.sdim]


def _torus_wrap(s, i):
    """The Evolver's torus wrap code of edge ``i``: per period a 6-bit field
    holding the wrap mod 32 (+x 1, -x 31, +y 64, -y 1984, +z 4096,
    -z 126976; the manual's 127040 for -z is not what REF prints)."""
    if "wrap_code" in s.eattr:                  # the other groups' codes (model.groups)
        return int(s.eattr["wrap_code"][i])
    w = s.eattr.get("wrap")
    if w is None or s.periods is None:
        return 0
    row = np.asarray(w[i]).ravel()
    return sum((int(v) & 31) << (6 * d) for d, v in enumerate(row[:3]))


def set_element_attr(session, base, name, idx, value):
    """Assign a graphics-only attribute or ``bare``; refuse the flags that
    would change numbers.  Returns True when handled."""
    k, i = base.kind, base.i
    if (k, name) in GRAPHICS:
        key = (k, _GRAPHICS_ALIAS.get(name, name))
        _session_store(session).setdefault(key, {})[i] = float(value)
        return True
    if k == "vertex" and name in ("p1", "p2", "p3", "p4") or (k == "vertex" and name == "p"
                                                            and idx is not None):
        return _set_parameter(session, i, name, idx, value)
    if name == "boundary":
        raise UnsupportedError(f"set {k} boundary", "putting elements on a parametric "
                               "boundary at run time")
    if name == "bare" and k in ("vertex", "edge"):
        _session_store(session).setdefault((k, "bare"), {})[i] = float(bool(value))
        return True
    if name in SET_REFUSED:
        if float(value) == FLAGS_DEFAULT.get((k, name), np.nan):
            return True                           # setting the default changes nothing
        raise UnsupportedError(f"set {k} {name}", SET_REFUSED[name])
    if name in INTERNAL or name in READ_ONLY:
        raise ExpressionError(f"{k} attribute '{name}' is read-only")
    return False


def is_flag(kind, name):
    """Whether ``set gen name`` / ``unset gen name`` (no value) sets or
    clears a boolean attribute of this module."""
    return ((kind, name) in GRAPHICS and GRAPHICS[(kind, name)] in (0.0, 1.0)
            and name != "opacity") or (kind, name) in FLAGS_DEFAULT and \
        name not in ("orientation", "phase") or (name == "bare" and kind in ("vertex", "edge"))


class ConstraintAt:
    """``vv.constraint[n]``: constraint n seen from a vertex (its ``normal``)."""

    __slots__ = ("i", "cid")

    def __init__(self, i, cid):
        self.i = i
        self.cid = cid

    def __float__(self):                    # printed or computed with on its own
        raise ExpressionError(f"constraint[{self.cid}] of a vertex is not a value; use "
                              f"vertex[i].constraint[{self.cid}].normal")

    __bool__ = __float__


def constraint_attr(session, base, name, idx):
    """``vertex[i].constraint[n].normal`` (vector or one component)."""
    if name != "normal":
        raise ExpressionError(f"constraint[{base.cid}] has no attribute '{name}' "
                              f"(only .normal)")
    if idx is not None and not isinstance(idx, tuple):
        idx = as_int(idx, "the index of 'normal'")
    return _component(constraint_normal(session, base.i, base.cid), idx, "normal")


def on_quantity(session, base, name, arg):
    """``on_quantity q`` / ``on_method_instance m``: whether the element
    contributes to the quantity (to one of its method instances)."""
    if not isinstance(base, ElemRef):
        raise ExpressionError(f"'{name}' needs an element")
    s = session.surface
    if not isinstance(arg, QRef):
        raise ExpressionError(f"{name} needs a quantity or method instance name "
                              f"(for example: ff.{name} myquant)")
    q = s.quantities[arg.name]
    if name == "on_method_instance" and q.kind != "instance":
        raise ExpressionError(f"'{arg.name}' is a quantity, not a method instance")
    if name == "on_quantity" and q.kind == "instance":
        raise ExpressionError(f"'{arg.name}' is a method instance, not a quantity")
    kind = base.kind

    def members(ss, tt):
        mask = np.zeros(elements.count(session, kind), bool)
        for m, etype, idx, _sign in q.methods:
            if etype == kind and not m.is_global:     # REF: global methods mark none
                mask[np.asarray(idx, np.int64)] = True
        return mask

    return float(cache(session).get(session, f"on:{arg.name}:{kind}", members)[base.i])


def element_quantity_value(session, base, qname):
    """``ff.qname``: the element's contribution to a named quantity (or
    method instance): Σ over the quantity's methods on elements of this kind
    of modulus × value (× orientation), times the quantity's modulus."""
    s = session.surface
    q = s.quantities[qname]
    if q.function is not None:
        raise UnsupportedError(f"per-element values of the FUNCTION quantity {qname}")
    kind = base.kind

    def values(ss, tt):
        out = np.zeros(elements.count(session, kind))
        for m, etype, idx, sign in q.methods:
            if etype != kind:
                continue
            _, fn = method_info(m.method)
            idx = np.asarray(idx, np.int64)
            vals = np.asarray(fn(tt, m, idx), float)
            if sign is not None:
                vals = vals * sign
            np.add.at(out, idx, m.modulus * vals)
        return q.modulus * out

    return float(cache(session).get(session, f"quantity:{qname}:{kind}", values)[base.i])


QUANTITY_KINDS = ("fixed", "energy", "info_only", "conserved")


def quantity_attr(session, q, name):
    """Quantity attributes beyond value/target/modulus/pressure/tolerance:
    the kind flags ``fixed``, ``energy``, ``info_only``, ``conserved`` (0/1)
    and ``volconst`` (0: pyevolver's quantities have none)."""
    if name in QUANTITY_KINDS:
        return float(q.kind == name)
    if name == "volconst":
        return 0.0
    if name in ("parameter_1", "element_modulus"):
        raise UnsupportedError(f"quantity attribute {name} in commands",
                               "method parameters are read from the datafile only")
    what = "method instance" if q.kind == "instance" else "quantity"
    raise ExpressionError(f"{what} {q.name} has no attribute '{name}' (expected value, "
                          f"target, modulus, pressure, tolerance, fixed, energy, info_only, "
                          f"conserved)")


def set_quantity(session, qname, attr, value):
    """``set q target|modulus|tolerance value`` and ``set q
    fixed|energy|info_only|conserved`` (the manual's SET quantityname forms);
    a method instance takes only ``modulus``."""
    s = session.surface
    q = s.quantities[qname]
    if q.kind == "instance":
        if attr != "modulus":
            raise ExpressionError(f"set {qname}: a method instance has only a settable "
                                  f"modulus")
    if attr in QUANTITY_KINDS:
        if value is not None:
            raise ExpressionError(f"set {qname} {attr} takes no value")
        if q.kind == "instance":
            raise ExpressionError(f"set {qname} {attr}: {qname} is a method instance")
        q.kind = attr
        return
    if attr in ("target", "modulus", "tolerance"):
        if value is None:
            raise ExpressionError(f"set {qname} {attr} needs a value")
        setattr(q, attr, as_float(value, f"{qname}.{attr}"))
        return
    if attr == "volconst":
        raise UnsupportedError("quantity volconst")
    raise ExpressionError(f"set {qname}: '{attr}' is not a settable quantity attribute "
                          f"(expected target, modulus, tolerance, fixed, energy, info_only "
                          f"or conserved)")


def _set_parameter(session, i, name, idx, value):
    """``set vertex p1 expr``: a boundary vertex's parameter; the vertex
    moves to its new place on the boundary at once (REF)."""
    s = session.surface
    bnd = s.vattr.get("boundary")
    if bnd is None or not bnd[i]:
        raise ExpressionError(f"vertex {int(s.ids('vertex')[i])} is on no parametric "
                              f"boundary: it has no parameter {name}")
    j = int(idx) if name == "p" else int(name[1])
    b = s.boundaries[int(bnd[i])]
    if j < 1 or j > b.nparams:
        raise ExpressionError(f"boundary {b.id} has {b.nparams} parameter(s), not p{j}")
    if not np.isfinite(value):
        raise ExpressionError(f"boundary parameters must be finite numbers, got {value:g}")
    P = s.vattr["params"]
    P[i, j - 1] = float(value)
    X, _ = boundary_eval(s, int(bnd[i]), P[i:i + 1])
    if not np.all(np.isfinite(X)):
        raise ExpressionError(f"boundary {b.id} at p{j} = {value:g} is not a finite point")
    s.X[i, :X.shape[1]] = X[0]
    cache(session).touch(session)
    return True


def unset_boundary(session, els, bid):
    """``unset vertex|edge|facet boundary n``: the elements leave boundary n
    (vertices keep their place and become free)."""
    s = session.surface
    bid = as_int(bid, "a boundary number")
    if bid not in s.boundaries:
        raise ExpressionError(f"unset ... boundary {bid}: boundary {bid} is not defined")
    for el in els:
        attrs = {"vertex": s.vattr, "edge": s.eattr, "facet": s.fattr}.get(el.kind)
        if attrs is None:
            raise ExpressionError("unset boundary applies to vertices, edges and facets")
        b = attrs.get("boundary")
        if b is not None and b[el.i] == bid:
            b[el.i] = 0


def remember_unset(session, i, attr, value):
    """``unset body target|pressure``: REF keeps printing the value it had."""
    if not np.isnan(value):
        _session_store(session).setdefault(("body", attr + "_unset"), {})[i] = \
            (session.surface, float(value))


def unset_value(session, i, attr, default):
    """The value a body's unset target or pressure still reads as (REF), or
    ``default``."""
    hit = _session_store(session).get(("body", attr + "_unset"), {}).get(i)
    if hit is None or hit[0] is not session.surface:
        return default
    return hit[1]


def membership_name(session, kind, attr, expr):
    """The quantity or method instance a ``set gen [quantity] name`` /
    ``unset gen name`` adds elements to or removes them from, or None."""
    s = session.surface
    if s is None or kind not in ("vertex", "edge", "facet") or (kind, attr) in s.extra:
        return None
    if attr in ("quantity", "method_instance", "method") and isinstance(expr, N.Var) \
            and expr.name in s.quantities:
        return expr.name
    if attr in s.quantities and expr is None:
        return attr
    return None


def set_membership(session, kind, els, qname, on):
    """Put elements on a named quantity / method instance (``on``) or take
    them off: its non-global methods of this element kind get or lose the
    elements (orientation +1 for new ones); global methods are left as they
    are, as REF does."""
    s = session.surface
    q = s.quantities[qname]
    if q.function is not None:
        raise UnsupportedError(f"set/unset elements on the FUNCTION quantity {qname}",
                               "put them on its method instances")
    which = [j for j, (m, etype, _idx, _sgn) in enumerate(q.methods) if etype == kind]
    if not which:
        if not on:
            return
        for _ in els:           # REF warns once per element
            session.write_err(f"WARNING 1569: Quantity '{qname}' has no methods applying "
                              f"to this type element.\n")
        return
    ids = np.array(sorted({el.i for el in els}), np.int64)
    for j in which:
        m, etype, idx, sgn = q.methods[j]
        if m.is_global:         # on every element already; REF ignores unset
            continue
        idx = np.asarray(idx, np.int64)
        sgn = np.ones(len(idx)) if sgn is None else np.asarray(sgn, float)
        if on:
            new = ids[~np.isin(ids, idx)]
            idx = np.concatenate([idx, new])
            sgn = np.concatenate([sgn, np.ones(len(new))])
        else:
            keep = ~np.isin(idx, ids)
            idx, sgn = idx[keep], sgn[keep]
        q.methods[j] = (m, etype, idx, sgn)
    cache(session).touch(session)           # memberships and values cached per surface
