"""The soapfilm linear model in an ambient space of dimension ``d > 3``
(``SPACE_DIMENSION 4`` .. ``9``): :class:`NDTotals`.

Facet areas and edge lengths are measured in R^d (Gram determinants:
:func:`pyevolver.geometry.kernels.gram_facet_areas`), as the Evolver's
``area`` is (measured against evolver-nox-d on relaxed.fe, where the
5-dimensional area of the unit triangle with reference coordinates is 1).
The energy is the facet tension times the area, the edge tensions times the
lengths and the energy quantities of the methods that work in any dimension
(:data:`ND_METHODS`).  What needs three dimensions is refused by name:
bodies and their volumes, gravity, constraint and boundary integrals,
CONVEX gap energy, the squared curvature, and every other method.
"""
from __future__ import annotations

import numpy as np

from ..constraints import integral_edges
from ..errors import UnsupportedError, dimension_error
from ..geometry import kernels as G
from ..model.surface import Surface
from .registry import lookup
from .totals import MODEL_TOTALS, Totals

# the methods that run in any dimension (their gradients are (nv, d))
ND_METHODS = frozenset({"linear_elastic_b", "relaxed_elastic", "relaxed_elastic1",
                        "relaxed_elastic2"})


def refuse(s: Surface, what: str, verb: str = "need",
           line: int | None = None) -> UnsupportedError:
    """The refusal of ``what`` in the surface's dimension (``"SPACE_DIMENSION 5:
    body volumes need 3 dimensions"``), located at ``line`` (default: the
    SPACE_DIMENSION declaration's)."""
    exc = dimension_error(s.sdim, what, verb)
    exc.line = line if line is not None else s.sdim_line  # type: ignore[attr-defined]
    return exc


class NDTotals(Totals):
    """:class:`~pyevolver.methods.totals.Totals` of a surface in R^d, d > 3.

    Attributes (beyond those of ``Totals`` that exist in any dimension)
    ----------------------------------------------------------------------
    facet_S : (nf, 2, d) array
        The facet sides.
    facet_x0 : (nf, d) array
        The first corners.
    """

    def __init__(self, s: Surface):
        self.surface = s
        check_supported(s)
        X = s.X
        self.edge_vec = G.edge_vectors(X, s.E, None)
        idx, sgn, F = s.topology()
        self.facet_S = G.facet_sides(self.edge_vec, s.FE, (idx, sgn))
        self.facet_x0 = X[F[:, 0]] if s.nf else np.zeros((0, X.shape[1]))
        self.facet_area = G.gram_facet_areas(self.facet_S)
        self.total_area = float(self.facet_area.sum())
        energy = self._tension_energy()
        self.con_energy, self.con_content = 0.0, None
        self.volumes = np.zeros(0)
        self.energy = self._finish_energy(energy, 0.0)

    @property
    def facet_N2(self) -> np.ndarray:  # type: ignore[override]
        """Refused: a facet has no normal vector in R^d, d > 3."""
        raise refuse(self.surface, "facet normals")

    @property
    def facet_volume(self) -> np.ndarray:  # type: ignore[override]
        """Refused: facet volume contributions need three dimensions."""
        raise refuse(self.surface, "volumes")

    def energy_gradient(self) -> np.ndarray:
        """Gradient (nv, d) of the total energy: the facet tensions' area
        gradients (:func:`pyevolver.geometry.kernels.gram_facet_area_grad`),
        the edge tensions' ``T (x_head − x_tail)/L`` and the energy quantities'."""
        s = self.surface
        per = G.gram_facet_area_grad(self.facet_S, self.facet_area)
        per = per * s.facet_tension[:, None, None]
        g = G.scatter_nd(s.nv, s.F.ravel(), per.reshape(-1, per.shape[2]))
        et = s.eattr.get("tension")
        if et is not None and np.any(et):
            L = self.edge_length
            with np.errstate(all="ignore"):
                u = np.where(L[:, None] > 0, self.edge_vec / np.where(L > 0, L, 1.0)[:, None], 0.0)
            u = u * et[:, None]
            g += G.scatter_nd(s.nv, np.concatenate([s.E[:, 1], s.E[:, 0]]),
                              np.concatenate([u, -u]))
        for q in s.quantities.values():
            if q.kind == "energy":
                g += _quantity_gradient(self, q)
        return g

    def body_volume_gradients(self) -> np.ndarray:
        """Refused: bodies need three dimensions."""
        raise refuse(self.surface, "body volumes")


def _quantity_gradient(t: NDTotals, q) -> np.ndarray:
    """Gradient (nv, d) of a named quantity of :data:`ND_METHODS`."""
    s = t.surface
    g = np.zeros((s.nv, s.X.shape[1]))
    if q.function is not None:
        raise refuse(s, f"FUNCTION quantities ({q.name})")
    for m, etype, idx, sign in q.methods:
        w = np.ones(len(idx)) if sign is None else np.asarray(sign, float)
        fn = lookup(m.method).gradient
        g += fn(t, m, np.asarray(idx, np.int64), w * m.modulus * q.modulus)
    return g


def check_supported(s: Surface) -> None:
    """Refuse by name what needs three dimensions on the surface ``s``.

    Raises
    ------
    UnsupportedError
        For bodies, gravity, constraint / boundary integrals, CONVEX
        constraints, squared curvature, FUNCTION quantities, methods outside
        :data:`ND_METHODS`, the torus model and parametric boundaries.
    """
    if getattr(s, "order", 1) != 1:
        raise refuse(s, "the quadratic model", "needs")
    if s.bodies.n:
        raise refuse(s, "body volumes")
    if s.sq_curvature_modulus:
        raise refuse(s, "squared curvature", "needs")
    if s.periods is not None:
        raise refuse(s, "the torus model here", "needs")
    if s.boundaries:
        raise refuse(s, "parametric boundaries")
    for c in s.constraints.values():
        if "convex" in getattr(c, "flags", ()):
            raise refuse(s, "CONVEX constraints (gap energy)")
    if integral_edges(s, "energy") or integral_edges(s, "content"):
        raise refuse(s, "constraint energy and content integrals")
    for q in s.quantities.values():
        if q.function is not None:
            raise refuse(s, f"FUNCTION quantities ({q.name})", line=q.line)
        for m, *_ in q.methods:
            if m.method.lower() not in ND_METHODS:
                raise refuse(s, f"method {m.method} (quantity {q.name})", "needs", q.line)


MODEL_TOTALS["ndim"] = NDTotals
