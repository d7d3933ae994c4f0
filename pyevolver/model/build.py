"""Building a :class:`~pyevolver.model.surface.Surface` from a parsed
:class:`~pyevolver.model.scene.Scene` (datafile ids renumbered, faces
triangulated, bodies and quantities set up, vertices projected)."""
from __future__ import annotations

import numpy as np
from .facet_csr import canonical_csr

from ..errors import DatafileError, PyEvolverError, UnsupportedError
from ..expr.nodes import CONSTANTS, Formula
from ..limits import MAX_ARRAY_ENTRIES
from ..memory import loading
from .formulas import located
from .ids import IdMap, Lazy, split_midpoints
from .metric import metric_of
from .records import first_facets_on_load, record_edge_first_facet
from .scene import Scene
from . import simplex as SX
from . import symmetry
from .string import STRING_METHODS, init_rings
from .surface import HOOKS, Quantity, Surface


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
        s.sdim_line = sc.decl_lines.get("space_dimension")
        s.string = sc.string
        sd = int(sc.values.get("surface_dimension", 1 if s.string else 2))
        if sd not in (1, 2):
            raise self.error(f"not supported in pyevolver: SURFACE_DIMENSION {sd} "
                             f"(the simplex model)", sc.decl_lines.get("surface_dimension"))
        if s.sdim < 3 and not (s.string and s.sdim == 2) or s.sdim > 3 and s.string:
            raise self.error(f"not supported in pyevolver: SPACE_DIMENSION {s.sdim} "
                             f"(3, or 2 in the string model)",
                             sc.decl_lines.get("space_dimension"))
        if s.sdim > 3 and (len(sc.bodies.ids) or sc.torus):   # methods.ndim refuses the rest
            raise self.error(f"not supported in pyevolver: SPACE_DIMENSION {s.sdim}: "
                             f"{'the torus model needs' if sc.torus else 'bodies need'} 3 dimensions",
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
        s.symmetry_group = symmetry.declared(sc, s, self.error)
        s.metric = metric_of(sc, self.error)   # METRIC / CONFORMAL_METRIC / KLEIN_METRIC
        if sc.torus or sc.symmetry_group == "torus":
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
        self.vid = IdMap(blk.ids, "vertex", sc.filename, blk.lines)
        sd = s.sdim                 # 2-d surfaces keep a zero z column
        X = np.zeros((n, max(3, sd)))
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
                elif kw == "axial_point":                       # model.groups
                    s.vattr.setdefault(kw, np.zeros(n, bool))[pos] = True
                elif kw in ("bare", "original", "tag", "triple_point",
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
        return idmap.lookup(np.abs(flat), Lazy(lambda j: blk.lines[owner[j]]), what,
                            Lazy(lambda j: blk.ids[owner[j]]))

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
        self.eid = IdMap(blk.ids, "edge", sc.filename, blk.lines)
        E = np.zeros((n, 2), np.int64)
        self._wrap_codes = np.zeros(n, np.int64)
        data = blk.data
        if "quadratic" in sc.flags and n:     # (pyevolver.remesh.quadratic.from_listed)
            data, s.listed_midpoints = split_midpoints(data, self.vid, blk.lines, blk.ids)
        if isinstance(data, np.ndarray):
            bad = [0] if data.shape[1] != 2 else []
        else:
            bad = [k for k, d in enumerate(data) if len(d) != 2]
        if bad:
            k = bad[0]
            raise self.error(f"edge {blk.ids[k]}: expected two vertex ids, got "
                             f"{len(data[k])}", blk.lines[k])
        if n:
            raw = np.array(data, dtype=np.int64)
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
                elif kw == "wrap" and sc.symmetry_group is not None:
                    if (len(vals) != 1 or not abs(vals[0]) < 2.0 ** 63
                            or vals[0] != int(vals[0])):
                        raise self.error(f"edge {blk.ids[pos]}: wrap expects one group "
                                         "element code (an integer)", blk.lines[pos])
                    self._wrap_codes[pos] = int(vals[0])
                elif kw == "wrap":
                    raise self.error(f"edge {blk.ids[pos]}: not supported in pyevolver: WRAP "
                                     "without SYMMETRY_GROUP", blk.lines[pos])
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
            s.eattr["wrap"] = w if s.symmetry_group is None else \
                symmetry.decode_torus(self._wrap_codes, s.sdim)
        elif s.symmetry_group is not None:           # the other groups' codes (model.groups)
            s.eattr["wrap_code"] = self._wrap_codes.copy()
        for cid, c in sc.constraints.items():
            if "global" in c.flags:
                s.econ[cid] = np.ones(n, np.int8)

    # -- faces ------------------------------------------------------------------
    def _faces(self):
        sc, s = self.sc, self.s
        blk = sc.faces
        nface = len(blk.ids)
        self.fid = IdMap(blk.ids, "face", sc.filename, blk.lines)
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
            del flat, owner, heads, nxt, ends       # (the load's peak memory)
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
        if len(big) and "wrap_code" in s.eattr:         # (model.groups: wrapped rims refused)
            symmetry.group_face_check(s, big, starts, lengths, eidx, blk, self.error)
        new_X, new_E, new_F = [], [], []      # new_F: (FE row, parent face position)
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
            if "wrap_code" in s.eattr:
                s.eattr["wrap_code"] = np.concatenate([s.eattr["wrap_code"],
                                                       np.zeros(nnew_e, np.int64)])
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
            symmetry.torus_face_centers(s, big, starts, lengths, enc)
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
        init_rings(s)
        s.sf_enc = np.where(rev, ~eidx, eidx).astype(np.int64)
        self.facet_attrs(blk, nface, fixed, tension, no_refine, colors)

    def facet_attrs(self, blk, nface, fixed, tension, no_refine, colors):
        """The faces' attributes, each face its own facet (no split yet)."""
        s = self.s
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
        b.facet_matrix = canonical_csr(vals, rows, cols, (nb, s.n_facets))  # (scipy's CSR)
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
                etype = HOOKS.require("method_etype")(m.method)
            except UnsupportedError as exc:
                raise self.error(f"method_instance {name}: {exc}", m.line) from None
            if s.string:
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
                    etype = HOOKS.require("method_etype")(m.method)
                except UnsupportedError as exc:
                    raise self.error(f"quantity {name}: {exc}", qd.line) from None
                self._check_integrand(m, f"quantity {name}", qd.line)
                q.methods.append(self._instance(m, etype, members.get((name, etype), [])))
            for m in qd.methods:
                self._check_string_method(m, f"quantity {name}", qd.line)
            if qd.function is not None:
                for v in qd.function.names():      # (REF: also other quantities' values)
                    ref = v[:-len(".value")] if v.endswith(".value") else None
                    if not (ref in sc.method_instances or v in sc.parameters or v in CONSTANTS
                            or ref in sc.quantities and sc.quantities[ref].function is None):
                        raise self.error(f"quantity {name}: FUNCTION uses {v!r}; expected values "
                                         "(name.value) of method instances and of quantities "
                                         "without a FUNCTION, parameters and constants", qd.line)
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
        HOOKS.require("project")(self.s, np.arange(self.s.nv))


@loading
def build_surface(scene: Scene) -> Surface:
    """Build a :class:`Surface` from a :class:`~pyevolver.model.scene.Scene`.

    Parameters
    ----------
    scene : Scene
        A parsed datafile (:func:`pyevolver.datafile.reader.read_datafile`).

    Returns
    -------
    Surface
        Vertices projected on their constraints; errors are
        :class:`~pyevolver.errors.DatafileError` located in the datafile.
    """
    try:
        return SX.build(_Builder(scene)) if scene.simplex else _Builder(scene).build()
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

