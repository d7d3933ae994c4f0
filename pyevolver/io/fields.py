"""Per-vertex and per-facet data of a surface, for export and pictures.

:func:`surface_fields` returns plain arrays keyed by name, the data that
``export`` writes beside the mesh and that ``snapshot`` colours by:

vertex fields
    ``id`` (the Evolver's vertex ids), ``mean_curvature`` (the estimate of
    the active curvature method, :func:`mean_curvature`), ``area`` (a third
    of the star area, so the vertex areas sum to the total area), ``fixed``
    (0/1), ``on_constraint_<n>`` (0/1, one per level-set constraint the
    datafile declares) and ``boundary`` (the boundary id, 0 for none, when
    the datafile has boundaries);
facet fields
    ``id``, ``area``, ``tension``, ``fixed``, ``on_constraint_<n>`` and
    ``boundary`` likewise.

Integer fields are int32 (every meshio format with data arrays can store
them), real fields float64.
"""
from __future__ import annotations

import numpy as np

from ..methods import curvature as C
from ..methods.curvature import _LEGACY, VERTEX_METHODS

#: The estimate used when no curvature method is active.
DEFAULT_CURVATURE = "star_perp_sq_mean_curvature"


def curvature_method(surface) -> str:
    """The name of the active mean curvature method of ``surface``.

    The method of the first energy quantity that is a squared mean curvature
    method (``star_perp_sq_mean_curvature``, ``cotan_sq_mean_curvature``,
    ...), else of the first such quantity of any kind, else the vertex
    method that the legacy ``SQUARED_CURVATURE`` uses under the current
    toggles, else :data:`DEFAULT_CURVATURE`.  Methods without a per-vertex
    estimate (``circle_willmore``, the Loop methods) count as absent.
    """
    known = set(VERTEX_METHODS) | {"cotan_sq_mean_curvature"}
    found = [(q.kind != "energy", m.method) for q in surface.quantities.values()
             for m, *_ in q.methods if m.method in known]
    if found:
        return min(found, key=lambda f: f[0])[1]
    if surface.sq_curvature_modulus:
        return _LEGACY[surface.curvature_mode]
    return DEFAULT_CURVATURE


def mean_curvature(surface, totals=None, method: str | None = None) -> np.ndarray:
    """Per-vertex mean curvature (nv,) of ``method`` (default: the active one,
    :func:`curvature_method`).

    The Evolver's vertex methods estimate h from the star sums of a vertex v
    (area A, area gradient F, area vector N; Evolver manual, "Named
    methods"): ``h = 3|F|/(2A)`` (``sq_mean_curvature``,
    ``star_sq_mean_curvature``; unsigned), ``3|F|/(2|N|)`` (the
    ``eff_area`` methods; unsigned), ``3 F·F/(2 F·N)`` (``normal``) and
    ``3 F·N/(2 N·N)`` (``star_perp``; positive where the surface is convex
    towards its facet normals).  Defining ``h_zero`` switches
    ``sq_mean_curvature`` and ``eff_area_sq_mean_curvature`` to the perp
    estimate, as it does their energies.  ``cotan_sq_mean_curvature``: H =
    |S|/(4A) with the cotangent sum S = 2∇A and the mixed area A (Meyer,
    Desbrun, Schröder & Barr 2003), signed by S·N.  h is the curvature
    itself, not h − h0.  NaN in the torus model (stars across the
    periodic wrap are not gathered here).
    """
    s = surface
    if s.periods is not None or s.nf == 0:
        return np.full(s.nv, np.nan)
    t = s.evaluate() if totals is None else totals
    name = method or curvature_method(s)
    with np.errstate(all="ignore"):
        A, F, N = C.star_sums(t)
        if name == "cotan_sq_mean_curvature":
            *_, Sv, Av = C._cotan_parts(t)
            h = np.linalg.norm(Sv, axis=1) / (4.0 * Av)
            h = np.where(np.einsum("ij,ij->i", Sv, N) < 0, -h, h)
        else:
            kind = C._kind(s, name)[0]
            FF = np.einsum("ij,ij->i", F, F)
            FN = np.einsum("ij,ij->i", F, N)
            NN = np.einsum("ij,ij->i", N, N)
            h = {"plain": lambda: 1.5 * np.sqrt(FF) / A,
                 "eff": lambda: 1.5 * np.sqrt(FF / NN),
                 "norm": lambda: 1.5 * FF / FN,
                 "perp": lambda: 1.5 * FN / NN}[kind]()
    return np.where(np.isfinite(h), h, 0.0)


def _flags(masks, n):
    return {f"on_constraint_{cid}": np.asarray(m, bool).astype(np.int32).reshape(n)
            for cid, m in sorted(masks.items())}


def surface_fields(surface, totals=None) -> tuple[dict, dict]:
    """``(vertex_fields, facet_fields)``: dicts of arrays (nv,) and (nf,)
    described in the module docstring."""
    s = surface
    t = s.evaluate() if totals is None else totals
    F = s.F
    area_f = np.asarray(t.facet_area, float)
    area_v = np.bincount(F.ravel(), weights=np.repeat(area_f, 3), minlength=s.nv) / 3.0
    v = {"id": np.asarray(s.ids("vertex"), np.int32),
         "mean_curvature": mean_curvature(s, t),
         "area": area_v,
         "fixed": np.asarray(s.vattr["fixed"], bool).astype(np.int32)}
    v.update(_flags(s.vcon, s.nv))
    if "boundary" in s.vattr:
        v["boundary"] = np.asarray(s.vattr["boundary"], np.int32)
    f = {"id": np.asarray(s.ids("facet"), np.int32),
         "area": area_f,
         "tension": np.asarray(s.facet_tension, float).copy()}
    if "fixed" in s.fattr:
        f["fixed"] = np.asarray(s.fattr["fixed"], bool).astype(np.int32)
    f.update(_flags(s.fcon, s.nf))
    if "boundary" in s.fattr:
        f["boundary"] = np.asarray(s.fattr["boundary"], np.int32)
    return v, f


#: The Evolver's 16 colours (BLACK .. WHITE, manual "Colors"), as RGB in [0, 1].
EVOLVER_COLORS = np.array([
    [0, 0, 0], [0, 0, 1], [0, 0.5, 0], [0, 1, 1], [1, 0, 0], [1, 0, 1], [0.6, 0.4, 0.2],
    [0.75, 0.75, 0.75], [0.5, 0.5, 0.5], [0.5, 0.5, 1], [0.5, 1, 0.5], [0.5, 1, 1],
    [1, 0.5, 0.5], [1, 0.5, 1], [1, 1, 0], [1, 1, 1]], float)


def facet_colors(surface) -> np.ndarray | None:
    """(nf, 3) RGB of the facets' colours when the datafile (or a ``set
    facet color``) gives them more than one colour; None otherwise."""
    c = surface.fattr.get("frontcolor")
    if c is None:
        c = surface.fattr.get("color")
    if c is None:
        return None
    c = np.asarray(c, float)
    if c.shape != (surface.nf,) or len(np.unique(c)) < 2:
        return None
    idx = np.clip(np.nan_to_num(c), 0, 15).astype(int)
    return EVOLVER_COLORS[idx]


def clipped_range(values: np.ndarray, lo: float = 2.0, hi: float = 98.0) -> tuple:
    """A colour range that a few extreme values cannot stretch: the
    ``lo``-th and ``hi``-th percentiles of the finite ``values``, narrowed
    to Tukey's far-out fences (quartiles ∓ 3 interquartile ranges: the mean
    curvature at a fixed boundary, say, is left out), widened when flat."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return 0.0, 1.0
    a, b, q1, q3 = (float(x) for x in np.percentile(v, [lo, hi, 25, 75]))
    a, b = max(a, q1 - 3 * (q3 - q1)), min(b, q3 + 3 * (q3 - q1))
    if b <= a:
        pad = max(abs(a) * 1e-6, 1e-12)
        a, b = a - pad, b + pad
    return a, b
