"""Geometry in a symmetry group other than the torus (pyevolver.model.groups).

An edge's group element is the affine map ``g(x) = A x + b`` of its code: the
edge vector is ``g(x_head) - x_tail``.  A facet's corners are unwrapped from
its first vertex by the group elements of its oriented edges (a reversed
edge contributes the inverse): corner 1 is ``g0(x1)``, corner 2
``(g0 g1)(x2)``, the product taken as REF takes it (``wrap_compose``).  The totals keep the maps, ``corner_maps`` (nf, 3, 3, 3) and
``edge_maps`` (ne, 3, 3), so that gradients flow back to each vertex
through ``Aᵀ`` (``methods._common.corner_scatter`` and ``edge_pullback``).
Body volumes are the plain sums of the facets' contents of those corners
(the manual: "the Euclidean volume calculation").
"""
from __future__ import annotations

import numpy as np

from ..errors import UnsupportedError
from ..geometry import kernels as G


def element_maps(s, group) -> tuple[np.ndarray, np.ndarray]:
    """(A (ne, 3, 3), b (ne, 3)) of the surface's edges."""
    return group.affine(s.eattr["wrap_code"])


def corner_codes(s, group) -> np.ndarray:
    """(nf, 3) group elements of the facets' corners: the identity, the
    first oriented edge's element ``c0`` and ``wrap_compose(c0, c1)`` (a
    reversed edge's element is ``wrap_inverse`` of its code).  REF places
    corners by these products of codes, so where its product is not the
    maps' composition (quarter_turn's z powers, cubocta's cycles) the
    corners are REF's."""
    idx, sgn, _ = s.topology()
    codes = s.eattr["wrap_code"][idx]
    oriented = np.where(sgn > 0, codes, group.inverse(codes))
    out = np.zeros(idx.shape, np.int64)
    if len(idx):
        out[:, 1] = oriented[:, 0]
        out[:, 2] = group.compose(oriented[:, 0], oriented[:, 1])
    return out


def corner_maps(s, group) -> tuple[np.ndarray, np.ndarray]:
    """(Ac (nf, 3, 3, 3), bc (nf, 3, 3)): corner k of facet f sits at
    ``Ac[f, k] x + bc[f, k]`` of its vertex x, in the frame of the facet's
    first vertex."""
    c = corner_codes(s, group)
    A, b = group.affine(c.ravel())
    return A.reshape(c.shape + (3, 3)), b.reshape(c.shape + (3,))


#: named-quantity methods whose values and gradients go through the corner
#: and edge maps (the others read vertex coordinates on their own)
METHODS = {"facet_area", "facet_volume", "edge_length", "edge_area", "edge_tension",
           "facet_tension", "vertex_scalar_integral"}


def check_supported(s) -> None:
    """Refuse by name what would ignore the group elements: metrics,
    constraint and boundary integrals, CONVEX gap energies, the quadratic
    model, wrapped edges on parametric boundaries (their midpoints) and
    named-quantity methods outside :data:`METHODS`."""
    where = f'in SYMMETRY_GROUP "{s.symmetry_group}"'
    tension = s.eattr.get("tension")
    if tension is not None and np.any(tension):
        raise UnsupportedError(f"edge TENSION {where} (REF leaves it out of the energy when "
                               f"it converts to named quantities: measured on flip_rotate.fe; "
                               f"a quantity with METHOD edge_length works)")
    if s.metric is not None:
        raise UnsupportedError(f"a metric {where}")
    if s.order != 1:
        raise UnsupportedError(f"the quadratic model {where}")
    for kind, table in (("constraint", s.constraints), ("boundary", s.boundaries)):
        for c in table.values():
            if getattr(c, "energy", None) or getattr(c, "content", None):
                raise UnsupportedError(f"{kind} ENERGY / CONTENT integrals {where}")
            if "convex" in getattr(c, "flags", ()):
                raise UnsupportedError(f"CONVEX constraints (gap energy) {where}")
    bnd = s.eattr.get("boundary")
    if bnd is not None and np.any((bnd != 0) & (s.eattr["wrap_code"] != 0)):
        raise UnsupportedError(f"a wrapped edge on a parametric boundary {where}")
    for q in s.quantities.values():
        for m, *_ in q.methods:
            if m.method not in METHODS:
                raise UnsupportedError(f"the quantity method {m.method} {where} (it reads "
                                       f"vertex coordinates without the group elements)")


def quarter_turn_pullback(s, group, Ac) -> np.ndarray:
    """The maps through which REF pulls gradients back in ``quarter_turn``:
    none at a corner whose code is not 0 (its facets' corners there add
    nothing to the vertex's force: measured with ``v_force`` on
    quarter_turn.fe, where every such corner's share is missing from REF's
    forces, to 12 digits), so that `g` moves as REF's."""
    for q in s.quantities.values():
        for m, *_ in q.methods:
            if m.method.startswith("edge_"):
                raise UnsupportedError(f'the quantity method {m.method} in SYMMETRY_GROUP '
                                       f'"quarter_turn" (REF\'s edge forces across its '
                                       f'elements were not measured)')
    return np.where((corner_codes(s, group) != 0)[:, :, None, None], 0.0, Ac)


def totals_geometry(t, group) -> None:
    """Set the evaluation's cached geometry (edge vectors, facet sides,
    normals, areas, contents) and the maps of ``t.surface`` in ``group``."""
    s = t.surface
    check_supported(s)
    X = s.X
    A, b = element_maps(s, group)
    t.edge_maps = A
    t.edge_vec = np.einsum("eij,ej->ei", A, X[s.E[:, 1]]) + b - X[s.E[:, 0]]
    F = s.topology()[2]
    Ac, bc = corner_maps(s, group)
    t.corner_maps = Ac
    if group.name == "quarter_turn":
        t.corner_maps = quarter_turn_pullback(s, group, Ac)
    P = np.einsum("fkij,fkj->fki", Ac, X[F]) + bc if len(F) else np.zeros((0, 3, 3))
    t.facet_x0 = P[:, 0]
    S = np.empty((len(F), 2, 3))
    S[:, 0] = P[:, 1] - P[:, 0]
    S[:, 1] = P[:, 2] - P[:, 0]
    t.facet_S = S
    t.facet_N2 = G.facet_normals(S)
    t.facet_area = G.facet_areas(t.facet_N2)
    t.facet_volume = G.facet_volumes(t.facet_x0, S, s.symmetric_content)

