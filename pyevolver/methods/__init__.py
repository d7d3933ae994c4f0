"""Quantity methods, registered under their Evolver names.

A method computes one value per element it applies to; a quantity's value
is ``modulus * sum``.  ``register_method(name, etype, fn)`` is public, so a
user can add methods::

    from pyevolver.methods import register_method
    register_method("my_area", "facet", lambda ctx, m, idx: ctx.facet_area[idx])

``fn(ctx, method, idx)`` gets the evaluation context (cached geometry of the
surface), the :class:`pyevolver.model.scene.MethodDecl` and the element indices,
and returns an array of per-element values (orientation signs are applied by
the caller).
"""
from __future__ import annotations

import numpy as np

from ..errors import UnsupportedError
from ..geometry import kernels as G

METHODS = {}
GRADIENTS = {}     # name -> fn(totals, method, idx, weights) -> (nv, 3)
HESSIANS = {}      # name -> fn(totals, method, idx, weights, basis=None) -> sparse
# Methods whose values couple vertices beyond a facet or an edge's two facets:
# no Hessian (the coloured differences of the gradient assume that stencil).
NO_HESSIAN = {
    "circle_willmore": "Bobenko's energy is not smooth (REF has no Hessian for it); use bfgs (or g)",
    "loop_sq_mean_curvature": "Loop patches couple vertex 2-rings; use g",
    "loop_area": "Loop patches couple vertex 2-rings; use g",
    "loop_volume": "Loop patches couple vertex 2-rings; use g",
}

# Evolver methods pyevolver knows by name but does not implement (yet).
CURVATURE_METHODS = {
    "sq_mean_curvature", "eff_area_sq_mean_curvature", "normal_sq_mean_curvature",
    "star_sq_mean_curvature", "star_eff_area_sq_mean_curvature",
    "star_normal_sq_mean_curvature", "star_perp_sq_mean_curvature",
    "mix_sq_mean_curvature", "mean_curvature_integral", "mean_curvature_integral_a",
    "sq_gauss_curvature", "star_gauss_curvature", "gauss_curvature_integral",
    "sqcurve_string",
}


def register_method(name, etype, fn, gradient=None, hessian=None):
    """Register ``fn`` as the value function of method ``name`` on ``etype``
    (and ``gradient(totals, method, idx, weights)`` -> (nv, 3) for ``g``,
    ``hessian(totals, method, idx, weights, basis=None)`` -> sparse
    (3nv, 3nv) for ``hessian``)."""
    METHODS[name.lower()] = (etype, fn)
    if gradient is not None:
        GRADIENTS[name.lower()] = gradient
    if hessian is not None:
        HESSIANS[name.lower()] = hessian


def method_info(name):
    try:
        return METHODS[name]
    except KeyError:
        if name in CURVATURE_METHODS:
            raise UnsupportedError(f"method {name}",
                                   "curvature energies come with the Willmore issue") from None
        raise UnsupportedError(f"method {name}") from None


def _facet_area(ctx, m, idx):
    return ctx.facet_area[idx]


def _facet_volume(ctx, m, idx):
    return ctx.facet_volume[idx]


def _edge_length(ctx, m, idx):
    return ctx.edge_length[idx]


def _edge_tension(ctx, m, idx):
    return ctx.edge_length[idx] * ctx.surface.edge_tension[idx]


def _facet_tension(ctx, m, idx):
    return ctx.facet_area[idx] * ctx.surface.facet_tension[idx]


def _vertex_scalar_integral(ctx, m, idx):
    X = ctx.surface.X[idx]
    return ctx.eval_points(m.scalar, X, "vertex", idx)


def _facet_scalar_integral(ctx, m, idx):
    pts = G.facet_quadrature_points(ctx.facet_x0[idx], ctx.facet_S[idx])
    n = len(idx)
    vals = ctx.eval_points(m.scalar, pts.reshape(-1, pts.shape[-1]), "facet",
                           np.repeat(idx, 12)).reshape(n, 12)
    return vals @ G.TRI6_W * ctx.facet_area[idx]


def _facet_vector_integral(ctx, m, idx):
    pts = G.facet_quadrature_points(ctx.facet_x0[idx], ctx.facet_S[idx])
    n = len(idx)
    flat = pts.reshape(-1, pts.shape[-1])
    rep = np.repeat(idx, 12)
    N2 = ctx.facet_N2[idx]
    total = np.zeros(n)
    for k, comp in enumerate(m.vector or []):
        q = ctx.eval_points(comp, flat, "facet", rep).reshape(n, 12) @ G.TRI6_W
        total += 0.5 * q * N2[:, k]
    return total


def _edge_scalar_integral(ctx, m, idx):
    x0 = ctx.surface.X[ctx.surface.E[idx, 0]]
    d = ctx.edge_vec[idx]
    pts = G.edge_quadrature_points(x0, d)
    n = len(idx)
    vals = ctx.eval_points(m.scalar, pts.reshape(-1, pts.shape[-1]), "edge",
                           np.repeat(idx, 2)).reshape(n, 2)
    return vals @ G.GL2_W * ctx.edge_length[idx]


def _edge_vector_integral(ctx, m, idx):
    return ctx.edge_vector_integral(m.vector or [], idx)


for _name, _et, _fn in [
    ("facet_area", "facet", _facet_area),
    ("facet_volume", "facet", _facet_volume),
    ("edge_length", "edge", _edge_length),
    ("edge_area", "edge", _edge_length),
    ("edge_tension", "edge", _edge_tension),
    ("facet_tension", "facet", _facet_tension),
    ("vertex_scalar_integral", "vertex", _vertex_scalar_integral),
    ("facet_scalar_integral", "facet", _facet_scalar_integral),
    ("facet_vector_integral", "facet", _facet_vector_integral),
    ("edge_scalar_integral", "edge", _edge_scalar_integral),
    ("edge_vector_integral", "edge", _edge_vector_integral),
]:
    register_method(_name, _et, _fn)


def _register_curvature():
    from . import curvature as C
    from . import curvature_hessian as CH
    for name in C.VERTEX_METHODS:
        register_method(name, "vertex", C.vertex_values, C.vertex_gradient, CH.vertex_hessian)
    for name in ("mean_curvature_integral", "mean_curvature_integral_a"):
        register_method(name, "edge", C.mci_values, C.mci_gradient, CH.mci_hessian)
        CURVATURE_METHODS.discard(name)
    register_method("star_gauss_curvature", "vertex", C.star_gauss_values,
                    C.star_gauss_gradient, CH.star_gauss_hessian)
    register_method("sq_gauss_curvature", "vertex", C.sq_gauss_values, C.sq_gauss_gradient,
                    CH.sq_gauss_hessian)
    register_method("cotan_sq_mean_curvature", "vertex", C.cotan_values, C.cotan_gradient,
                    CH.cotan_hessian)
    register_method("circle_willmore", "vertex", C.circle_willmore_values,
                    C.circle_willmore_gradient)
    CURVATURE_METHODS.difference_update(C.VERTEX_METHODS)
    CURVATURE_METHODS.difference_update({"star_gauss_curvature", "sq_gauss_curvature"})


_register_curvature()


def _register_harmonic():
    from . import harmonic as H
    register_method("harmonic_energy", "edge", H.values, H.gradient, H.hessian)


_register_harmonic()


def _register_loop():
    from . import loop as L
    for name in L.KIND:
        register_method(name, "vertex", L.values, L.gradient)


_register_loop()
