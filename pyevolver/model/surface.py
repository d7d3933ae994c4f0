"""The Surface: coordinates and topology as numpy arrays, built from a Scene.

Element indices are 0-based internally; the Evolver's ids are index + 1
(elements are renumbered consecutively in reading order, the datafile id is
kept as ``original``).  Attributes, constraints, boundaries and quantities
exist only when the datafile declares them.
"""
from __future__ import annotations

import contextlib
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..geometry import kernels as G
from ..errors import DatafileError, PyEvolverError, UnsupportedError
from ..limits import MAX_ARRAY_ENTRIES
from ..expr import nodes as N
from ..methods import method_info


@dataclass
class Quantity:
    """A named quantity at run time."""

    name: str
    kind: str                      # energy fixed conserved info_only
    target: float = 0.0
    modulus: float = 1.0
    tolerance: float = -1.0
    methods: list = field(default_factory=list)    # [(MethodDecl, etype, idx, sign)]
    value: float = 0.0
    pressure: float = 0.0
    # FUNCTION quantities: a Formula of the global values of method instances,
    # ``inst.value``; the instances are quantities of kind "instance"
    function: object = None
    line: int | None = None        # source line of its declaration


@dataclass
class Bodies:
    n: int = 0
    facet_matrix: object = None      # sparse (nb, nf) with +-1 entries
    target: np.ndarray = None        # nan where no volume constraint
    volconst: np.ndarray = None
    pressure: np.ndarray = None      # prescribed pressure (nan = none)
    density: np.ndarray = None
    volume: np.ndarray = None        # last computed
    lagrange: np.ndarray = None      # reported pressures (multipliers)
    original: np.ndarray = None
    occurrences: tuple = None        # (body, facet, sign) as listed (duplicates kept)


class Surface:
    """Arrays of one surface (soapfilm model, linear elements)."""

    def __init__(self):
        self.sdim = 3
        self.X = np.zeros((0, 3))
        self.E = np.zeros((0, 2), dtype=np.int64)
        self.FE = np.zeros((0, 3), dtype=np.int64)
        self.vattr = {}
        self.eattr = {}
        self.fattr = {}
        self.vcon = {}      # constraint id -> bool (nv,)
        self.econ = {}      # constraint id -> int8 (ne,) (+1 / -1 orientation)
        self.fcon = {}      # constraint id -> bool (nf,)
        self.extra = {}     # (etype, name) -> array
        self.bodies = Bodies()
        self.quantities = {}
        self.constraints = {}
        self.boundaries = {}
        self.periods = None
        self.symmetric_content = False
        self.torus_filled = False
        self.params = {}
        self.gravity_constant = 1.0
        self.gravity_on = True       # the `gravity` toggle (G v sets it to v != 0)
        self.gap_constant = 1.0
        self.sq_curvature_modulus = 0.0     # legacy SQUARED_CURVATURE c
        self.curvature_mode = "plain"       # toggles: effective_area -> eff, normal_curvature -> norm
        # the string model (surface dimension 1): facets are edge chains kept in
        # sf_ptr / sf_enc (pyevolver.model.string) and FE stays empty
        self.string = False
        self.sf_ptr = np.zeros(1, np.int64)
        self.sf_enc = np.zeros(0, np.int64)

    # -- topology helpers ---------------------------------------------------
    @property
    def nv(self):
        return len(self.X)

    @property
    def ne(self):
        return len(self.E)

    @property
    def nf(self):
        return len(self.FE)

    @property
    def n_facets(self):
        """Facets as the command language counts them: the edge chains in
        the string model, the triangles otherwise."""
        return len(self.sf_ptr) - 1 if self.string else len(self.FE)

    def topology(self):
        """Topology-derived arrays, cached while ``E`` and ``FE`` are the same
        array objects: ``(idx, sgn, F)`` = edge index (nf, 3), orientation
        sign (nf, 3) and facet vertices (nf, 3).  Operations that change the
        connectivity build new arrays, which invalidates the cache."""
        c = self.__dict__.get("_topo")
        if c is not None and c[0] is self.FE and c[1] is self.E:
            return c[2]
        idx, sgn = G.edge_index(self.FE)
        tails = np.where(sgn > 0, self.E[idx, 0], self.E[idx, 1])
        val = (idx, sgn, tails)
        self._topo = (self.FE, self.E, val)
        return val

    @property
    def F(self):
        """(nf, 3) vertices of each facet (tails of its oriented edges)."""
        return self.topology()[2]

    def facet_corners(self):
        """(3, nf) contiguous copy of ``F.T`` (cached with the topology), for
        gathering one coordinate of every facet corner at once."""
        topo = self.topology()
        c = self.__dict__.get("_corners")
        if c is not None and c[0] is topo:
            return c[1]
        Fc = np.ascontiguousarray(topo[2].T)
        self._corners = (topo, Fc)
        return Fc

    def ids(self, kind):
        """(n,) element ids of ``kind`` ("vertex", "edge", "facet"): 1..n
        after loading; deletions (``t``, ``w``, ...) leave gaps, as in the
        Evolver, and new elements take ids above the largest."""
        attrs = {"vertex": self.vattr, "edge": self.eattr, "facet": self.fattr}[kind]
        n = {"vertex": self.nv, "edge": self.ne, "facet": self.n_facets}[kind]
        a = attrs.get("id")
        return a if a is not None else np.arange(1, n + 1)

    @property
    def facet_tension(self):
        return self.fattr["tension"]

    @property
    def edge_tension(self):
        return self.eattr.get("tension", np.zeros(self.ne))

    def wrap_shift(self):
        w = self.eattr.get("wrap")
        if w is None or self.periods is None:
            return None
        return w @ self.periods

    def param_env(self):
        env = dict(self.params)
        env.setdefault("g", self.gravity_constant)
        return N.MapEnv(env)

    # -- evaluation --------------------------------------------------------
    def evaluate(self):
        """Compute energy, area, volumes and quantity values (a :class:`Totals`)."""
        if self.string:
            from .string import StringTotals
            return StringTotals(self)
        return Totals(self)


class Totals:
    """Energies, area and volumes of a surface at its current coordinates.

    Derived geometry (edge vectors, facet normals, areas) is computed once per
    evaluation and shared by every energy term and method.
    """

    def __init__(self, s):
        self.surface = s
        X = s.X
        wrap = s.wrap_shift()
        if wrap is None and X.shape[1] == 3:
            # corners gathered one coordinate at a time (several times faster
            # than gathering edge vectors); the torus needs the edge wraps
            P, N2T, self.facet_area, self.facet_volume = G.corner_geometry(
                np.ascontiguousarray(X.T), s.facet_corners(), s.symmetric_content)
            self._corner_xyz = P
            self.facet_N2 = N2T.T
        else:
            self.edge_vec = G.edge_vectors(X, s.E, wrap)
            idx, sgn, F = s.topology()
            self.facet_S = G.facet_sides(self.edge_vec, s.FE, (idx, sgn))
            self.facet_x0 = X[F[:, 0]] if s.nf else np.zeros((0, X.shape[1]))
            self.facet_N2 = G.facet_normals(self.facet_S)
            self.facet_area = G.facet_areas(self.facet_N2)
            self.facet_volume = G.facet_volumes(self.facet_x0, self.facet_S,
                                                s.symmetric_content)
        self.total_area = float(self.facet_area.sum())
        self.terms = {}
        energy = float(self.facet_area @ s.facet_tension)
        self.terms["facet_tension"] = energy
        et = s.eattr.get("tension")
        if et is not None:
            e = float(self.edge_length @ et)
            self.terms["edge_tension"] = e
            energy += e
        self.con_energy, self.con_content = self._integrals()
        energy += self.con_energy
        gap = self._gap_energy()
        if gap:
            self.terms["gap"] = gap
            energy += gap
        if s.sq_curvature_modulus:
            # legacy top-of-file SQUARED_CURVATURE (spec 5.3): the vertex
            # method picked by the effective_area / normal_curvature toggles
            from ..methods.curvature import legacy_energy
            e = s.sq_curvature_modulus * legacy_energy(self)
            self.terms["sq_curvature"] = e
            energy += e
        self.volumes = self._volumes()
        self.energy = self._finish_energy(energy, self._gravity() if s.bodies.n else 0.0)

    def _finish_energy(self, energy, grav):
        """``energy`` plus gravity ``grav``, the prescribed pressures' −P·V
        and the energy quantities (whose values are kept); ``self.volumes``
        must be set."""
        s = self.surface
        b = s.bodies
        if grav:
            self.terms["gravity"] = grav
            energy += grav
        if b.n:
            pmask = ~np.isnan(b.pressure)
            if pmask.any():
                energy -= float(b.pressure[pmask] @ self.volumes[pmask])
        self.quantity_values = {}
        for q in s.quantities.values():
            v = self.quantity_value(q)
            self.quantity_values[q.name] = v
            if q.kind == "energy":
                energy += v
        return energy

    # ---- derived geometry computed on first use -------------------------------
    def __getattr__(self, name):
        # only reached for attributes not yet set: build and cache them
        maker = Totals._LAZY.get(name)
        if maker is None:
            raise AttributeError(name)
        val = maker(self)
        setattr(self, name, val)
        return val

    def _make_edge_vec(self):
        s = self.surface
        return G.edge_vectors(s.X, s.E, s.wrap_shift())

    def _make_edge_length(self):
        d = self.edge_vec
        return np.sqrt(np.einsum("ij,ij->i", d, d))

    def _make_total_length(self):
        return float(self.edge_length.sum())

    def _make_facet_x0(self):
        P = self._corner_xyz
        return np.stack([P[0][0], P[1][0], P[2][0]], axis=1)

    def _make_facet_S(self):
        P = self._corner_xyz
        S = np.empty((self.surface.nf, 2, 3))
        for k in range(3):
            S[:, 0, k] = P[k][1] - P[k][0]
            S[:, 1, k] = P[k][2] - P[k][0]
        return S

    _LAZY = {"edge_vec": _make_edge_vec, "edge_length": _make_edge_length,
             "total_length": _make_total_length, "facet_x0": _make_facet_x0,
             "facet_S": _make_facet_S}

    # ---- pieces -----------------------------------------------------------
    def eval_points(self, formula, P, etype=None, idx=None):
        """Evaluate a formula at points ``P (n, sdim)``."""
        s = self.surface
        coords = {"x": P[:, 0], "y": P[:, 1]}
        if P.shape[1] > 2:
            coords["z"] = P[:, 2]
        if P.shape[1] > 3:
            coords["w"] = P[:, 3]
        if etype is not None and idx is not None:
            for (et, name), arr in s.extra.items():
                if et == etype and arr.ndim == 1:
                    coords[name] = arr[idx]
        return formula.values(s.param_env(), coords, len(P))

    def edge_vector_integral(self, comps, idx):
        """Sum of Gauss-Legendre line integrals of a vector field along edges."""
        s = self.surface
        x0 = s.X[s.E[idx, 0]]
        d = self.edge_vec[idx]
        pts = G.edge_quadrature_points(x0, d)
        n = len(idx)
        flat = pts.reshape(-1, pts.shape[-1])
        rep = np.repeat(idx, 2)
        total = np.zeros(n)
        with located(getattr(comps, "what", ""), getattr(comps, "line", None)):
            for k, comp in enumerate(comps):
                if k >= d.shape[1]:
                    break
                q = self.eval_points(comp, flat, "edge", rep).reshape(n, 2) @ G.GL2_W
                total += q * d[:, k]
        return total

    def _integrals(self):
        """Constraint and boundary ENERGY / CONTENT edge integrals."""
        s = self.surface
        energy = 0.0
        for comps, idx, sign in integral_edges(s, "energy"):
            energy += float(sign @ self.edge_vector_integral(comps, idx))
        content = None
        for comps, idx, sign in integral_edges(s, "content"):
            if content is None:
                content = np.zeros(s.ne)
            content[idx] += sign * self.edge_vector_integral(comps, idx)
        return energy, content

    def _gap_energy(self):
        """Gap energy of edges on CONVEX constraints (spec §4.1.7)."""
        s = self.surface
        total = 0.0
        for c, idx in convex_edges(s):
            d = self.edge_vec[idx]
            L = self.edge_length[idx]
            for end in (0, 1):
                P = s.X[s.E[idx, end]]
                g = self.constraint_gradient(c, P)
                gn = np.sqrt(np.einsum("ij,ij->i", g, g))
                sg = np.abs(np.einsum("ij,ij->i", d, g))
                with np.errstate(all="ignore"):
                    total += float(np.sum(np.where(gn > 0, sg * L / (12.0 * gn), 0.0)))
        return s.gap_constant * total

    def constraint_gradient(self, c, P):
        coords = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
        return c.formula.gradient(self.surface.param_env(), coords, len(P))

    def _volumes(self):
        s = self.surface
        b = s.bodies
        if not b.n:
            return np.zeros(0)
        vols = b.facet_matrix @ self.facet_volume
        if self.con_content is not None:
            # edge content counts toward the bodies of the facets the edge is on
            vols = vols + b.facet_matrix @ self.facet_edge_sum(self.con_content)
        vols = vols + b.volconst
        if s.periods is not None:
            D = torus_lift_shifts(s)                  # (nb, nf, 3)
            N2 = self.facet_N2
            if s.symmetric_content:
                vols = vols + np.einsum("bfk,fk->b", D, N2) / 6.0
            else:
                vols = vols + D[:, :, 2] @ (N2[:, 2] / 2.0)
            cell = abs(np.linalg.det(s.periods))
            ref = np.where(np.isnan(b.target), b.volume if b.volume is not None else vols,
                           b.target)
            ref = np.where(np.isnan(ref), vols, ref)
            shift = np.round((ref - vols) / cell) * cell
            vols = vols + shift
        return vols

    def facet_edge_sum(self, per_edge):
        """For each facet, sum of oriented per-edge values over its edges."""
        idx, sgn = G.edge_index(self.surface.FE)
        return np.sum(per_edge[idx] * sgn, axis=1)

    def _gravity(self):
        s = self.surface
        b = s.bodies
        G_ = s.gravity_constant
        if G_ == 0 or not s.gravity_on or not np.any(b.density):
            return 0.0
        return float(G_ * (b.density @ (b.facet_matrix @ self._facet_gravity())))

    def _facet_gravity(self):
        """(nf,) each facet's gravitational integral (unit density and G)."""
        return G.facet_gravity(self.facet_x0, self.facet_S)

    def instance_values(self, q):
        """``{"inst.value": value}`` of the method instances a FUNCTION reads."""
        s = self.surface
        return {f"{n}.value": self.quantity_value(s.quantities[n])
                for n in (v[:-6] for v in q.function.node.names() if v.endswith(".value"))}

    def quantity_value(self, q, magnitude=False):
        """Value of a named quantity; with ``magnitude=True`` the sum of the
        absolute values of its element contributions instead (the scale of
        its restoring tolerance).  A FUNCTION quantity's magnitude is its
        linearization's: Σ_i |∂f/∂v_i| magnitude_i."""
        try:
            return self._quantity_value(q, magnitude)
        except PyEvolverError as exc:
            if getattr(exc, "line", None) is None:     # say which quantity failed, where
                exc.line = q.line
                exc.args = (f"quantity {q.name}: {exc}",)
            raise

    def _quantity_value(self, q, magnitude=False):
        if q.function is not None:
            s = self.surface
            env = self.instance_values(q)
            params = s.param_env()
            if not magnitude:
                return q.modulus * float(q.function.values(params, env, 1)[0])
            names = list(env)
            d = q.function.gradient(params, env, 1, names)[0]
            return abs(q.modulus) * float(sum(
                abs(di) * self.quantity_value(s.quantities[n[:-6]], True)
                for di, n in zip(d, names)))
        total = 0.0
        for m, etype, idx, sign in q.methods:
            _, fn = method_info(m.method)
            vals = fn(self, m, idx)
            if magnitude:
                total += abs(m.modulus) * float(np.sum(np.abs(vals)))
                continue
            if sign is not None:
                vals = vals * sign
            total += m.modulus * float(np.sum(vals))
        return abs(q.modulus) * total if magnitude else q.modulus * total

    def volume_magnitudes(self):
        """Per body, the sum of absolute element contributions to its volume:
        facet contents and edge CONTENT integrals, shape (nbodies,)."""
        s = self.surface
        b = s.bodies
        per_facet = np.abs(self.facet_volume)
        if self.con_content is not None:
            idx, _ = G.edge_index(s.FE)
            per_facet = per_facet + np.abs(self.con_content)[idx].sum(axis=1)
        return abs(b.facet_matrix) @ per_facet


# ---------------------------------------------------------------------------
# building


class _Builder:
    def __init__(self, scene):
        self.sc = scene
        self.s = Surface()

    def error(self, msg, line=None):
        return DatafileError(msg, self.sc.filename, line)

    def build(self):
        sc, s = self.sc, self.s
        self._actual_volume = {}        # body position -> ACTUAL_VOLUME
        s.params = dict(sc.parameters)
        s.sdim = sc.space_dimension
        s.string = sc.string
        sd = int(sc.values.get("surface_dimension", 1 if s.string else 2))
        if sd not in (1, 2):
            raise self.error(f"not supported in pyevolver: SURFACE_DIMENSION {sd} "
                             f"(the simplex model)", sc.decl_lines.get("surface_dimension"))
        if s.sdim != 3 and not (s.string and s.sdim == 2):
            raise self.error(f"not supported in pyevolver: SPACE_DIMENSION {s.sdim} "
                             f"(3, or 2 in the string model)",
                             sc.decl_lines.get("space_dimension"))
        if s.string and sc.torus and s.sdim != 2:
            raise self.error("not supported in pyevolver: TORUS in a 3-dimensional string model",
                             sc.decl_lines.get("torus", sc.decl_lines.get("torus_filled")))
        s.constraints = dict(sc.constraints)
        s.boundaries = dict(sc.boundaries)
        s.symmetric_content = "symmetric_content" in sc.flags
        s.torus_filled = "torus_filled" in sc.flags
        s.gravity_constant = sc.values.get("gravity_constant", 1.0)
        s.gap_constant = sc.values.get("gap_constant", 1.0)
        s.sq_curvature_modulus = float(sc.values.get("squared_curvature", 0.0))
        if sc.torus:
            vals = sc.values.get("_periods")
            sd = s.sdim
            P = np.eye(3)
            if vals is not None:            # a 2-d torus keeps z out of its cell
                P[:sd, :sd] = np.array(vals).reshape(sd, sd)
            s.periods = P
        self._vertices()
        self._project()         # REF projects the vertices as read: face centres use them
        self._edges()
        self._faces()
        self._bodies()
        self._quantities()
        self._project()
        if s.nf:
            record_edge_first_facet(s, first_facets_on_load(s.FE, self.facet_parent, s.ne))
        if self._actual_volume:
            # ACTUAL_VOLUME a: volconst is set so that the body's volume is a
            vols = s.evaluate().volumes
            for pos, a in self._actual_volume.items():
                s.bodies.volconst[pos] += a - vols[pos]
        return s

    def _constraint_ids(self, vals, what, blk, pos):
        """``(id, orientation sign)`` of the constraints named on an element."""
        out = []
        for c in vals:
            cid = int(abs(c))
            if cid not in self.sc.constraints:
                raise self.error(f"{what} {blk.ids[pos]}: constraint {cid} is not defined",
                                 blk.lines[pos])
            out.append((cid, -1 if c < 0 else 1))
        return out

    # -- vertices -----------------------------------------------------------
    def _vertices(self):
        sc, s = self.sc, self.s
        blk = sc.vertices
        n = len(blk.ids)
        self.vid = _IdMap(blk.ids, "vertex", sc.filename, blk.lines)
        X = np.zeros((n, 3))
        sd = s.sdim                 # 2-d surfaces keep a zero z column
        fixed = np.zeros(n, bool)
        bnd = None
        params = None
        table = isinstance(blk.data, np.ndarray)
        if table:
            if blk.data.shape[1] != sd:
                raise self.error(f"vertex {blk.ids[0]}: expected {sd} coordinates, got "
                                 f"{blk.data.shape[1]}", blk.lines[0])
            X[:, :sd] = blk.data
            simple = range(n)
        else:
            simple = [k for k, d in enumerate(blk.data) if len(d) == sd]
            if len(simple) == n and n:
                X[:, :sd] = np.array(blk.data, dtype=float)
        for pos, attrs in blk.attrs.items():
            for kw, vals in attrs:
                if kw == "fixed":
                    fixed[pos] = True
                elif kw in ("constraint", "constraints"):
                    for cid, sign in self._constraint_ids(vals, "vertex", blk, pos):
                        s.vcon.setdefault(cid, np.zeros(n, bool))[pos] = True
                elif kw == "boundary":
                    bid = int(vals[0]) if vals else 0
                    if bid not in sc.boundaries:
                        raise self.error(f"vertex {blk.ids[pos]}: boundary {bid} is not defined",
                                         blk.lines[pos])
                    if bnd is None:
                        bnd = np.zeros(n, np.int64)
                        params = np.zeros((n, max(b.nparams for b in sc.boundaries.values())))
                    bnd[pos] = bid
                elif kw == "quantity":
                    self._member("vertex", pos, vals)
                elif kw == "attribute":
                    self._attr("vertex", n, pos, vals)
                elif kw in ("bare", "original", "tag", "axial_point", "triple_point",
                            "tetra_point", "no_hessian_normal", "hessian_normal_one"):
                    pass
                else:
                    raise self.error(f"vertex {blk.ids[pos]}: '{kw}' is not a vertex attribute",
                                     blk.lines[pos])
        for pos, d in enumerate(() if table else blk.data):
            if bnd is not None and bnd[pos]:
                b = sc.boundaries[bnd[pos]]
                if len(d) != b.nparams:
                    raise self.error(f"vertex {blk.ids[pos]}: boundary {b.id} needs "
                                     f"{b.nparams} parameter(s), got {len(d)}", blk.lines[pos])
                params[pos, :len(d)] = d
            elif len(d) != sd:
                raise self.error(f"vertex {blk.ids[pos]}: expected {sd} coordinates, got "
                                 f"{len(d)}", blk.lines[pos])
            elif len(simple) != n:
                X[pos, :sd] = d
        for cid, c in sc.constraints.items():
            if "global" in c.flags:
                s.vcon[cid] = np.ones(n, bool)
        s.X = X
        s.vattr["fixed"] = fixed
        s.vattr["original"] = self._originals(blk)
        if bnd is not None:
            s.vattr["boundary"] = bnd
            s.vattr["params"] = params
            self._boundary_coords(np.nonzero(bnd)[0])

    def _signed_refs(self, blk, flat, owner, idmap, what, target):
        """Indices of the signed ``target`` ids ``flat`` listed on the lines
        of ``blk`` (``owner`` = line of each id); id 0 is an error."""
        if np.any(flat == 0):
            k = owner[np.nonzero(flat == 0)[0][0]]
            raise self.error(f"{what} {blk.ids[k]}: {target} id 0 does not exist", blk.lines[k])
        return idmap.lookup(np.abs(flat), _Lazy(lambda j: blk.lines[owner[j]]), what,
                            _Lazy(lambda j: blk.ids[owner[j]]))

    def _boundary_coords(self, idx):
        s = self.s
        for bid, b in s.boundaries.items():
            sel = idx[s.vattr["boundary"][idx] == bid]
            if not len(sel):
                continue
            P = s.vattr["params"][sel]
            env = {f"p{k + 1}": P[:, k] for k in range(b.nparams)}
            for k, f in enumerate(b.coords[:3]):
                with located(f"boundary {bid}", b.line):
                    s.X[sel, k] = f.values(s.param_env(), env, len(sel))
            bad = ~np.all(np.isfinite(s.X[sel]), axis=1)
            if bad.any():
                pos = sel[np.nonzero(bad)[0][0]]
                blk = self.sc.vertices
                raise self.error(f"vertex {blk.ids[pos]}: its position on boundary {bid} is "
                                 f"not finite", blk.lines[pos])

    # -- edges ----------------------------------------------------------------
    def _edges(self):
        sc, s = self.sc, self.s
        blk = sc.edges
        n = len(blk.ids)
        self.eid = _IdMap(blk.ids, "edge", sc.filename, blk.lines)
        E = np.zeros((n, 2), np.int64)
        if isinstance(blk.data, np.ndarray):
            bad = [0] if blk.data.shape[1] != 2 else []
        else:
            bad = [k for k, d in enumerate(blk.data) if len(d) != 2]
        if bad:
            k = bad[0]
            raise self.error(f"edge {blk.ids[k]}: expected two vertex ids, got "
                             f"{len(blk.data[k])}", blk.lines[k])
        if n:
            raw = np.array(blk.data, dtype=np.int64)
            E[:] = self.vid.lookup(raw, blk.lines, "edge", blk.ids)
        fixed = np.zeros(n, bool)
        tension = np.ones(n) if s.string else None     # string edges: tension 1
        bnd = None
        no_refine = np.zeros(n, bool)
        for pos, attrs in blk.attrs.items():
            for kw, vals in attrs:
                if kw == "fixed":
                    fixed[pos] = True
                elif kw in ("constraint", "constraints"):
                    for cid, sign in self._constraint_ids(vals, "edge", blk, pos):
                        s.econ.setdefault(cid, np.zeros(n, np.int8))[pos] = sign
                elif kw == "boundary":
                    bid = int(vals[0]) if vals else 0
                    if bid not in sc.boundaries:
                        raise self.error(f"edge {blk.ids[pos]}: boundary {bid} is not defined",
                                         blk.lines[pos])
                    if bnd is None:
                        bnd = np.zeros(n, np.int64)
                    bnd[pos] = bid
                elif kw in ("tension", "density"):
                    if tension is None:
                        tension = np.zeros(n)
                    tension[pos] = vals[0]
                elif kw == "no_refine":
                    no_refine[pos] = True
                elif kw in ("color", "colour"):
                    s.eattr.setdefault("color", np.zeros(n, np.int64))[pos] = int(vals[0])
                elif kw == "quantity":
                    self._member("edge", pos, vals)
                elif kw == "attribute":
                    self._attr("edge", n, pos, vals)
                elif kw == "orientation" and vals and vals[0] < 0:
                    raise self.error(f"edge {blk.ids[pos]}: not supported in pyevolver: "
                                     "ORIENTATION -1 (an edge's oriented integrals reversed)",
                                     blk.lines[pos])
                elif kw in ("bare", "original", "orientation"):
                    pass
                elif kw == "wrap":
                    raise self.error(f"edge {blk.ids[pos]}: not supported in pyevolver: WRAP "
                                     "(symmetry groups are not implemented)", blk.lines[pos])
                else:
                    raise self.error(f"edge {blk.ids[pos]}: '{kw}' is not an edge attribute",
                                     blk.lines[pos])
        s.E = E
        s.eattr["fixed"] = fixed
        s.eattr["no_refine"] = no_refine
        s.eattr["original"] = self._originals(blk)
        if tension is not None:
            s.eattr["tension"] = tension
        if bnd is not None:
            s.eattr["boundary"] = bnd
        if s.periods is not None:
            w = np.zeros((n, 3))
            for pos, wr in sc.wraps.items():
                w[pos, :len(wr)] = wr
            s.eattr["wrap"] = w
        for cid, c in sc.constraints.items():
            if "global" in c.flags:
                s.econ[cid] = np.ones(n, np.int8)

    # -- faces ------------------------------------------------------------------
    def _faces(self):
        sc, s = self.sc, self.s
        blk = sc.faces
        nface = len(blk.ids)
        self.fid = _IdMap(blk.ids, "face", sc.filename, blk.lines)
        if s.string:
            return self._string_faces()
        ne0 = s.ne
        fixed, tension, no_refine, colors, fcon, fbnd = self._face_attributes(blk, nface)
        # validate edge loops
        E = s.E
        table = isinstance(blk.data, np.ndarray)
        if table:
            lengths = np.full(nface, blk.data.shape[1], dtype=np.int64)
        else:
            lengths = np.array([len(d) for d in blk.data], dtype=np.int64)
        if nface:
            short = np.nonzero(lengths < 3)[0]
            if len(short):
                k = short[0]
                raise self.error(f"face {blk.ids[k]}: a facet needs at least 3 edges, got "
                                 f"{lengths[k]}", blk.lines[k])
            if table:
                flat = blk.data.astype(np.int64).ravel()
            else:
                flat = np.fromiter((e for d in blk.data for e in d), np.int64,
                                   int(lengths.sum()))
            owner = np.repeat(np.arange(nface), lengths)
            eidx = self._signed_refs(blk, flat, owner, self.eid, "face", "edge")
            rev = flat < 0
            tails = np.where(rev, E[eidx, 1], E[eidx, 0])
            heads = np.where(rev, E[eidx, 0], E[eidx, 1])
            starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
            nxt = np.arange(len(flat)) + 1
            ends = starts + lengths - 1
            nxt[ends] = starts
            badloop = np.nonzero(heads != tails[nxt])[0]
            if len(badloop):
                j = badloop[0]
                k = owner[j]
                raise self.error(
                    f"face {blk.ids[k]}: the edge loop is not closed: edge {flat[j]} ends at "
                    f"vertex {s.vattr['original'][heads[j]]} but the next edge "
                    f"{flat[nxt[j]]} starts at vertex {s.vattr['original'][tails[nxt[j]]]}",
                    blk.lines[k])
            enc = np.where(rev, ~eidx, eidx)
        else:
            enc = np.zeros(0, np.int64)
            starts = lengths = np.zeros(0, np.int64)
            tails = np.zeros(0, np.int64)
        # triangulate
        FE = np.zeros((nface, 3), np.int64)
        tri3 = lengths == 3
        if nface:
            st = starts[tri3]
            FE[tri3] = np.stack([enc[st], enc[st + 1], enc[st + 2]], axis=1)
        big = np.nonzero(~tri3)[0]
        new_X = []
        new_E = []
        new_F = []            # (FE row, parent face position)
        self.split_children = {}     # face position -> its triangles (faces split on load)
        nv = s.nv
        ne = ne0
        nf = nface
        center_parent = []
        spoke_parent = []
        for k in big:
            st, n = starts[k], lengths[k]
            loop = enc[st:st + n]
            rim = tails[st:st + n]
            c = nv + len(new_X)
            new_X.append(self._face_center(rim))
            center_parent.append(k)
            spokes = ne + np.arange(n)
            for j in range(n):
                new_E.append((rim[j], c))
                spoke_parent.append(k)
            ne += n
            kids = []
            for j in range(n):
                # the face keeps its id for the triangle on its last edge,
                # (in-spoke, edge, out-spoke); the others start with their
                # edge (the Evolver's `list facets` after loading cube.fe)
                if j == n - 1:
                    FE[k] = (~spokes[j], loop[j], spokes[(j + 1) % n])
                else:
                    new_F.append(((loop[j], spokes[(j + 1) % n], ~spokes[j]), k))
                    kids.append(nf)
                    nf += 1
            self.split_children[k] = [k] + kids
        if new_X:
            s.X = np.vstack([s.X, np.array(new_X)])
            s.E = np.vstack([s.E, np.array(new_E, dtype=np.int64)])
            FE = np.vstack([FE, np.array([r for r, _ in new_F], dtype=np.int64).reshape(-1, 3)])
        parent = np.concatenate([np.arange(nface), np.array([p for _, p in new_F], np.int64)])
        s.FE = FE
        self.facet_parent = parent
        # facet attributes
        s.fattr["fixed"] = fixed[parent]
        s.fattr["tension"] = tension[parent]
        s.fattr["no_refine"] = no_refine[parent]
        s.fattr["original"] = self._originals(blk)[parent] if nface else \
            np.zeros(0, np.int64)
        for key, arr in colors.items():
            s.fattr[key] = arr[parent]
        for cid, m in fcon.items():
            s.fcon[cid] = m[parent]
        if fbnd.any():
            s.fattr["boundary"] = fbnd[parent]
        # new vertices and edges inherit from their face
        cpar = np.array(center_parent, np.int64)
        spar = np.array(spoke_parent, np.int64)
        nnew_v = len(cpar)
        nnew_e = len(spar)
        if nnew_v:
            s.vattr["fixed"] = np.concatenate([s.vattr["fixed"], fixed[cpar]])
            s.vattr["original"] = np.concatenate([s.vattr["original"], np.zeros(nnew_v, np.int64)])
            for cid in list(s.vcon):
                add = fcon[cid][cpar] if cid in fcon else np.zeros(nnew_v, bool)
                if "global" in s.constraints[cid].flags:
                    add = np.ones(nnew_v, bool)
                s.vcon[cid] = np.concatenate([s.vcon[cid], add])
            for cid in fcon:
                if cid not in s.vcon:
                    s.vcon[cid] = np.concatenate([np.zeros(s.nv - nnew_v, bool), fcon[cid][cpar]])
            if "boundary" in s.vattr:
                if fbnd[cpar].any():
                    k = int(cpar[np.nonzero(fbnd[cpar])[0][0]])
                    raise self.error(f"face {blk.ids[k]}: not supported in pyevolver: BOUNDARY "
                                     f"on a face with more than 3 edges", blk.lines[k])
                s.vattr["boundary"] = np.concatenate([s.vattr["boundary"], np.zeros(nnew_v, np.int64)])
                s.vattr["params"] = np.vstack([s.vattr["params"],
                                               np.zeros((nnew_v, s.vattr["params"].shape[1]))])
            for key in list(s.extra):
                if key[0] == "vertex":
                    arr = s.extra[key]
                    s.extra[key] = np.concatenate([arr, np.zeros((nnew_v,) + arr.shape[1:])])
        if nnew_e:
            s.eattr["fixed"] = np.concatenate([s.eattr["fixed"], fixed[spar]])
            s.eattr["no_refine"] = np.concatenate([s.eattr["no_refine"], no_refine[spar]])
            s.eattr["original"] = np.concatenate([s.eattr["original"], np.zeros(nnew_e, np.int64)])
            if "tension" in s.eattr:
                s.eattr["tension"] = np.concatenate([s.eattr["tension"], np.zeros(nnew_e)])
            if "color" in s.eattr:
                s.eattr["color"] = np.concatenate([s.eattr["color"], np.zeros(nnew_e, np.int64)])
            if "boundary" in s.eattr or fbnd.any():
                eb = s.eattr.get("boundary", np.zeros(ne0, np.int64))
                s.eattr["boundary"] = np.concatenate([eb, fbnd[spar]])
            if "wrap" in s.eattr:
                s.eattr["wrap"] = np.vstack([s.eattr["wrap"], np.zeros((nnew_e, 3))])
            for cid in list(s.econ):
                add = fcon[cid][spar].astype(np.int8) if cid in fcon else np.zeros(nnew_e, np.int8)
                if "global" in s.constraints[cid].flags:
                    add = np.ones(nnew_e, np.int8)
                s.econ[cid] = np.concatenate([s.econ[cid], add])
            for cid in fcon:
                if cid not in s.econ:
                    s.econ[cid] = np.concatenate([np.zeros(ne0, np.int8),
                                                  fcon[cid][spar].astype(np.int8)])
            for key in list(s.extra):
                if key[0] == "edge":
                    arr = s.extra[key]
                    s.extra[key] = np.concatenate([arr, np.zeros((nnew_e,) + arr.shape[1:])])
        for key in list(s.extra):
            if key[0] == "facet":
                s.extra[key] = s.extra[key][parent]
        if s.periods is not None and nnew_v:
            self._torus_centers(big, starts, lengths, enc, nface)
        if nnew_v:
            # the mean of huge (finite) coordinates or periods can overflow
            bad = np.nonzero(~np.all(np.isfinite(s.X[nv:]), axis=1))[0]
            if len(bad):
                k = cpar[bad[0]]
                raise self.error(f"face {blk.ids[k]}: the centre of the face is not finite "
                                 f"(its coordinates or the PERIODS are too large)",
                                 blk.lines[k])

    def _face_attributes(self, blk, nface, string=False):
        """The faces' attributes: ``(fixed, tension, no_refine, colors,
        constraints, boundaries)``, arrays over the faces (constraints a dict
        id → mask; the string model has no facet constraints, boundaries or
        quantities, and its facets no default tension)."""
        sc = self.sc
        fixed = np.zeros(nface, bool)
        tension = np.zeros(nface) if string else np.ones(nface)
        no_refine = np.zeros(nface, bool)
        fcon = {}
        fbnd = np.zeros(nface, np.int64)
        colors = {}
        where = " in the string model" if string else ""
        for pos, attrs in blk.attrs.items():
            for kw, vals in attrs:
                if kw == "fixed":
                    fixed[pos] = True
                elif kw in ("tension", "density"):
                    tension[pos] = vals[0]
                elif kw == "no_refine":
                    no_refine[pos] = True
                elif kw in ("color", "colour", "frontcolor", "frontcolour", "backcolor",
                            "backcolour"):
                    key = kw.replace("colour", "color")
                    colors.setdefault(key, np.zeros(nface, np.int64))[pos] = int(vals[0])
                elif kw == "attribute":
                    self._attr("facet", nface, pos, vals)
                elif kw == "phase":
                    raise self.error(f"face {blk.ids[pos]}: not supported in pyevolver: PHASE "
                                     "(phases need a PHASEFILE, which is not implemented)",
                                     blk.lines[pos])
                elif kw in ("nodisplay", "no_display", "opacity", "original", "tag"):
                    pass
                elif kw == "quantity" and string:
                    raise self.error(f"face {blk.ids[pos]}: not supported in pyevolver: "
                                     f"facet quantities in the string model", blk.lines[pos])
                elif kw == "quantity":
                    self._member("facet", pos, vals)
                elif kw in ("constraint", "constraints") and not string:
                    for cid, sign in self._constraint_ids(vals, "face", blk, pos):
                        fcon.setdefault(cid, np.zeros(nface, bool))[pos] = True
                elif kw == "boundary" and not string:
                    bid = int(vals[0])
                    if bid not in sc.boundaries:
                        raise self.error(f"face {blk.ids[pos]}: boundary {bid} is not defined",
                                         blk.lines[pos])
                    fbnd[pos] = bid
                else:
                    raise self.error(f"face {blk.ids[pos]}: '{kw}' is not a facet "
                                     f"attribute{where}", blk.lines[pos])
        return fixed, tension, no_refine, colors, fcon, fbnd

    def _string_faces(self):
        """String model: a facet is a chain of edges, open or closed, kept as
        it is (no triangulation)."""
        sc, s = self.sc, self.s
        blk = sc.faces
        nface = len(blk.ids)
        fixed, tension, no_refine, colors, _, _ = self._face_attributes(blk, nface, string=True)
        if isinstance(blk.data, np.ndarray):
            lengths = np.full(nface, blk.data.shape[1], dtype=np.int64)
            flat = blk.data.astype(np.int64).ravel()
        else:
            lengths = np.array([len(d) for d in blk.data], dtype=np.int64)
            flat = np.fromiter((e for d in blk.data for e in d), np.int64, int(lengths.sum()))
        empty = np.nonzero(lengths < 1)[0]
        if len(empty):
            k = empty[0]
            raise self.error(f"face {blk.ids[k]}: a facet needs at least one edge",
                             blk.lines[k])
        owner = np.repeat(np.arange(nface), lengths)
        eidx = self._signed_refs(blk, flat, owner, self.eid, "face", "edge")
        rev = flat < 0
        tails = np.where(rev, s.E[eidx, 1], s.E[eidx, 0])
        heads = np.where(rev, s.E[eidx, 0], s.E[eidx, 1])
        ends = np.cumsum(lengths) - 1
        inner = np.ones(len(flat), bool)
        inner[ends] = False
        j = np.nonzero(inner & (heads != np.roll(tails, -1)))[0]
        if len(j):
            j = j[0]
            k = owner[j]
            orig = s.vattr["original"]
            raise self.error(
                f"face {blk.ids[k]}: the edges do not form a chain: edge {flat[j]} ends at "
                f"vertex {orig[heads[j]]} but the next edge {flat[j + 1]} starts at vertex "
                f"{orig[tails[j + 1]]}", blk.lines[k])
        s.sf_ptr = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
        from .string import init_rings
        init_rings(s)
        s.sf_enc = np.where(rev, ~eidx, eidx).astype(np.int64)
        self.split_children = {}
        self.facet_parent = np.arange(nface)
        s.fattr["fixed"] = fixed
        s.fattr["tension"] = tension
        s.fattr["no_refine"] = no_refine
        s.fattr["original"] = self._originals(blk)
        for key, arr in colors.items():
            s.fattr[key] = arr

    def children(self, pos):
        return self.split_children.get(pos, [pos])

    @staticmethod
    def _originals(blk):
        """The ``original`` attribute of a section's elements: the datafile
        id, or the value of an ``original N`` keyword (the Evolver's dump
        writes it for elements made by refining element N)."""
        orig = np.asarray(blk.ids, dtype=np.int64).copy()
        for pos, attrs in blk.attrs.items():
            for kw, vals in attrs:
                if kw == "original" and vals:
                    orig[pos] = int(vals[0])
        return orig

    def _face_center(self, rim):
        return self.s.X[rim].mean(axis=0)

    def _torus_centers(self, big, starts, lengths, enc, nface):
        """Torus: the centre is the mean of the unwrapped rim; spokes get wraps."""
        s = self.s
        P = s.periods
        wrap = s.eattr["wrap"]
        nv0 = s.nv - len(big)
        ne_spoke = s.ne - int(lengths[big].sum())
        for j, k in enumerate(big):
            st, n = starts[k], lengths[k]
            loop = enc[st:st + n]
            idx, sgn = G.edge_index(loop)
            # unwrapped offsets (in periods) of rim vertices relative to the first
            offs = np.zeros((n, 3))
            for m in range(1, n):
                offs[m] = offs[m - 1] + wrap[idx[m - 1]] * sgn[m - 1]
            rim = np.where(sgn > 0, s.E[idx, 0], s.E[idx, 1])
            pts = s.X[rim] + offs @ P
            c = nv0 + j
            s.X[c] = pts.mean(axis=0)
            for m in range(n):
                e = ne_spoke + m
                # spoke from rim m (at offset offs[m]) to centre (offset 0)
                wrap[e] = -offs[m]
            ne_spoke += n

    # -- bodies -------------------------------------------------------------------
    def _bodies(self):
        sc, s = self.sc, self.s
        blk = sc.bodies
        nb = len(blk.ids)
        b = s.bodies
        b.n = nb
        b.target = np.full(nb, np.nan)
        b.volconst = np.zeros(nb)
        b.pressure = np.full(nb, np.nan)
        b.density = np.zeros(nb)
        b.lagrange = np.zeros(nb)
        b.original = self._originals(blk)
        lens = [len(d) for d in blk.data]
        flat = np.concatenate([np.asarray(d, dtype=np.int64) for d in blk.data]) if nb else \
            np.zeros(0, np.int64)
        owner = np.repeat(np.arange(nb), lens)
        pos = self._signed_refs(blk, flat, owner, self.fid, "body", "facet")
        sign = np.where(flat > 0, 1.0, -1.0)
        # faces split on load contribute all their triangles
        if self.split_children:
            nkids = np.ones(len(self.facet_parent), np.int64)
            for p, kids in self.split_children.items():
                nkids[p] = len(kids)
            # each listed face first, in the order given, then the triangles
            # split off faces, in facet order (REF's `list bodies`)
            reps = nkids[pos] - 1
            kids = np.concatenate([self.children(p)[1:] for p in pos]) if len(pos) else pos
            krows = np.repeat(owner, reps)
            kvals = np.repeat(sign, reps)
            korder = np.lexsort((-kvals, krows, kids))
            rows = np.concatenate([owner, krows[korder]])
            cols = np.concatenate([pos, kids[korder]])
            vals = np.concatenate([sign, kvals[korder]])
        else:
            rows, cols, vals = owner, pos, sign
        for pos, attrs in blk.attrs.items():
            for kw, v in attrs:
                if kw == "volume":
                    b.target[pos] = v[0]
                elif kw == "volconst":
                    b.volconst[pos] = v[0]
                elif kw == "pressure":
                    b.pressure[pos] = v[0]
                elif kw == "density":
                    b.density[pos] = v[0]
                elif kw == "actual_volume":
                    self._actual_volume[pos] = v[0]
                elif kw == "lagrange_multiplier":
                    b.lagrange[pos] = v[0]      # the pressure REF reports until the next step
                elif kw in ("centerofmass", "original"):
                    pass        # centerofmass is a display flag; original above
                elif kw == "attribute":
                    self._attr("body", nb, pos, v)
                elif kw == "phase":
                    raise self.error(f"body {blk.ids[pos]}: not supported in pyevolver: PHASE "
                                     "(phases need a PHASEFILE, which is not implemented)",
                                     blk.lines[pos])
                else:
                    raise self.error(f"body {blk.ids[pos]}: '{kw}' is not a body attribute",
                                     blk.lines[pos])
            kws = [kw for kw, _ in attrs]
            if "volume" in kws and "pressure" in kws:
                raise self.error(f"body {blk.ids[pos]}: VOLUME and PRESSURE exclude each other",
                                 blk.lines[pos])
        b.facet_matrix = sp.csr_matrix((vals, (rows, cols)), shape=(nb, s.n_facets))
        b.occurrences = (np.asarray(rows, np.int64), np.asarray(cols, np.int64),
                         np.asarray(vals, float))
        b.volume = None

    # -- quantities -----------------------------------------------------------------
    def _member(self, etype, pos, vals):
        name, sign = vals
        self.members = getattr(self, "members", {})
        self.members.setdefault((name, etype), []).append((pos, sign))

    def _attr_array(self, etype, name, n, size):
        """Zeros for an element attribute, refused when absurdly large."""
        if n * size > MAX_ARRAY_ENTRIES:
            raise self.error(f"attribute {name}: {n} {etype}s times {size} entries is more "
                             f"than the {MAX_ARRAY_ENTRIES} allowed")
        return np.zeros(n if size == 1 else (n, size))

    def _attr(self, etype, n, pos, vals):
        name = vals[0]
        atype, size, dims = self.sc.attributes[(etype, name)]
        key = (etype, name)
        if key not in self.s.extra:
            self.s.extra[key] = self._attr_array(etype, name, n, size)
        arr = self.s.extra[key]
        v = vals[1:]
        if size == 1:
            arr[pos] = v[0] if v else 0.0
        else:
            arr[pos, :len(v)] = v

    def _quantities(self):
        sc, s = self.sc, self.s
        members = getattr(self, "members", {})
        for name, m in sc.method_instances.items():
            # a method instance: a quantity of its own (kind "instance": no
            # energy, no constraint, not listed by v) whose value FUNCTION
            # quantities read as ``name.value``
            try:
                etype, _ = method_info(m.method)
            except UnsupportedError as exc:
                raise self.error(f"method_instance {name}: {exc}", m.line) from None
            if s.string:
                from .string import STRING_METHODS
                if m.method not in STRING_METHODS:
                    raise self.error(f"method_instance {name}: not supported in pyevolver: method "
                                     f"{m.method} in the string model", m.line)
            self._check_integrand(m, f"method_instance {name}", m.line)
            self._check_string_method(m, f"method_instance {name}", m.line)
            q = Quantity(name, "instance", line=m.line)
            q.methods.append(self._instance(m, etype, members.get((name, etype), [])))
            s.quantities[name] = q
        for name, qd in sc.quantities.items():
            q = Quantity(name, qd.kind, qd.target, qd.modulus, qd.tolerance, line=qd.line)
            q.pressure = qd.lagrange_multiplier      # a dump's multiplier, until the next step
            for m in qd.methods:
                try:
                    etype, _ = method_info(m.method)
                except UnsupportedError as exc:
                    raise self.error(f"quantity {name}: {exc}", qd.line) from None
                self._check_integrand(m, f"quantity {name}", qd.line)
                q.methods.append(self._instance(m, etype, members.get((name, etype), [])))
            for m in qd.methods:
                self._check_string_method(m, f"quantity {name}", qd.line)
            if qd.function is not None:
                for v in qd.function.names():
                    inst = v[:-len(".value")] if v.endswith(".value") else None
                    if inst is None or inst not in sc.method_instances:
                        if v in sc.parameters:
                            continue
                        raise self.error(f"quantity {name}: FUNCTION uses {v!r}; expected "
                                         "method_instance values (name.value) and parameters",
                                         qd.line)
                from ..expr.nodes import Formula
                q.function = Formula(qd.function)
            s.quantities[name] = q
        # declared attributes that no element set still exist
        for (etype, name), (atype, size, dims) in sc.attributes.items():
            if (etype, name) not in s.extra:
                n = {"vertex": s.nv, "edge": s.ne, "facet": s.n_facets,
                     "body": s.bodies.n}[etype]
                s.extra[(etype, name)] = self._attr_array(etype, name, n, size)

    def _check_string_method(self, m, what, line):
        """The string model has its own methods (no facets)."""
        if self.s.string:
            from .string import STRING_METHODS
            if m.method not in STRING_METHODS:
                raise self.error(f"{what}: not supported in pyevolver: method {m.method} in "
                                 f"the string model", line)

    def _check_integrand(self, m, what, line):
        """The scalar integral methods need their SCALAR_INTEGRAND."""
        if m.method.endswith("_scalar_integral") and m.scalar is None:
            raise self.error(f"{what}: method {m.method} needs a SCALAR_INTEGRAND", line)

    def _instance(self, m, etype, mem):
        s = self.s
        n = {"vertex": s.nv, "edge": s.ne, "facet": s.nf}[etype]
        if m.is_global:
            return (m, etype, np.arange(n), None)
        idx, sgn = [], []
        for pos, sign in mem:
            kids = self.children(pos) if etype == "facet" else [pos]
            for kid in kids:
                idx.append(kid)
                sgn.append(float(sign))
        return (m, etype, np.array(idx, np.int64), np.array(sgn))

    # -- projection -------------------------------------------------------------------
    def _project(self):
        project_to_constraints(self.s, np.arange(self.s.nv))


def first_facets_on_load(FE, parent, ne):
    """(ne,) index of each edge's first facet, -1 where unknown.

    The Evolver keeps the facets round an edge in a cyclic loop that starts
    at the first face of the datafile listing the edge (checked with ``O`` on
    octa.fe and on single four-facet edges, where the loop start breaks ties
    between equal angles).  ``parent`` (nf,) is the datafile face position of
    each facet; an edge whose first face was split on load into several
    triangles containing it (a spoke) gets -1.
    """
    nf = len(FE)
    e = np.where(FE >= 0, FE, ~FE).ravel()
    f = np.repeat(np.arange(nf), 3)
    p = np.asarray(parent)[f]
    order = np.lexsort((f, p, e))
    e, f, p = e[order], f[order], p[order]
    head = np.ones(len(e), bool)
    head[1:] = e[1:] != e[:-1]
    first = np.full(ne, -1, np.int64)
    h = np.nonzero(head)[0]
    nxt = h + 1
    tie = (nxt < len(e)) & (e[np.minimum(nxt, len(e) - 1)] == e[h]) & \
        (p[np.minimum(nxt, len(e) - 1)] == p[h])
    first[e[h]] = np.where(tie, -1, f[h])
    return first


def record_edge_first_facet(s, first):
    """Attach the first facet of every edge's loop to ``s``, valid while its
    connectivity stays what it is now (any change to ``E`` or ``FE`` drops
    it; only the operations that know how the loop start moves keep it)."""
    s._edge_first = (s.FE.copy(), s.E.copy(), np.asarray(first, np.int64))


def edge_first_facet(s):
    """(ne,) first facet of each edge's loop (-1 unknown), or None when the
    connectivity changed since it was recorded."""
    c = s.__dict__.get("_edge_first")
    if c is None:
        return None
    FE, E, first = c
    if FE.shape != s.FE.shape or E.shape != s.E.shape or \
            not np.array_equal(FE, s.FE) or not np.array_equal(E, s.E):
        return None
    return first


def record_along_first(s, along):
    """Attach to ``s`` which edges have the facet running along them first
    in their facet loop (``along`` (ne,) bool), valid while its connectivity
    stays what it is now."""
    s._along_first = (s.FE.copy(), s.E.copy(), np.asarray(along, bool))


def along_first(s):
    """(ne,) bool: the facet running along the edge comes first in the
    edge's facet loop (REF's ``ee.facet`` order of a two-facet edge).

    Recorded by ``r`` (:func:`record_along_first`); on a loaded surface from
    :func:`edge_first_facet`; where neither is known, True (the facet along
    the edge first, as ``ee.facet`` lists it)."""
    c = s.__dict__.get("_along_first")
    if c is not None and c[0].shape == s.FE.shape and c[1].shape == s.E.shape and \
            np.array_equal(c[0], s.FE) and np.array_equal(c[1], s.E):
        return c[2].copy()
    out = np.ones(s.ne, bool)
    first = edge_first_facet(s)
    if first is None:
        return out
    idx, sgn, _ = s.topology()
    known = np.nonzero(first >= 0)[0]
    f = first[known]
    hit = idx[f] == known[:, None]
    out[known] = (sgn[f] * hit).sum(axis=1) >= 0
    return out


def record_vertex_rings(s, rank):
    """Attach REF's edge rings to ``s``: ``rank`` (ne, 2) is the position of
    each edge in the ring of its tail (column 0) and head (column 1) vertex
    (:func:`vertex_edge_rank`), valid while the edges stay what they are."""
    s._rings = (s.E.copy(), np.asarray(rank, np.int64))


def vertex_edge_rank(s):
    """(ne, 2) position of each edge in the edge ring of its tail (column 0)
    and head (column 1) vertex: REF's ``vv.edge`` order.

    The Evolver keeps the edges at a vertex in a cyclic list read from the
    vertex's first edge; a new edge goes in right after the first.  On a
    freshly loaded surface edges join in id order, so the list reads: the
    lowest-numbered edge, then the others newest first (as in the string
    model, ``string_model.init_rings``).  Rings recorded by an operation
    that knows how they change (:func:`record_vertex_rings`; ``r``) are used
    while the edges are unchanged, otherwise the freshly loaded order.
    """
    ne, nv = s.ne, s.nv
    c = s.__dict__.get("_rings")
    if c is not None and c[0].shape == s.E.shape and np.array_equal(c[0], s.E):
        return c[1]
    t = np.empty(ne, np.int64)
    t[np.argsort(s.ids("edge"), kind="stable")] = np.arange(ne)
    v = s.E.ravel()
    key = np.repeat(t, 2)
    first = np.full(nv, ne, np.int64)
    np.minimum.at(first, v, key)
    key = np.where(key == first[v], np.iinfo(np.int64).max, key)
    order = np.lexsort((-key, v))
    vs = v[order]
    start = np.searchsorted(vs, np.arange(nv))
    pos = np.empty(2 * ne, np.int64)
    pos[order] = np.arange(2 * ne) - start[vs]
    return pos.reshape(ne, 2)


def vertex_facet_rank(s):
    """(nf, 3) position of each facet in the facet order of its corner k:
    REF's ``vv.facet`` order, which its ``vertex_normal`` follows.

    Measured with evolver-nox-d (catbody.fe, column.fe after ``g 5; r``,
    boundary vertices included): the facets come in the ring order
    (:func:`vertex_edge_rank`) of the edge along which each leaves the
    vertex (facet side k leaves corner k).
    """
    idx, sgn, _ = s.topology()
    return vertex_edge_rank(s)[idx, np.where(sgn > 0, 0, 1)]


def convex_edges(s):
    """``[(constraint, edge indices)]`` of edges on CONVEX constraints (gap energy)."""
    out = []
    for cid, sign in s.econ.items():
        c = s.constraints[cid]
        idx = np.nonzero(sign)[0]
        if "convex" in c.flags and len(idx):
            out.append((c, idx))
    return out


def integral_edges(s, which):
    """Edges carrying ENERGY (``which="energy"``) or CONTENT integrands.

    Returns ``[(components, edge indices, signs), ...]``.  Constraint
    integrals skip FIXED edges (manual) and take the edge's constraint
    orientation; boundary content enters with the opposite sign (REF,
    checked on column.fe with its boundary edges reversed).
    """
    out = []
    efixed = s.eattr["fixed"]
    for cid, sign in s.econ.items():
        c = s.constraints[cid]
        comps = getattr(c, which)
        if comps is None:
            continue
        idx = np.nonzero((sign != 0) & ~efixed)[0]
        if len(idx):
            out.append((Integrand(comps, f"constraint {cid} {which}", getattr(c, "line", None)),
                        idx, sign[idx].astype(float)))
    eb = s.eattr.get("boundary")
    if eb is not None:
        for bid, b in s.boundaries.items():
            comps = getattr(b, which)
            if comps is None:
                continue
            idx = np.nonzero(eb == bid)[0]
            if len(idx):
                out.append((Integrand(comps, f"boundary {bid} {which}", getattr(b, "line", None)),
                            idx, np.full(len(idx), -1.0 if which == "content" else 1.0)))
    return out


class Integrand(tuple):
    """The components of a constraint's or boundary's ENERGY or CONTENT
    integrand (a tuple of formulas) with the name and source line of their
    declaration, for the messages of :func:`located`."""

    def __new__(cls, comps, what, line):
        self = super().__new__(cls, comps)
        self.what, self.line = what, line
        return self


class LocatedFormula:
    """A formula whose evaluation errors name its declaration ``what`` and
    source ``line`` (see :func:`located`)."""

    def __init__(self, formula, what, line):
        self.formula, self.what, self.line = formula, what, line

    def values(self, *args):
        with located(self.what, self.line):
            return self.formula.values(*args)

    def gradient(self, *args):
        with located(self.what, self.line):
            return self.formula.gradient(*args)


@contextlib.contextmanager
def located(what, line):
    """Give an error raised in the block without a source line the
    declaration ``what`` (e.g. ``"constraint 1"``) and its ``line``."""
    try:
        yield
    except PyEvolverError as exc:
        if getattr(exc, "line", None) is None and line:
            exc.line = line
            exc.args = (f"{what}: {exc}",)
        raise


def torus_lift_shifts(s):
    """Per body, the period shift of each facet that makes its facets a
    consistently lifted surface (so the divergence theorem gives its volume).

    Each facet is unwrapped from its first vertex; across every edge shared
    by two facets of a body the two lifts of the edge must coincide, which
    fixes the relative shift (a breadth-first walk over the body's facets).
    Depends on topology and wraps only, so it is cached.
    Returns ``(nb, nf, 3)`` shifts already multiplied by the body's facet sign.
    """
    key = (s.nf, s.ne, id(s.FE), id(s.eattr.get("wrap")))
    cache = getattr(s, "_lift_cache", None)
    if cache is not None and cache[0] == key:
        return cache[1]
    from collections import deque
    P = s.periods
    wrap = s.eattr["wrap"]
    idx, sgn = G.edge_index(s.FE)
    wv = wrap @ P                                   # (ne, 3)
    # offset of the tail of each oriented edge in the facet's own lift
    A = np.zeros((s.nf, 3, 3))
    A[:, 1] = wv[idx[:, 0]] * sgn[:, 0, None]
    A[:, 2] = A[:, 1] + wv[idx[:, 1]] * sgn[:, 1, None]
    # offset of the edge's own tail in the facet's lift
    O = A - np.where(sgn[..., None] < 0, wv[idx], 0.0)
    occ_b, occ_f, occ_s = s.bodies.occurrences
    ev = G.edge_vectors(s.X, s.E, wv)
    dvec = ev[idx] * sgn[..., None]                 # oriented edge vectors (nf, 3, 3)
    N2 = np.cross(dvec[:, 0], dvec[:, 0] + dvec[:, 1])
    out = np.zeros((s.bodies.n, s.nf, 3))
    for b in range(s.bodies.n):
        sel = np.nonzero(occ_b == b)[0]
        facets = occ_f[sel]
        signs = occ_s[sel]
        # occurrences by (edge, direction in which the body's side traverses it)
        by_edge = {}
        for o, (f, sg) in enumerate(zip(facets, signs)):
            for k in range(3):
                by_edge.setdefault((idx[f, k], sgn[f, k] * sg > 0), []).append((o, k))
        # pair the occurrences at every edge: going round the edge from a
        # facet towards the body's side, the next facet of the body met is
        # its partner (this separates a body's wall with its own image)
        partner = {}
        groups = {}
        for (e, d), lst in by_edge.items():
            groups.setdefault(e, []).extend(lst)
        for e, lst in groups.items():
            if len(lst) == 2:
                (o, k), (o2, j) = lst
                partner[(o, k)] = (o2, j)
                partner[(o2, j)] = (o, k)
                continue
            t = ev[e] / np.linalg.norm(ev[e])
            a = np.cross(t, [1.0, 0, 0] if abs(t[0]) < 0.9 else [0, 1.0, 0])
            a /= np.linalg.norm(a)
            bvec = np.cross(t, a)
            ang = []
            for o, k in lst:
                f = facets[o]
                w = -dvec[f, (k + 2) % 3]
                u = w - (w @ t) * t
                th = np.arctan2(u @ bvec, u @ a)
                side = -signs[o] * N2[f]
                rot = 1.0 if side @ np.cross(t, u) > 0 else -1.0
                ang.append((th, rot))
            for m, (o, k) in enumerate(lst):
                th, rot = ang[m]
                best, bestd = None, None
                for m2, (o2, j) in enumerate(lst):
                    if m2 == m or facets[o2] == facets[o] or ang[m2][1] != -rot:
                        continue
                    dth = ((ang[m2][0] - th) * rot) % (2 * np.pi)
                    if bestd is None or dth < bestd:
                        best, bestd = (o2, j), dth
                if best is not None:
                    partner[(o, k)] = best
        D = [None] * len(facets)
        for root in range(len(facets)):
            if D[root] is not None:
                continue
            D[root] = np.zeros(3)
            dq = deque([root])
            while dq:
                o = dq.popleft()
                f = facets[o]
                for k in range(3):
                    p = partner.get((o, k))
                    if p is None or D[p[0]] is not None:
                        continue
                    o2, j = p
                    D[o2] = D[o] + O[f, k] - O[facets[o2], j]
                    dq.append(o2)
        for o, (f, sg) in enumerate(zip(facets, signs)):
            out[b, f] += sg * D[o]
    s._lift_cache = (key, out)
    return out


def boundary_eval(s, bid, P):
    """Points and Jacobians of parametric boundary ``bid`` at parameters ``P``.

    Returns ``X`` (n, 3) and ``J`` (n, 3, k) with ``J[:, i, j] = ∂x_i/∂p_j``.
    """
    b = s.boundaries[bid]
    names = tuple(f"p{k + 1}" for k in range(b.nparams))
    env0 = s.param_env()
    P = P[:, :b.nparams]
    env = {nm: P[:, k] for k, nm in enumerate(names)}
    X = np.stack([f.values(env0, env, len(P)) for f in b.coords[:3]], axis=1)
    J = np.stack([f.gradient(env0, env, len(P), names) for f in b.coords[:3]], axis=1)
    return X, J


def boundary_groups(s, mask=None):
    """``(bid, rows)`` for each parametric boundary with vertices (among ``mask``)."""
    bnd = s.vattr.get("boundary")
    if bnd is None:
        return []
    out = []
    for bid in s.boundaries:
        sel = bnd == bid
        if mask is not None:
            sel &= mask
        rows = np.nonzero(sel)[0]
        if len(rows):
            out.append((bid, rows))
    return out


def solve_small(A, b):
    """Batched ``A[n]⁻¹ b[n]`` for small (k, k) systems; a singular system
    (a constraint gradient that vanishes, e.g. x² + y² = 1 at the origin)
    gets the least-squares solution instead of an error."""
    with np.errstate(all="ignore"):
        try:
            return np.linalg.solve(A, b[..., None])[..., 0]
        except np.linalg.LinAlgError:
            # (an infinite or NaN system, from a runaway vertex, would make
            # the SVD fail: it gets a zero matrix, hence a zero solution)
            bad = ~np.all(np.isfinite(A), axis=(1, 2))
            A = np.where(bad[:, None, None], 0.0, A)
            return np.einsum("nkl,nl->nk", np.linalg.pinv(A), b)


def state(s):
    """Snapshot of the coordinates (and boundary parameters) of ``s``."""
    P = s.vattr.get("params")
    return s.X.copy(), (None if P is None else P.copy())


def restore_state(s, st):
    s.X = st[0].copy()
    if st[1] is not None:
        s.vattr["params"] = st[1].copy()


def displace(s, base, dX):
    """Move the vertices of ``s`` from the snapshot ``base`` (see :func:`state`)
    by the spatial displacements ``dX`` (nv, 3).

    Vertices on a parametric boundary move in parameter space (spec §6.3):
    ``p = p0 + (JᵀJ)⁻¹ Jᵀ dx`` with ``J = ∂X/∂p`` at ``p0``, then
    ``x = X(p)``; the others move by ``dx``.
    """
    X0, P0 = base
    s.X = X0 + dX
    if P0 is None:
        return
    P = P0.copy()
    for bid, rows in boundary_groups(s):
        k = s.boundaries[bid].nparams
        _, J = boundary_eval(s, bid, P0[rows])
        JtJ = np.einsum("nik,nil->nkl", J, J)
        rhs = np.einsum("nik,ni->nk", J, dX[rows])
        with np.errstate(all="ignore"):
            dp = solve_small(JtJ, rhs)
        P[rows, :k] = P0[rows, :k] + np.nan_to_num(dp)
        s.X[rows], _ = boundary_eval(s, bid, P[rows])
    s.vattr["params"] = P


def project_tangent(s, vecs):
    """Project vectors onto the tangent spaces of the vertices' level-set
    constraints (all constraints of a vertex at once) and, for vertices on a
    parametric boundary, onto the boundary's tangent space (span of ∂X/∂p).

    Parameters
    ----------
    s : Surface
    vecs : list of (nv, 3) arrays

    Returns
    -------
    list of (nv, 3) arrays
        Copies with the components along the constraint gradients removed
        (the input list itself when no vertex is constrained).
    """
    groups = boundary_groups(s)
    if groups:
        vecs = [v.copy() for v in vecs]
        P = s.vattr["params"]
        for bid, rr in groups:
            _, J = boundary_eval(s, bid, P[rr])
            JtJ = np.einsum("nik,nil->nkl", J, J)
            for v in vecs:
                rhs = np.einsum("nik,ni->nk", J, v[rr])
                with np.errstate(all="ignore"):
                    c = solve_small(JtJ, rhs)
                v[rr] = np.einsum("nik,nk->ni", J, np.nan_to_num(c))
    if not s.vcon:
        return vecs
    cids = sorted(s.vcon)
    on = np.stack([s.vcon[c] for c in cids], axis=1)
    env = s.param_env()
    on = _hit_one_sided(s, cids, on, env)
    rows = np.nonzero(on.any(axis=1))[0]
    if not len(rows):
        return vecs
    keys, inv = np.unique(on[rows], axis=0, return_inverse=True)
    inv = inv.ravel()
    out = [v.copy() for v in vecs]
    for gi, key in enumerate(keys):
        rr = rows[inv == gi]
        coords = vertex_coords(s, rr)
        Gm = np.stack([s.constraints[c].formula.gradient(env, coords, len(rr))
                       for c, k in zip(cids, key) if k], axis=2)     # (n, 3, k)
        GtG = np.einsum("nik,nil->nkl", Gm, Gm)
        for v in out:
            w = v[rr]
            rhs = np.einsum("nik,ni->nk", Gm, w)
            lam = np.nan_to_num(solve_small(GtG, rhs))
            v[rr] = w - np.einsum("nik,nk->ni", Gm, lam)
    return out


def _hit_one_sided(s, cids, on, env, tol=1e-10, rows=None, violated=False, hold=None):
    """``on`` with one-sided (NONNEGATIVE / NONPOSITIVE) constraints kept only
    for the vertices that hit them (value 0 within ``tol``), or, with
    ``violated``, also those outside the allowed side: a vertex inside the
    allowed region moves freely (REF: the face centres of drop_afm.fe between
    its two one-sided plates move in z).  ``rows``: the vertices of the rows
    of ``on`` (default all)."""
    one = [j for j, c in enumerate(cids)
           if s.constraints[c].flags & {"nonnegative", "nonpositive"}]
    if not one:
        return on
    on = on.copy()
    for j in one:
        rr = np.nonzero(on[:, j])[0]
        if not len(rr):
            continue
        coords = vertex_coords(s, rr if rows is None else rows[rr])
        c = s.constraints[cids[j]]
        phi = np.broadcast_to(_constraint_formula(c, "values", env, coords, len(rr)), (len(rr),))
        keep = np.abs(phi) <= tol
        rel = getattr(s, "_one_sided_released", None)
        if rel and cids[j] in rel:      # hit, but leaving it this step
            keep &= ~np.isin(rr if rows is None else rows[rr], rel[cids[j]])
        if violated:
            keep |= (phi < 0) if "nonnegative" in c.flags else (phi > 0)
        if hold and cids[j] in hold:    # held on the constraint (see project_to_constraints)
            keep |= np.isin(rr if rows is None else rows[rr], hold[cids[j]])
        on[rr, j] = keep
    return on


def release_one_sided(s, force):
    """At the start of a step: the vertices that hit a one-sided constraint
    and whose force ``force`` (nv, 3) points into its allowed side leave it
    for this step (manual: "The 'g' iteration step will check for a vertex
    wanting to leave a one-sided constraint it has hit"); recorded in
    ``s._one_sided_released``."""
    s._one_sided_released = None
    if not s.vcon:
        return
    env = s.param_env()
    out = {}
    for c, mask in s.vcon.items():
        con = s.constraints[c]
        if not con.flags & {"nonnegative", "nonpositive"}:
            continue
        rr = np.nonzero(mask)[0]
        if not len(rr):
            continue
        coords = vertex_coords(s, rr)
        phi = np.broadcast_to(_constraint_formula(con, "values", env, coords, len(rr)),
                              (len(rr),))
        g = np.broadcast_to(_constraint_formula(con, "gradient", env, coords, len(rr)),
                            (len(rr), 3))
        into = np.einsum("ij,ij->i", np.asarray(force)[rr], g)
        if "nonpositive" in con.flags:
            into = -into
        leave = (np.abs(phi) <= 1e-10) & (into > 0)
        if leave.any():
            out[c] = rr[leave]
    s._one_sided_released = out or None


def vertex_coords(s, rows):
    """The names a level-set formula may use at the vertices ``rows``: the
    coordinates ``x, y, z`` and the vertex extra attributes (the manual:
    ``constraint 1 formula: z = zfix`` with a vertex attribute ``zfix``).

    Returns
    -------
    dict of str -> (n,) or (n, k) array
    """
    P = s.X[rows]
    out = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
    for (etype, name), arr in s.extra.items():
        if etype == "vertex" and name not in out:
            out[name] = arr[rows]
    return out


def constrained_vertices(s):
    """(nv,) bool: the vertices on at least one level-set constraint."""
    on = np.zeros(s.nv, bool)
    for m in (s.vcon or {}).values():
        on |= np.asarray(m, bool)
    return on


def project_to_constraints(s, idx, tol=None, maxit=20, _again=True, hold=None):
    """Newton-project the vertices ``idx`` onto their level-set constraints.

    Uses ``x <- x - G (G^T G)^{-1} phi(x)`` over the vertex's active
    constraints (spec §6.1).  One-sided constraints are projected only when
    violated (or hit, or held: ``hold`` maps a constraint to vertices kept on
    it; the constraints a call enforced are left in ``s._one_sided_hits``).  A vertex whose projection diverges (its coordinates or its
    constraint values become infinite or NaN, or it ends unconverged
    farther from its constraints than it started) is put back where it was.

    Returns
    -------
    ndarray of int
        The vertices put back (empty when every projection was finite).
    """
    failed = np.zeros(0, np.int64)
    if not s.vcon:
        return failed
    tol = tol if tol is not None else s.params.get("constraint_tolerance", 1e-12)
    cids = sorted(s.vcon)
    onmat = np.stack([s.vcon[c][idx] for c in cids], axis=1)
    env = s.param_env()
    full = onmat
    # one-sided constraints act on the vertices that violate or hit them
    onmat = _hit_one_sided(s, cids, onmat, env, rows=idx, violated=True, hold=hold)
    if _again:                      # the one-sided constraints this projection enforces
        s._one_sided_hits = {c: idx[onmat[:, j]] for j, c in enumerate(cids)
                             if s.constraints[c].flags & {"nonnegative", "nonpositive"}
                             and onmat[:, j].any()}
    anyon = np.nonzero(onmat.any(axis=1))[0]
    if not len(anyon):
        return failed
    ukeys, inv = np.unique(onmat[anyon], axis=0, return_inverse=True)
    inv = inv.ravel()
    for gi, key in enumerate(ukeys):
        sel = idx[anyon[inv == gi]]
        start = s.X[sel].copy()
        active = [c for c, on in zip(cids, key) if on]
        phi = phi0 = None
        for _ in range(maxit + 1):
            P = s.X[sel]
            coords = vertex_coords(s, sel)
            phis = []
            grads = []
            for cid in active:
                c = s.constraints[cid]
                # (a one-sided constraint here is violated, hit or held: an equality)
                phi = _constraint_formula(c, "values", env, coords, len(sel))
                phis.append(phi)
                grads.append(_constraint_formula(c, "gradient", env, coords, len(sel)))
            phi = np.stack(phis, axis=1)           # (n, k)
            if phi0 is None:
                phi0 = np.max(np.abs(phi), axis=1)
            if np.max(np.abs(phi)) < tol or _ == maxit:
                break
            Gm = np.stack(grads, axis=2)           # (n, 3, k)
            GtG = np.einsum("nik,nil->nkl", Gm, Gm)
            lam = solve_small(GtG, phi)
            with np.errstate(all="ignore"):
                step = np.einsum("nik,nk->ni", Gm, lam)
            step = np.where(np.isfinite(step), step, 0.0)
            s.X[sel] = P - step
        res = np.max(np.abs(phi), axis=1)
        bad = ~(np.all(np.isfinite(s.X[sel]), axis=1) & np.isfinite(res))
        # not converged and farther from the constraint than at the start: the
        # Newton iteration ran away (e.g. atan(z) = 0 from |z| > 1.39)
        bad |= (res > tol) & (res > phi0)
        if bad.any():
            s.X[sel[bad]] = start[bad]
            failed = np.concatenate([failed, sel[bad]])
    if _again and (full != onmat).any():
        # a one-sided constraint left out may be violated now: once more
        again = _hit_one_sided(s, cids, full, env, rows=idx, violated=True) & ~onmat
        redo = np.nonzero(again.any(axis=1))[0]
        if len(redo):
            failed = np.concatenate([failed, project_to_constraints(
                s, idx[redo], tol, maxit, _again=False)])
    return failed


class _Lazy:
    """Index-computed sequence (line numbers for error messages only)."""

    def __init__(self, fn):
        self.fn = fn

    def __getitem__(self, j):
        return self.fn(int(j))


class _IdMap:
    """Datafile ids -> positions (elements are renumbered in reading order)."""

    def __init__(self, ids, what, filename, lines):
        self.ids = np.asarray(ids, dtype=np.int64)
        self.what = what
        self.filename = filename
        order = np.argsort(self.ids, kind="stable")
        self.sorted = self.ids[order]
        self.order = order
        dup = np.nonzero(self.sorted[1:] == self.sorted[:-1])[0]
        if len(dup):
            k = order[dup[0] + 1]
            raise DatafileError(f"{what} {self.ids[k]} is defined twice", filename, lines[k])

    def lookup(self, raw, lines, user, user_ids):
        raw = np.asarray(raw, dtype=np.int64)
        if not len(self.sorted):
            if raw.size:
                raise DatafileError(f"{user} {user_ids[0]} refers to {self.what} "
                                    f"{int(raw.flat[0])}, but there are no {self.what}s",
                                    self.filename, lines[0])
            return raw
        pos = np.searchsorted(self.sorted, raw)
        pos_c = np.minimum(pos, len(self.sorted) - 1)
        ok = self.sorted[pos_c] == raw
        if not ok.all():
            flat = np.nonzero(~ok.reshape(len(ok), -1).all(axis=-1) if ok.ndim > 1 else ~ok)[0][0]
            bad = raw[flat]
            bad = int(np.asarray(bad).flat[np.nonzero(~np.asarray(ok[flat]).reshape(-1))[0][0]]) \
                if np.ndim(bad) else int(bad)
            raise DatafileError(f"{user} {user_ids[flat]} refers to {self.what} {bad}, "
                                f"which is not defined", self.filename, lines[flat])
        return self.order[pos_c]


def build_surface(scene):
    """Build a :class:`Surface` from a :class:`Scene` (datafile errors located)."""
    try:
        return _Builder(scene).build()
    except DatafileError as exc:
        lines = scene.source_lines
        if exc.excerpt is None and exc.line and lines and 0 < exc.line <= len(lines):
            raise DatafileError(exc.message, exc.filename, exc.line, exc.column,
                                lines[exc.line - 1]) from None
        raise
    except PyEvolverError as exc:
        # an expression that fails while the surface is built (a constraint
        # formula dividing by zero in the projection): at the declaration
        # when known
        line = getattr(exc, "line", None)
        lines = scene.source_lines
        raise DatafileError(str(exc), scene.filename, line, None,
                            lines[line - 1] if line and lines and line <= len(lines)
                            else None) from None


def _constraint_formula(c, what, *args):
    """``c.formula.values(...)`` or ``.gradient(...)``; an error names the
    constraint and its line."""
    with located(f"constraint {c.id}", getattr(c, "line", None)):
        return getattr(c.formula, what)(*args)
