"""Writing a surface back as a datafile (the ``dump`` command).

The writer turns the arrays of a :class:`pyevolver.model.surface.Surface` (and the
settings of its session, :class:`DumpSettings`) into a datafile that both pyevolver and the
Evolver load back to the same surface: the same elements in the same order,
coordinates written with 17 significant digits (so every double comes back
exactly), parameters, constraints, boundaries, quantities, method instances,
element attributes, flags, tensions and bodies.  Formulas are written from
their expression trees, fully parenthesized.  Whatever the surface holds
that a datafile cannot express makes the writer refuse by name; it never
writes a silently different surface.

Writers are registered by format name (``WRITERS``), as meshio does;
:func:`dump` picks one (the datafile format by default).
"""
from __future__ import annotations

import contextvars

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..atomic import atomic_write
from ..errors import UnsupportedError
from ..expr import nodes as N
from ..model.surface import Surface
from ..model.symmetry import encode_torus

_CON_FLAGS = ("global", "convex", "nonwall", "nonnegative", "nonpositive")
_NAME = re.compile(r"^[a-z_][a-z0-9_]*$", re.I)


def num(v):
    """A number written so that reading it gives back the same double."""
    v = float(v)
    if not math.isfinite(v):
        raise UnsupportedError(f"dump: the value {v} (not a finite number)")
    if v == int(v) and abs(v) < 1e15:
        return str(int(v))
    return "%.17g" % v


_PREC = {"+": 5, "-": 5, "*": 6, "/": 6, "%": 6, "mod": 6, "imod": 6, "idiv": 6, "^": 8}


def expr_text(node):
    """Source text of an expression tree (parentheses where precedence
    needs them; numbers with 17 digits)."""
    if isinstance(node, N.Formula):
        node = node.node
    return _text(node)[0]


def _wrap(child, prec, strict=False):
    text, p = _text(child)
    return f"({text})" if p < prec or (strict and p == prec) else text


# whether the surface being written has SPACE_DIMENSION > 3 (formulas name x4)
_HIGH_DIM: contextvars.ContextVar[bool] = contextvars.ContextVar("_HIGH_DIM", default=False)


def _text(node):
    """(text, precedence of its outermost operator)."""
    if isinstance(node, N.Num):
        t = num(node.value)
        return (f"({t})", 9) if t.startswith("-") else (t, 9)
    if isinstance(node, N.Var):
        # the gravitational constant is G in the Evolver (g alone is its go command)
        # in SPACE_DIMENSION > 3 the fourth coordinate (canonically w) is x4
        if node.name == "w" and _HIGH_DIM.get():
            return "x4", 9
        return ("G" if node.name == "g" else node.name), 9
    if isinstance(node, N.Func):
        return f"{node.name}({', '.join(expr_text(a) for a in node.args)})", 9
    if isinstance(node, N.Index):
        return f"{node.name}[{expr_text(node.index)}]", 9
    if isinstance(node, N.Neg):
        return f"-{_wrap(node.a, 9)}", 7
    if isinstance(node, N.Not):
        return f"!{_wrap(node.a, 9)}", 7
    if isinstance(node, N.Bin) and node.op in _PREC:
        p = _PREC[node.op]
        op = node.op if len(node.op) == 1 else f" {node.op} "
        if node.op == "^":
            return f"{_wrap(node.a, 9)}^{_wrap(node.b, 9)}", p
        return f"{_wrap(node.a, p)}{op}{_wrap(node.b, p, strict=True)}", p
    if isinstance(node, N.Cmp):
        return f"{_wrap(node.a, 5)} {node.op} {_wrap(node.b, 5)}", 4
    if isinstance(node, N.And):
        return f"{_wrap(node.a, 4)} && {_wrap(node.b, 4)}", 3
    if isinstance(node, N.Or):
        return f"{_wrap(node.a, 3)} || {_wrap(node.b, 3)}", 2
    if isinstance(node, N.Cond):
        return f"{_wrap(node.c, 2)} ? {_wrap(node.a, 2)} : {_wrap(node.b, 2)}", 1
    raise UnsupportedError(f"dump: a formula with {type(node).__name__} "
                           "(it has no datafile form)")


def _comps(letter, formulas):
    return "\n".join(f"  {letter}{k + 1}: {expr_text(f)}" for k, f in enumerate(formulas))


# ---------------------------------------------------------------------------


@dataclass
class DumpSettings:
    """What a dump writes besides the surface: the settings of the session
    that evolved it.

    ``settings``: ``scale``, ``scale_limit``, ``constraint_tolerance``,
    ``autochop_length``; ``toggles``: the motion and energy toggles (``conj_grad``,
    ``gravity``, ``_fixed_scale``, ...); ``attr_types``: ``(kind, name) ->``
    the declared type of an extra attribute (``"integer"``, ``"real"``).
    """

    filename: str = ""
    settings: Mapping = field(default_factory=dict)
    toggles: Mapping = field(default_factory=dict)
    attr_types: Mapping = field(default_factory=dict)

    @classmethod
    def of(cls, obj) -> "DumpSettings":
        """Those of an object with the attributes ``filename``,
        ``settings``, ``toggles`` and ``attr_types`` (a session)."""
        return cls(getattr(obj, "filename", ""), obj.settings, obj.toggles,
                   getattr(obj, "attr_types", {}))


class _FeWriter:
    def __init__(self, surface, settings: DumpSettings | None = None):
        self.s = surface
        self.opts = settings
        self.lines: list[str] = []

    def w(self, text=""):
        self.lines.append(text)

    def refuse(self, what):
        raise UnsupportedError(f"dump: {what} (a datafile cannot express it)")

    def text(self):
        token = _HIGH_DIM.set(self.s.sdim > 3)
        try:
            return self._text()
        finally:
            _HIGH_DIM.reset(token)

    def _text(self):
        s = self.s
        if s.sdim < 3 and not (s.string and s.sdim == 2):
            self.refuse(f"space dimension {s.sdim}")
        self._check()
        self._header()
        self._vertices()
        self._edges()
        self._faces()
        self._bodies()
        self._read()
        return "\n".join(self.lines) + "\n"

    # -- what cannot be written ------------------------------------------------
    def _check(self):
        s = self.s
        known_v = {"fixed", "original", "boundary", "params", "id", "axial_point"}
        known_e = {"fixed", "original", "boundary", "tension", "no_refine", "color", "wrap", "id",
                   "wrap_code"}
        if s.string:                 # the string model's own bookkeeping (rebuilt on reading)
            known_v = known_v | {"ring_head"}
            known_e = known_e | {"ring_time"}
        known_f = {"fixed", "original", "boundary", "tension", "no_refine", "color", "frontcolor",
                   "backcolor", "id"}
        for what, attrs, known in (("vertex", s.vattr, known_v), ("edge", s.eattr, known_e),
                                   ("facet", s.fattr, known_f)):
            for k in attrs:
                if k not in known:
                    self.refuse(f"the {what} attribute '{k}'")
        for key, arr in s.extra.items():
            if key[0] not in ("vertex", "edge", "facet", "body"):
                self.refuse(f"{key[0]} attribute '{key[1]}'")
        b = s.bodies
        if b.n:
            ob, of, osg = b.occurrences
            M = sp.csr_matrix((osg, (ob, of)), shape=(b.n, s.n_facets))
            if (M != b.facet_matrix.tocsr()).nnz:
                self.refuse("bodies whose facet list differs from their facets")

    # -- top section -------------------------------------------------------------
    def _metric(self, m):
        """METRIC rows / CONFORMAL_METRIC / KLEIN_METRIC (after the
        parameters its formulas may name), with non-default quadrature orders."""
        if m.order_1d != 3:
            self.w(f"INTEGRAL_ORDER_1D: {m.order_1d}")
        if m.order_2d != 6:
            self.w(f"INTEGRAL_ORDER_2D: {m.order_2d}")
        if m.kind == "klein":
            self.w("KLEIN_METRIC")
        elif m.kind == "conformal":
            self.w("CONFORMAL_METRIC " + expr_text(m.comps[0]))
        else:
            self.w("METRIC")
            for i in range(m.dim):
                self.w(" " + " ".join(f"({expr_text(c)})" for c in m.comps[i * m.dim:(i + 1) * m.dim]))
        self.w()

    def _header(self):
        s, opts = self.s, self.opts
        name = opts.filename if opts is not None else ""
        self.w(f"// Dump of a surface by pyevolver{' (datafile ' + name + ')' if name else ''}")
        self.w()
        if s.string:
            self.w("STRING")
        if s.simplex:
            self.w("SIMPLEX_REPRESENTATION")
            self.w(f"SURFACE_DIMENSION {s.simplex}")
        if s.sdim != 3:
            self.w(f"SPACE_DIMENSION {s.sdim}")
        group = getattr(s, "symmetry_group", None)
        if group is not None:
            self.w(f'SYMMETRY_GROUP "{group}"')
        if s.periods is not None and (group is None or np.any(s.periods != np.eye(3))):
            if group is None:
                self.w("TORUS_FILLED" if s.torus_filled else "TORUS")
            self.w("PERIODS")
            for row in np.asarray(s.periods)[:s.sdim, :s.sdim]:
                self.w(" ".join(num(v) for v in row))
        if s.symmetric_content:
            self.w("SYMMETRIC_CONTENT")
        if s.order == 2:
            self.w("QUADRATIC")
        mode = getattr(s, "curvature_mode", "plain")
        if mode == "eff":
            self.w("EFFECTIVE_AREA")
        elif mode == "norm":
            self.w("NORMAL_CURVATURE")
        if s.gravity_constant != 1.0:
            self.w(f"GRAVITY_CONSTANT {num(s.gravity_constant)}")
        if s.gap_constant != 1.0:
            self.w(f"GAP_CONSTANT {num(s.gap_constant)}")
        if s.sq_curvature_modulus:
            self.w(f"SQUARED_CURVATURE {num(s.sq_curvature_modulus)}")
        if opts is not None:
            st = opts.settings
            if st.get("diffusion_coeff"):
                self.w(f"DIFFUSION: {num(st['diffusion_coeff'])}")
            fixed = " FIXED" if opts.toggles.get("_fixed_scale") else ""
            self.w(f"SCALE {num(st['scale'])}{fixed}")
            self.w(f"SCALE_LIMIT {num(st['scale_limit'])}")
            self.w(f"CONSTRAINT_TOLERANCE {num(st['constraint_tolerance'])}")
            if opts.toggles.get("autochop"):
                self.w(f"AUTOCHOP {num(st.get('autochop_length', 0.0))}")
        self.w()
        for pname, v in s.params.items():
            if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.number)):
                continue            # strings and arrays are not datafile parameters
            if not _NAME.match(pname) or pname in N.CONSTANTS:
                continue
            opt = (getattr(s, "optimizing", None) or {}).get(pname)
            if opt is not None:     # REF: OPTIMIZING_PARAMETER rr = 1.2 pscale = 0.3
                extra = "".join(f" {k} = {num(x)}" for k, x, d in
                                (("pdelta", opt[0], 1e-4), ("pscale", opt[1], 1.0)) if x != d)
                self.w(f"OPTIMIZING_PARAMETER {pname} = {num(v)}{extra}")
                continue
            self.w(f"PARAMETER {pname} = {num(v)}")
        self.w()
        if getattr(s, "metric", None) is not None:
            self._metric(s.metric)
        types = self.opts.attr_types if self.opts is not None else {}
        for (etype, aname), arr in self.s.extra.items():
            typ = types.get((etype, aname), "real")
            if typ == "integer" and np.any(arr != np.round(arr)):
                typ = "real"
            dims = "".join(f"[{d}]" for d in arr.shape[1:])
            self.w(f"define {etype} attribute {aname} {typ}{dims}")
        self.w()
        cnames = getattr(s, "constraint_names", {})
        bnames = getattr(s, "boundary_names", {})
        if cnames or bnames:
            # named constraints and boundaries are written by name, declared
            # ahead as in REF's dumps ("constraint pinned;")
            for cid in sorted(cnames):
                if cid in s.constraints:
                    self.w(f"constraint {cnames[cid]};")
            for bid in sorted(bnames):
                if bid in s.boundaries:
                    self.w(f"boundary {bnames[bid]};")
            self.w()
        for cid, c in sorted(s.constraints.items()):
            opts = "".join(f" {f.upper()}" for f in sorted(c.flags) if f in _CON_FLAGS)
            self.w(f"CONSTRAINT {cnames.get(cid, cid)}{opts}")
            self.w(f"FORMULA: {expr_text(c.formula)} = 0")
            if c.energy:
                self.w("ENERGY:\n" + _comps("e", c.energy))
            if c.content:
                self.w("CONTENT:\n" + _comps("c", c.content))
            self.w()
        for bid, b in sorted(s.boundaries.items()):
            opts = " CONVEX" if "convex" in b.flags else ""
            self.w(f"BOUNDARY {bnames.get(bid, bid)} PARAMETERS {b.nparams}{opts}")
            self.w(_comps("x", b.coords))
            if b.energy:
                self.w("ENERGY:\n" + _comps("e", b.energy))
            if b.content:
                self.w("CONTENT:\n" + _comps("c", b.content))
            self.w()
        self._quantities()

    def _method_text(self, m):
        out = [m.method]
        if m.is_global:
            out.append("global")
        if m.modulus != 1.0:
            out.append(f"modulus {num(m.modulus)}")
        if getattr(m, "parameter_1", None) is not None:
            out.append(f"parameter_1 {num(m.parameter_1)}")
        if m.ignore_fixed:
            out.append("ignore_fixed")
        if m.ignore_constraints:
            out.append("ignore_constraints")
        if m.scalar is not None:
            out.append(f"scalar_integrand: {expr_text(m.scalar)}")
        if m.vector is not None:
            out.append("vector_integrand:\n" + _comps("q", m.vector))
        return " ".join(out)

    def _quantities(self):
        s = self.s
        self.members = {"vertex": {}, "edge": {}, "facet": {}}
        for name, q in s.quantities.items():
            if q.kind == "instance":
                (m, etype, idx, sign), = q.methods
                self.w(f"METHOD_INSTANCE {name} METHOD {self._method_text(m)}")
                self._add_members(name, etype, m, idx, sign)
        for name, q in s.quantities.items():
            if q.kind == "instance":
                continue
            if q.kind == "fixed":
                head = f"QUANTITY {name} FIXED = {num(q.target)}"
            elif q.kind in ("energy", "conserved", "info_only"):
                head = f"QUANTITY {name} {q.kind.upper()}"
            else:
                self.refuse(f"quantity {name} of kind {q.kind}")
            if q.modulus != 1.0:
                head += f" MODULUS {num(q.modulus)}"
            if q.tolerance != -1.0:
                head += f" TOLERANCE {num(q.tolerance)}"
            self.w(head)
            seen = {}
            for m, etype, idx, sign in q.methods:
                kw = "METHOD"
                self.w(f"  {kw} {self._method_text(m)}")
                if not m.is_global:
                    prev = seen.get(etype)
                    if prev is not None and not (np.array_equal(prev[0], idx) and
                                                 np.array_equal(prev[1], sign)):
                        self.refuse(f"quantity {name}: two {etype} methods on different "
                                    f"{etype}s")
                    seen[etype] = (idx, sign)
                    self._add_members(name, etype, m, idx, sign)
            if q.function is not None:
                self.w(f"  FUNCTION {expr_text(q.function)}")
            self.w()

    def _add_members(self, name, etype, m, idx, sign):
        if m.is_global or idx is None:
            return
        d = self.members[etype]
        seen = set()
        for k, sg in zip(np.asarray(idx).tolist(),
                         (np.ones(len(idx)) if sign is None else np.asarray(sign)).tolist()):
            if (k, name) in seen:
                self.refuse(f"{name}: an {etype} listed twice")
            seen.add((k, name))
            d.setdefault(k, []).append(name if sg > 0 else name + "-")

    # -- elements -------------------------------------------------------------------
    def _extra_text(self, etype, k):
        out = []
        for (et, aname), arr in self.s.extra.items():
            if et != etype:
                continue
            v = arr[k]
            if np.ndim(v) == 0:
                if v != 0:
                    out.append(f"{aname} {num(v)}")
            elif np.any(v != 0):
                out.append(aname + " " + " ".join(num(x) for x in np.ravel(v)))
        return out

    def _blabel(self, bid):
        return getattr(self.s, "boundary_names", {}).get(bid, str(bid))

    def _cons(self, table, k, signed=False):
        ids = []
        for cid, arr in sorted(table.items()):
            if "global" in self.s.constraints[cid].flags:
                continue
            v = arr[k]
            if v:
                name = getattr(self.s, "constraint_names", {}).get(cid, str(cid))
                ids.append(("-" if signed and v < 0 else "") + name)
        return f"constraints {' '.join(ids)}" if ids else None

    def _vertices(self):
        s = self.s
        fixed = s.vattr.get("fixed")
        bnd = s.vattr.get("boundary")
        params = s.vattr.get("params")
        self.w("vertices")
        mem = self.members["vertex"]
        for k in range(s.nv):
            if bnd is not None and bnd[k]:
                b = s.boundaries[int(bnd[k])]
                parts = [num(v) for v in params[k, :b.nparams]] + [f"boundary {self._blabel(int(bnd[k]))}"]
            else:
                parts = [num(v) for v in s.X[k, :s.sdim]]
            if fixed is not None and fixed[k]:
                parts.append("fixed")
            if "axial_point" in s.vattr and s.vattr["axial_point"][k]:
                parts.append("axial_point")
            c = self._cons(s.vcon, k)
            if c:
                parts.append(c)
            parts += mem.get(k, [])
            parts += self._extra_text("vertex", k)
            self.w(f"{k + 1} " + " ".join(parts))
        self.w()

    def _edges(self):
        s = self.s
        ea = s.eattr
        wrap = ea.get("wrap") if s.periods is not None else None
        codes = None
        if wrap is not None and getattr(s, "symmetry_group", None) is not None:
            codes, wrap = encode_torus(wrap), None
        elif "wrap_code" in ea:                     # the other groups (model.groups)
            codes = ea["wrap_code"]
        if wrap is not None and np.any(~np.isin(wrap, (-1, 0, 1))):
            self.refuse("an edge wrapping more than one period")
        mem = self.members["edge"]
        self.w("edges")
        for k in range(s.ne):
            a, b = s.E[k]
            parts = [str(a + 1), str(b + 1)]
            if s.order == 2:               # the midpoint third (REF's dump)
                parts.append(str(s.midv[k] + 1))
            if wrap is not None:
                parts += [{0: "*", 1: "+", -1: "-"}[int(v)] for v in wrap[k]]
            elif codes is not None and codes[k]:
                parts.append(f"wrap {codes[k]}")
            if ea.get("fixed") is not None and ea["fixed"][k]:
                parts.append("fixed")
            if ea.get("boundary") is not None and ea["boundary"][k]:
                parts.append(f"boundary {self._blabel(int(ea['boundary'][k]))}")
            c = self._cons(s.econ, k, signed=True)
            if c:
                parts.append(c)
            if ea.get("tension") is not None and ea["tension"][k] != (1.0 if s.string else 0.0):
                parts.append(f"density {num(ea['tension'][k])}")
            if ea.get("no_refine") is not None and ea["no_refine"][k]:
                parts.append("no_refine")
            if ea.get("color") is not None and ea["color"][k]:
                parts.append(f"color {int(ea['color'][k])}")
            parts += mem.get(k, [])
            parts += self._extra_text("edge", k)
            self.w(f"{k + 1} " + " ".join(parts))
        self.w()

    def _faces(self):
        s = self.s
        fa = s.fattr
        mem = self.members["facet"]
        self.w("faces")
        for k in range(s.n_facets):
            if s.string:                 # a chain of edges (encoded ~e when reversed)
                parts = [str(int(e) + 1) if e >= 0 else str(int(e))
                         for e in s.sf_enc[s.sf_ptr[k]:s.sf_ptr[k + 1]]]
            elif s.simplex:              # the simplex model: the oriented vertex list
                parts = [str(int(v) + 1) for v in s.SF[k]]
            else:
                parts = [str(int(e) + 1) if e >= 0 else str(int(e)) for e in s.FE[k]]
            if fa.get("fixed") is not None and fa["fixed"][k]:
                parts.append("fixed")
            if fa.get("boundary") is not None and fa["boundary"][k]:
                parts.append(f"boundary {self._blabel(int(fa['boundary'][k]))}")
            c = self._cons(s.fcon, k)
            if c:
                parts.append(c)
            t = fa["tension"][k]
            if t != 1.0 and not s.string:      # string facets carry no tension
                parts.append(f"tension {num(t)}")
            if fa.get("no_refine") is not None and fa["no_refine"][k]:
                parts.append("no_refine")
            for key in ("color", "frontcolor", "backcolor"):
                if fa.get(key) is not None and fa[key][k]:
                    parts.append(f"{key} {int(fa[key][k])}")
            parts += mem.get(k, [])
            parts += self._extra_text("facet", k)
            self.w(f"{k + 1} " + " ".join(parts))
        self.w()

    def _bodies(self):
        b = self.s.bodies
        if not b.n:
            return
        ob, of, osg = b.occurrences
        self.w("bodies")
        for k in range(b.n):
            sel = ob == k
            parts = [str(int(c) + 1) if v > 0 else str(-(int(c) + 1))
                     for c, v in zip(of[sel], osg[sel])]
            if not np.isnan(b.target[k]):
                parts.append(f"volume {num(b.target[k])}")
            if b.pressure is not None and not np.isnan(b.pressure[k]):
                parts.append(f"pressure {num(b.pressure[k])}")
            if b.volconst is not None and b.volconst[k]:
                parts.append(f"volconst {num(b.volconst[k])}")
            if not np.isnan(b.target[k]) and b.lagrange[k] and \
                    self.opts is not None and self.opts.toggles.get("diffusion"):
                # the pressure the next step's diffusion starts from (REF writes it)
                parts.append(f"lagrange_multiplier {num(b.lagrange[k])}")
            if b.density is not None and b.density[k]:
                parts.append(f"density {num(b.density[k])}")
            parts += self._extra_text("body", k)
            self.w(f"{k + 1} " + " ".join(parts))
        self.w()

    def _read(self):
        """Toggles that change the energy, set as the surface had them."""
        opts = self.opts
        if opts is None:
            return
        out = []
        tg = opts.toggles
        # the motion toggles, as the Evolver's dump restores them (its names)
        for name, word in (("conj_grad", "conj_grad"), ("autochop", "autochop"),
                           ("approximate_curvature", "approx_curv"),
                           ("runge_kutta", "runge_kutta"), ("check_increase", "check_increase"),
                           ("area_normalization", "area_normalization"),
                           ("post_project", "post_project"), ("normal_motion", "normal_motion"),
                           ("autopop", "autopop"), ("jiggle", "jiggle"),
                           ("diffusion", "diffusion")):
            if tg.get(name):
                out.append(f"{word} on")
        for name in ("ribiere", "hessian_normal"):          # on by default
            if not tg.get(name, 1):
                out.append(f"{name} off")
        b = self.s.bodies
        if b.n and np.any(b.density) or self.s.gravity_constant != 1.0:
            out.append(f"gravity {'on' if opts.toggles.get('gravity', 1) else 'off'}")
        if out:
            self.w("read")
            self.w()
            for line in out:
                self.w(line)


def write_fe(surface: Surface, path: str, settings: DumpSettings | None = None) -> None:
    """Write ``surface`` as a datafile to ``path`` (atomically), with the
    session ``settings`` when given (SCALE, toggles in a ``read`` section)."""
    text = _FeWriter(surface, settings).text()
    with atomic_write(path, "w", encoding="latin-1") as fh:
        fh.write(text)


WRITERS = {"fe": write_fe}


def dump(surface: Surface, path: str, fmt: str = "fe",
         settings: DumpSettings | None = None) -> None:
    """Write ``surface`` with the session ``settings`` to ``path`` in the
    format ``fmt`` (a key of :data:`WRITERS`).

    ``surface`` may also be an object holding one in ``.surface`` with the
    attributes of :meth:`DumpSettings.of` (a session): its settings are
    written unless ``settings`` is given.
    """
    if surface is not None and not isinstance(surface, Surface):
        if settings is None:
            settings = DumpSettings.of(surface)
        surface = surface.surface
    if surface is None:
        raise UnsupportedError("dump: no surface is loaded")
    try:
        writer = WRITERS[fmt]
    except KeyError:
        raise UnsupportedError(f"dump format '{fmt}'", f"known: {', '.join(WRITERS)}") from None
    writer(surface, path, settings=settings)
