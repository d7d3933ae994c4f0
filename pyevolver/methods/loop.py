"""``loop_sq_mean_curvature``, ``loop_area``, ``loop_volume``: pyevolver's own
quantity methods on the Loop subdivision surface whose control mesh is the
triangulation (:mod:`pyevolver.geometry.loop`, issue 8).

They are global: the whole (closed) surface is the control mesh.  As vertex
methods, each facet's share of the limit surface's W = ∫H² dA (H the mean
of the principal curvatures), area or volume (∮ x·n dA / 3) is split
equally between its three vertices, so the sum over all vertices is the
total.  Gradients follow the same split: with vertex weights ``w``, facet f
is weighted by ``(w_a + w_b + w_c)/3``.
"""
from __future__ import annotations

import numpy as np

from ..errors import UnsupportedError
from ..geometry.loop import LoopEvaluator
from .curvature import vertex_weights
from .registry import register_method

KIND = {"loop_sq_mean_curvature": "W", "loop_area": "A", "loop_volume": "V"}


def evaluator(s, name="loop_sq_mean_curvature"):
    """The :class:`pyevolver.geometry.loop.LoopEvaluator` of surface ``s``, cached
    while its topology is unchanged."""
    topo = s.topology()
    c = s.__dict__.get("_loop_eval")
    if c is not None and c[0] is topo:
        return c[1]
    if s.periods is not None:
        raise UnsupportedError(f"method {name} in the torus model")
    if s.X.shape[1] != 3:
        raise UnsupportedError(f"method {name}", "needs a surface in 3 dimensions")
    ev = LoopEvaluator(s.F, s.nv, what=f"method {name}")
    s._loop_eval = (topo, ev)
    return ev


def _facet_values(t, name):
    c = t.__dict__.get("_loop_values")
    if c is None:
        c = evaluator(t.surface, name).values(t.surface.X)
        t._loop_values = c
    return c[KIND[name]]


def values(ctx, m, idx):
    """Per-vertex third of the vertex's facets' shares (see the module docstring)."""
    s = ctx.surface
    v = _facet_values(ctx, m.method) / 3.0
    per_v = np.bincount(s.F.ravel(), weights=np.repeat(v, 3), minlength=s.nv)
    return per_v[idx]


def gradient(t, m, idx, w):
    """Gradient (nv, 3) of ``Σ w_v value_v``."""
    s = t.surface
    wv = vertex_weights(s.nv, idx, w)
    coef = wv[s.F].sum(1) / 3.0
    return evaluator(s, m.method).gradient(s.X, KIND[m.method], coef)


for _name in KIND:
    register_method(_name, "vertex", values, gradient,
                    no_hessian="Loop patches couple vertex 2-rings; use g")
