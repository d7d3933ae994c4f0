"""``gauss_curvature_integral``: the total Gaussian curvature of a surface
with boundary as the total geodesic curvature of its boundary.

Surface Evolver manual, "gauss_curvature_integral": a facet method whose
value is the sum of its corner angles at boundary vertices minus π for each
of its boundary edges; summed over the surface this is ``Σ_v (Σ_i θ_i) − π``
over the boundary vertices, which equals the angle deficit of the interior
vertices plus 2πχ (Gauss–Bonnet).  Boundary vertices are the FIXED ones and
those on a parametric boundary (not those on level-set constraints), boundary
edges likewise; a vertex extra attribute ``gauss_bdry_v`` and an edge extra
attribute ``gauss_bdry_e`` override the criterion where defined.  Checked
against evolver-nox-d 2.70 (tests/reference/test_curvature_constrained_reference.py):
facet values and the sum on cat.fe (fixed and free ring vertices) and on a
mound with fixed or constrained base, and the ``g`` steps.
"""
from __future__ import annotations

import numpy as np

from ..errors import UnsupportedError
from ..model.surface import Surface
from ._common import corner_scatter, facet_points
from .curvature import _angles
from .registry import register_method


def boundary_marks(s: Surface) -> tuple[np.ndarray, np.ndarray]:
    """The boundary vertices (nv,) and boundary edges (ne,) of the method.

    Returns
    -------
    (nv,) bool, (ne,) bool
        FIXED or on a parametric boundary, unless ``gauss_bdry_v`` /
        ``gauss_bdry_e`` are defined (then: nonzero there).
    """
    bv = s.extra.get(("vertex", "gauss_bdry_v"))
    if bv is not None:
        vmark = np.asarray(bv, float).reshape(s.nv) != 0
    else:
        vmark = s.vattr["fixed"].copy()
        if "boundary" in s.vattr:
            vmark |= s.vattr["boundary"] != 0
    be = s.extra.get(("edge", "gauss_bdry_e"))
    if be is not None:
        emark = np.asarray(be, float).reshape(s.ne) != 0
    else:
        emark = s.eattr["fixed"].copy()
        if "boundary" in s.eattr:
            emark |= s.eattr["boundary"] != 0
    return vmark, emark


def _edge_ids(s):
    """(nf, 3) edge indices of the facets' sides."""
    return s.topology()[0]


def gci_values(ctx, m, idx):
    """Per-facet value (len(idx),): Σ corner angles at boundary vertices − π ×
    number of boundary sides."""
    s = ctx.surface
    if s.periods is not None:
        raise UnsupportedError("gauss_curvature_integral in the torus model")
    vmark, emark = boundary_marks(s)
    P = facet_points(ctx)
    ang, _ = _angles(P)
    val = (ang * vmark[s.F]).sum(axis=1) - np.pi * emark[_edge_ids(s)].sum(axis=1)
    return val[np.asarray(idx, np.int64)]



def gci_gradient(t, m, idx, w):
    """Gradient (nv, 3) of ``Σ_f w_f value_f``: the corner-angle gradients of
    :func:`curvature._angles` at the boundary corners."""
    s = t.surface
    if s.periods is not None:
        raise UnsupportedError("gauss_curvature_integral in the torus model")
    vmark, _ = boundary_marks(s)
    P = facet_points(t)
    _, dang = _angles(P)
    wf = np.zeros(s.nf)
    np.add.at(wf, np.asarray(idx, np.int64), np.asarray(w, float))
    coef = vmark[s.F] * wf[:, None]                               # (nf, 3 corners)
    g = np.einsum("fa,fabk->fbk", coef, dang)
    return corner_scatter(t, g)


register_method("gauss_curvature_integral", "facet", gci_values, gci_gradient)
