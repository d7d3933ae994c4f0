"""The ambient Riemannian metric a datafile declares (manual, "Metric"):
``METRIC`` (the N² components of the tensor as formulas of the
coordinates), ``CONFORMAL_METRIC`` (a scalar multiple of the identity) or
``KLEIN_METRIC`` (hyperbolic space in the unit ball).

Data only: the lengths and areas it gives are in
:mod:`pyevolver.methods.metric`.  The metric changes edge lengths and facet
areas (the default energy), never volumes nor the motion (REF moves
vertices by the plain coordinate gradient).
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import UnsupportedError


@dataclass
class Metric:
    """One metric declaration.

    Attributes
    ----------
    kind : str
        ``"matrix"``, ``"conformal"`` or ``"klein"``.
    comps : list
        The formulas (:class:`pyevolver.expr.nodes.Formula`): N² components
        row by row for ``"matrix"``, the conformal factor for
        ``"conformal"``, none for ``"klein"``.
    dim : int
        N, the space dimension.
    order_1d, order_2d : int
        The quadrature orders (``INTEGRAL_ORDER_1D`` / ``_2D``): edges take
        Gauss-Legendre with ``order_1d // 2 + 1`` points, facets REF's
        triangle rule of ``order_2d``.
    line : int or None
        The declaration's source line.
    """

    kind: str
    comps: list = field(default_factory=list)
    dim: int = 3
    order_1d: int = 3
    order_2d: int = 6
    line: int | None = None

    def texts(self) -> list[str]:
        """The components as the datafile can write them back."""
        return [str(getattr(c, "text", "") or c.node) for c in self.comps]


#: the named methods checked against REF under a metric: the first four stay
#: Euclidean there, the metric_ ones measure in it, the rest do not measure
METRIC_METHODS = {"facet_area", "edge_length", "facet_tension", "edge_tension", "facet_volume",
                  "metric_facet_area", "metric_edge_length", "vertex_scalar_integral",
                  "facet_vector_integral", "edge_vector_integral"}

#: the facet quadrature orders whose REF rules pyevolver has
FACET_ORDERS = (6, 7)


def metric_orders_refusal(sc) -> str | None:
    """Why non-default ``INTEGRAL_ORDER``s of the Scene ``sc`` stay refused
    (``""``: no metric uses them), or None when only the metric's integrals
    use them and pyevolver has REF's rules for them."""
    m = sc.values.get("_metric")
    if m is None:
        return ""
    o2 = int(sc.values.get("integral_order_2d", 6))
    if not sc.string and m.kind != "klein" and o2 not in FACET_ORDERS:
        return (f"with a metric pyevolver has REF's facet rules of INTEGRAL_ORDER_2D "
                f"{' and '.join(map(str, FACET_ORDERS))} only")
    if "quadratic" in sc.flags:
        return "in the quadratic model"
    if sc.quantities or any(c.energy or c.content for c in
                            list(sc.constraints.values()) + list(sc.boundaries.values())):
        return "the integrals of constraints, boundaries and quantities use order 3 only"
    return None


def metric_of(sc, error=None) -> Metric | None:
    """The Scene's metric with its quadrature orders, or None; the
    combinations pyevolver does not have are refused by name (with
    ``error(message, line)``, the builder's located error, when given)."""
    m = sc.values.get("_metric")
    if m is None:
        return None
    if m.kind == "matrix" and len(m.comps) != sc.space_dimension ** 2:
        msg = (f"METRIC has {len(m.comps)} components where SPACE_DIMENSION "
               f"{sc.space_dimension} needs {sc.space_dimension ** 2}")
        raise error(msg, m.line) if error is not None else ValueError(msg)
    why = None
    bad = sorted({md.method.lower() for q in sc.quantities.values() for md in q.methods}
                 .union(md.method.lower() for md in sc.method_instances.values())
                 - METRIC_METHODS)
    if sc.torus:
        why = "a metric in the torus model (lengths and areas of wrapped edges)"
    elif bad:
        why = (f"method {bad[0]} with a metric (whether REF measures it in the metric "
               f"is not reproduced)")
    elif any(c.energy for c in list(sc.constraints.values()) + list(sc.boundaries.values())):
        why = ("constraint or boundary ENERGY integrals with a metric (REF's motion differs "
               "from their gradient: sphere.fe with a conformal metric)")
    elif sc.values.get("squared_curvature"):
        why = "SQUARED_CURVATURE with a metric"
    elif sc.space_dimension > 3:
        why = f"a metric in SPACE_DIMENSION {sc.space_dimension}"
    if why is not None:
        if error is not None:
            raise error(f"not supported in pyevolver: {why}", m.line)
        raise UnsupportedError(why)
    m.dim = sc.space_dimension
    m.order_1d = int(sc.values.get("integral_order_1d", 3))
    m.order_2d = int(sc.values.get("integral_order_2d", 6))
    return m
