"""Energy assembly: :class:`Totals` sums the surface tension, the edge
tensions, constraint integrals, gap and gravity energies, prescribed
pressures and the registered methods of the named quantities.

``Surface.evaluate()`` calls :func:`evaluate` (installed as the model's
``evaluate`` hook when this module is imported).
"""
from __future__ import annotations

import numpy as np

from ..constraints import integral_edges, located
from ..errors import PyEvolverError, UnsupportedError
from ..geometry import kernels as G
from ..model.records import convex_edges, torus_lift_shifts
from ..model.groups import group_of
from ._common import csr_matvec
from .group_geometry import totals_geometry
from ..model.surface import HOOKS, Quantity, Surface
from . import metric as MT
from .curvature import legacy_energy
from .registry import lookup


class Totals:
    """Energies, area and volumes of a surface at its current coordinates.

    Derived geometry (edge vectors, facet normals, areas) is computed once per
    evaluation and shared by every energy term and method.

    Attributes
    ----------
    surface : Surface
    energy : float
        The total energy.
    total_area : float
    terms : dict of str -> float
        The energy by term (``facet_tension``, ``edge_tension``, ``gap``,
        ``gravity``, ``sq_curvature``).
    facet_area, facet_volume : (nf,) arrays
    facet_N2 : (nf, 3) array
        Twice the facet area vectors.
    volumes : (nbodies,) array
    quantity_values : dict of str -> float
    edge_vec, edge_length, facet_x0, facet_S
        (ne, 3), (ne,), (nf, 3), (nf, 2, 3): computed on first use.
    """

    model = "linear"        # the element order whose method variants apply

    def __init__(self, s: Surface):
        self.surface = s
        X = s.X
        wrap = s.wrap_shift()
        group = group_of(s)
        if group is not None:           # a symmetry group's maps (methods.group_geometry)
            totals_geometry(self, group)
        elif wrap is None and X.shape[1] == 3:
            # corners gathered one coordinate at a time (several times faster
            # than gathering edge vectors); the torus needs the edge wraps
            P, N2T, self.facet_area, self.facet_volume, a, b = G.corner_geometry(
                np.ascontiguousarray(X.T), s.facet_corners(), s.symmetric_content, sides=True)
            self._corner_xyz = P
            self._corner_sides = (a, b)
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
        if s.metric is not None:        # areas in the metric (volumes stay Euclidean)
            self.euclidean_facet_area = self.facet_area
            self.facet_area = MT.facet_areas(self)
        self.total_area = float(self.facet_area.sum())
        energy = self._tension_energy()
        self.con_energy, self.con_content = self._integrals()
        energy += self.con_energy
        gap = self._gap_energy()
        if gap:
            self.terms["gap"] = gap
            energy += gap
        if s.sq_curvature_modulus:
            # legacy top-of-file SQUARED_CURVATURE (spec 5.3): the vertex
            # method picked by the effective_area / normal_curvature toggles
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
        if self.surface.metric is not None:
            return MT.edge_lengths(self)
        d = self.edge_vec
        return np.sqrt(np.einsum("ij,ij->i", d, d))

    def _make_total_length(self):
        return float(self.edge_length.sum())

    def _make_facet_x0(self):
        P = self._corner_xyz
        return np.stack([P[0][0], P[1][0], P[2][0]], axis=1)

    def _make_facet_S(self):
        ab = self.__dict__.get("_corner_sides")
        if ab is None:                  # (a model that gathers the corners itself)
            P = self._corner_xyz
            ab = (np.array([P[k][1] - P[k][0] for k in range(3)]),
                  np.array([P[k][2] - P[k][0] for k in range(3)]))
        a, b = ab
        S = np.empty((self.surface.nf, 2, 3))
        S[:, 0] = a.T
        S[:, 1] = b.T
        return S

    _LAZY = {"edge_vec": _make_edge_vec, "edge_length": _make_edge_length,
             "total_length": _make_total_length, "facet_x0": _make_facet_x0,
             "facet_S": _make_facet_S}

    # ---- pieces -----------------------------------------------------------
    def eval_points(self, formula, P: np.ndarray, etype: str | None = None,
                    idx: np.ndarray | None = None) -> np.ndarray:
        """Evaluate a formula at points ``P (n, sdim)`` (the elements' extra
        attributes of ``etype`` at ``idx`` available by name); (n,)."""
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

    def edge_vector_integral(self, comps, idx: np.ndarray) -> np.ndarray:
        """(n,) 2-point Gauss-Legendre line integrals of the vector field
        ``comps`` along the edges ``idx``."""
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

    def _tension_energy(self) -> float:
        """Facet and edge tension energy; starts ``self.terms`` with both
        (the linear, quadratic and n-D totals share it)."""
        s = self.surface
        self.terms = {}
        energy = float(self.facet_area @ s.facet_tension)
        self.terms["facet_tension"] = energy
        et = s.eattr.get("tension")
        if et is not None:
            e = float(self.edge_length @ et)
            self.terms["edge_tension"] = e
            energy += e
        return energy

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
            L = np.sqrt(np.einsum("ij,ij->i", d, d))        # Euclidean under a metric too
            for end in (0, 1):
                P = s.X[s.E[idx, end]]
                g = self.constraint_gradient(c, P)
                gn = np.sqrt(np.einsum("ij,ij->i", g, g))
                sg = np.abs(np.einsum("ij,ij->i", d, g))
                with np.errstate(all="ignore"):
                    total += float(np.sum(np.where(gn > 0, sg * L / (12.0 * gn), 0.0)))
        return s.gap_constant * total

    def constraint_gradient(self, c, P: np.ndarray) -> np.ndarray:
        """(n, 3) gradient of constraint ``c``'s formula at points ``P (n, 3)``."""
        coords = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
        return c.formula.gradient(self.surface.param_env(), coords, len(P))

    def _volumes(self):
        s = self.surface
        b = s.bodies
        if not b.n:
            return np.zeros(0)
        vols = csr_matvec(b.facet_csr, self.facet_volume)
        if self.con_content is not None:
            # edge content counts toward the bodies of the facets the edge is on
            vols = vols + b.facet_matrix @ self.facet_edge_sum(self.con_content)
        vols = vols + b.volconst
        if s.periods is not None and s.symmetry_group is None:
            # (a symmetry group's volumes are the facets' unwrapped contents:
            # pyevolver.model.symmetry)
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

    def facet_edge_sum(self, per_edge: np.ndarray) -> np.ndarray:
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

    def instance_values(self, q: Quantity) -> dict[str, float]:
        """``{"inst.value": value}`` of the method instances a FUNCTION reads."""
        s = self.surface
        return {f"{n}.value": self.quantity_value(s.quantities[n])
                for n in (v[:-6] for v in q.function.node.names()  # type: ignore[attr-defined]
                          if v.endswith(".value"))}

    def quantity_value(self, q: Quantity, magnitude: bool = False) -> float:
        """Value of a named quantity; with ``magnitude=True`` the sum of the
        absolute values of its element contributions instead (the scale of
        its restoring tolerance).  A FUNCTION quantity's magnitude is its
        linearization's: Σ_i |∂f/∂v_i| magnitude_i."""
        try:
            return self._quantity_value(q, magnitude)
        except PyEvolverError as exc:
            if getattr(exc, "line", None) is None:     # say which quantity failed, where
                exc.line = q.line  # type: ignore[attr-defined]
                exc.args = (f"quantity {q.name}: {exc}",)
            raise

    def _quantity_value(self, q, magnitude=False):
        if q.kind == "energy" and q.modulus == 0:
            return 0.0              # REF does not evaluate an energy of modulus 0
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
            fn = lookup(m.method, self.model).value
            vals = fn(self, m, idx)
            if magnitude:
                total += abs(m.modulus) * float(np.sum(np.abs(vals)))
                continue
            if sign is not None:
                vals = vals * sign
            total += m.modulus * float(np.sum(vals))
        return abs(q.modulus) * total if magnitude else q.modulus * total

    def volume_magnitudes(self) -> np.ndarray:
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


# the Totals class of each surface model ("soapfilm", "string"); the string
# model's (pyevolver.methods.string) registers itself
MODEL_TOTALS: dict[str, type[Totals]] = {"soapfilm": Totals}


def evaluate(surface: Surface) -> Totals:
    """Energy, area, volumes and quantity values of ``surface`` at its
    current coordinates.

    Returns
    -------
    Totals
        Of the class :data:`MODEL_TOTALS` gives the surface's model (a
        :class:`pyevolver.methods.string.StringTotals` in the string model).
    """
    model = "string" if surface.string else "soapfilm"
    if getattr(surface, "simplex", 0):
        model = "simplex"       # pyevolver.methods.simplex
    elif surface.X.shape[1] > 3:
        model = "ndim"          # pyevolver.methods.ndim
    elif getattr(surface, "order", 1) == 2:
        model = "quadratic"
    if surface.metric is not None and model not in ("string", "soapfilm"):
        raise UnsupportedError(f"a metric in the {model} model")
    return MODEL_TOTALS[model](surface)


HOOKS.evaluate = evaluate
