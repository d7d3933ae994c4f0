"""String-model bending energies at vertices: ``sqcurve_string``,
``sqcurve2_string`` and ``sqcurve3_string``.

Surface Evolver 2.70 manual, "Quantities and methods", with the formulas
evolver-nox-d actually uses (found by experiment, tests/methods/
test_string_curvature.py).  At a vertex with two edges, ``s1`` and ``s2`` the
lengths of the edge coming in and the edge going out (the vertex's two edges,
whatever their orientation), ``c`` the cosine of the exterior angle ``t``
and ``h = (s1 + s2)/2``:

* the Evolver does not use ``t²`` itself but the first two terms of its
  series in ``1 − c``: ``T = 2(1 − c) + (1 − c)²/3`` (exact to O(t⁶));
* ``sqcurve_string``: ``T^(p/2) h^(1−p)``, the integral of ``κ^p`` with
  ``κ = √T / h`` over the length ``h``; ``p`` is the instance's
  ``parameter_1`` or else the variable ``curvature_power`` (default 2, created
  at the first evaluation as the Evolver does).  The manual's
  ``4(1 − cos t)/(s1 + s2)`` is the leading term for ``p = 2``;
* ``sqcurve_string_marked``: ``sqcurve_string`` with only the edges whose
  attribute ``sqcurve_string_mark`` is nonzero (0 at a vertex with one);
* ``sqcurve3_string``: ``T (1/s1 + 1/s2)/2`` (no power);
* ``sqcurve2_string``: ``(σ/h + h₀)² h`` with ``σ`` the sine of the turn
  from the ``xy`` cross product of the vertex's edges taken in the order
  of REF's edge ring (its first edge coming in; so the sign of ``σ``
  follows REF's vertex lists, not the curve's orientation), ``h₀`` the
  vertex attribute or variable ``h_zero``; a method of the plane: ``g``
  with it in space dimension 3 is refused by name (REF's force out of the
  plane was not reproduced).

Vertices with fewer than two edges count 0; vertices with more than two are
refused (the Evolver takes "the first two edges it finds").  Gradients are
analytic; the Hessians are the registry's finite differences of them.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import UnsupportedError
from ..model.string import STRING_METHODS
from .registry import register_method


def _param(s, name: str, default: float) -> float:
    """A variable's value, created with its default at the first use."""
    if name not in s.params:
        s.params[name] = default
    try:
        return float(s.params[name])
    except (TypeError, ValueError):
        return default


def vertex_pairs(s, idx: np.ndarray, marked: bool = False) -> tuple[
        np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For the vertices ``idx`` with two edges: their positions ``k`` in idx,
    the vertices ``v``, the two edges ``e1 < e2``.  Refuses vertices with
    more than two edges.  ``marked``: only the edges whose attribute
    ``sqcurve_string_mark`` is nonzero count (``sqcurve_string_marked``)."""
    E = s.E
    ne = len(E)
    eids = np.arange(ne)
    if marked:
        mark = s.extra.get(("edge", "sqcurve_string_mark"))
        eids = eids[np.asarray(mark, float) != 0] if mark is not None else eids[:0]
    ends = np.concatenate([E[eids, 0], E[eids, 1]])
    eid = np.concatenate([eids, eids])
    order = np.lexsort((eid, ends))
    ends, eid = ends[order], eid[order]
    val = np.bincount(ends, minlength=s.nv)
    idx = np.asarray(idx, np.int64)
    if (val[idx] > 2).any():
        raise UnsupportedError("string curvature methods at vertices with more than two edges",
                               "the Evolver uses the first two edges of its vertex list")
    start = np.concatenate([[0], np.cumsum(val)])[:-1]
    k = np.nonzero(val[idx] == 2)[0]
    v = idx[k]
    e1 = eid[start[v]]
    e2 = eid[start[v] + 1]
    return k, v, e1, e2


def turn_vectors(t, v: np.ndarray, e1: np.ndarray, e2: np.ndarray):
    """The incoming ``t1`` (into ``v`` along ``e1``), outgoing ``t2`` (out of
    ``v`` along ``e2``) vectors, (m, D) each, and the far ends ``a``, ``b``."""
    s = t.surface
    E = s.E
    d1 = t.edge_vec[e1]
    d2 = t.edge_vec[e2]
    head1 = E[e1, 1] == v
    t1 = np.where(head1[:, None], d1, -d1)
    a = np.where(head1, E[e1, 0], E[e1, 1])
    tail2 = E[e2, 0] == v
    t2 = np.where(tail2[:, None], d2, -d2)
    b = np.where(tail2, E[e2, 1], E[e2, 0])
    return t1, t2, a, b


def _geometry(t, idx, marked=False):
    s = t.surface
    k, v, e1, e2 = vertex_pairs(s, idx, marked)
    t1, t2, a, b = turn_vectors(t, v, e1, e2)
    s1 = np.linalg.norm(t1, axis=1)
    s2 = np.linalg.norm(t2, axis=1)
    c = np.einsum("ij,ij->i", t1, t2) / (s1 * s2)
    return k, v, a, b, t1, t2, s1, s2, c


def _series(c):
    """T(c) = 2(1 − c) + (1 − c)²/3 and dT/dc."""
    u = 1.0 - c
    return 2.0 * u + u * u / 3.0, -2.0 - 2.0 * u / 3.0


def _scatter_turn(s, v, a, b, G1, G2):
    """Gradient (nv, D) from derivatives with respect to t1 = x_v − x_a and
    t2 = x_b − x_v."""
    idx = np.concatenate([v, a, v, b])
    vec = np.concatenate([G1, -G1, -G2, G2])
    D = s.X.shape[1]
    out = np.zeros((s.nv, D))
    for j in range(D):
        out[:, j] = np.bincount(idx, weights=vec[:, j], minlength=s.nv)
    return out


def _chain(t1, t2, s1, s2, c, fc, fs1, fs2):
    """∂f/∂t1, ∂f/∂t2 from ∂f/∂c and ∂f/∂s1, ∂f/∂s2 (each (m,))."""
    inv = 1.0 / (s1 * s2)
    dc1 = t2 * inv[:, None] - (c / s1 ** 2)[:, None] * t1
    dc2 = t1 * inv[:, None] - (c / s2 ** 2)[:, None] * t2
    G1 = fc[:, None] * dc1 + (fs1 / s1)[:, None] * t1
    G2 = fc[:, None] * dc2 + (fs2 / s2)[:, None] * t2
    return G1, G2


def _power(m, s) -> float:
    p = getattr(m, "parameter_1", None)
    if p is not None:
        return float(p)
    return _param(s, "curvature_power", 2.0)


# ---- sqcurve_string ----------------------------------------------------------------
def _sqcurve_parts(t, m, idx, marked=False):
    k, v, a, b, t1, t2, s1, s2, c = _geometry(t, idx, marked)
    p = _power(m, t.surface)
    T, dT = _series(c)
    h = 0.5 * (s1 + s2)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = np.where(T > 0, T, 0.0) ** (p / 2.0) * h ** (1.0 - p)
        fT = np.nan_to_num((p / 2.0) * np.where(T > 0, T, 0.0) ** (p / 2.0 - 1.0)
                           * h ** (1.0 - p)) if p != 2 else h ** (1.0 - p)
        fh = (1.0 - p) * f / h
    return k, v, a, b, t1, t2, s1, s2, c, f, fT * dT, fh / 2.0


def sqcurve(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-vertex ``T^(p/2) h^(1−p)``, shape (len(idx),)."""
    out = np.zeros(len(idx))
    parts = _sqcurve_parts(t, m, idx)
    out[parts[0]] = parts[9]
    return out


def sqcurve_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ w_v f_v``."""
    k, v, a, b, t1, t2, s1, s2, c, _, fc, fh = _sqcurve_parts(t, m, idx)
    wk = np.asarray(w, float)[k]
    G1, G2 = _chain(t1, t2, s1, s2, c, wk * fc, wk * fh, wk * fh)
    return _scatter_turn(t.surface, v, a, b, G1, G2)


def sqcurve_marked(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """``sqcurve_string`` over the marked edges only, shape (len(idx),)."""
    out = np.zeros(len(idx))
    parts = _sqcurve_parts(t, m, idx, marked=True)
    out[parts[0]] = parts[9]
    return out


def sqcurve_marked_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ w_v f_v`` over the marked edges."""
    k, v, a, b, t1, t2, s1, s2, c, _, fc, fh = _sqcurve_parts(t, m, idx, marked=True)
    wk = np.asarray(w, float)[k]
    G1, G2 = _chain(t1, t2, s1, s2, c, wk * fc, wk * fh, wk * fh)
    return _scatter_turn(t.surface, v, a, b, G1, G2)


# ---- sqcurve3_string ---------------------------------------------------------------
def sqcurve3(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-vertex ``T (1/s1 + 1/s2)/2``, shape (len(idx),)."""
    out = np.zeros(len(idx))
    k, _, _, _, _, _, s1, s2, c = _geometry(t, idx)
    out[k] = _series(c)[0] * (1.0 / s1 + 1.0 / s2) / 2.0
    return out


def sqcurve3_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ w_v T (1/s1 + 1/s2)/2``."""
    k, v, a, b, t1, t2, s1, s2, c = _geometry(t, idx)
    wk = np.asarray(w, float)[k]
    T, dT = _series(c)
    r = (1.0 / s1 + 1.0 / s2) / 2.0
    G1, G2 = _chain(t1, t2, s1, s2, c, wk * dT * r, -wk * T / (2 * s1 ** 2),
                    -wk * T / (2 * s2 ** 2))
    return _scatter_turn(t.surface, v, a, b, G1, G2)


# ---- sqcurve2_string ---------------------------------------------------------------
def ring_pairs(s, idx):
    """Like :func:`vertex_pairs`, with ``e1`` the vertex's first edge in
    REF's ring (``vattr["ring_head"]``, :mod:`pyevolver.model.string`) and
    ``e2`` the other: the order in which REF "finds" them."""
    k, v, e1, e2 = vertex_pairs(s, idx)
    head = s.vattr.get("ring_head")
    if head is not None:
        swap = head[v] == e2
        e1, e2 = np.where(swap, e2, e1), np.where(swap, e1, e2)
    return k, v, e1, e2


def h_zero(s, v) -> np.ndarray:
    """(m,) the intrinsic curvature at vertices ``v``: the vertex attribute
    ``h_zero`` when declared, else the variable ``h_zero`` (0 when unset)."""
    attr = s.extra.get(("vertex", "h_zero"))
    if attr is not None:
        return np.asarray(attr, float)[v]
    try:
        return np.full(len(v), float(s.params.get("h_zero", 0.0) or 0.0))
    except (TypeError, ValueError):
        return np.zeros(len(v))


def _cross_z(t1, t2):
    return t1[:, 0] * t2[:, 1] - t1[:, 1] * t2[:, 0]


def _sq2_parts(t, idx):
    s = t.surface
    k, v, e1, e2 = ring_pairs(s, idx)
    t1, t2, a, b = turn_vectors(t, v, e1, e2)
    s1 = np.linalg.norm(t1, axis=1)
    s2 = np.linalg.norm(t2, axis=1)
    h = 0.5 * (s1 + s2)
    sg = _cross_z(t1, t2) / (s1 * s2)
    return k, v, a, b, t1, t2, s1, s2, h, sg, h_zero(s, v)


def sqcurve2(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-vertex ``(σ/h + h₀)² h``, σ = (t1 × t2)_z/(s1 s2) with the edges
    in REF's ring order, shape (len(idx),)."""
    out = np.zeros(len(idx))
    k, _, _, _, _, _, _, _, h, sg, h0 = _sq2_parts(t, idx)
    out[k] = (sg / h + h0) ** 2 * h
    return out


def sqcurve2_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """What ``g`` moves by: :func:`sqcurve2_full_gradient` in the plane,
    refused by name in space (REF's force there differs)."""
    if t.surface.sdim > 2:
        raise UnsupportedError("the gradient of method sqcurve2_string in space dimension 3",
                               "a method of the plane: REF's force out of it was not "
                               "reproduced")
    return sqcurve2_full_gradient(t, m, idx, w)


def sqcurve2_full_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, D) of ``Σ w_v (σ/h + h₀)² h`` = ``Σ w_v (σ²/h + 2h₀σ + h₀²h)``."""
    k, v, a, b, t1, t2, s1, s2, h, sg, h0 = _sq2_parts(t, idx)
    wk = np.asarray(w, float)[k]
    fs = wk * (2.0 * sg / h + 2.0 * h0)                     # ∂f/∂σ
    fh = wk * (-(sg / h) ** 2 + h0 * h0)                    # ∂f/∂h
    fcz = fs / (s1 * s2)
    fs1 = -fs * sg / s1 + 0.5 * fh
    fs2 = -fs * sg / s2 + 0.5 * fh
    G1 = (fs1 / s1)[:, None] * t1
    G2 = (fs2 / s2)[:, None] * t2
    G1[:, 0] += fcz * t2[:, 1]
    G1[:, 1] -= fcz * t2[:, 0]
    G2[:, 0] -= fcz * t1[:, 1]
    G2[:, 1] += fcz * t1[:, 0]
    return _scatter_turn(t.surface, v, a, b, G1, G2)


register_method("sqcurve_string", "vertex", sqcurve, sqcurve_gradient)
register_method("sqcurve_string_marked", "vertex", sqcurve_marked, sqcurve_marked_gradient)
register_method("sqcurve3_string", "vertex", sqcurve3, sqcurve3_gradient)
register_method("sqcurve2_string", "vertex", sqcurve2, sqcurve2_gradient,
                no_hessian="REF: the method has no Hessian (manual)")
STRING_METHODS.update({"sqcurve_string", "sqcurve2_string", "sqcurve3_string",
                       "sqcurve_string_marked"})


# ---- the vertex attribute mean_curvature ------------------------------------------
def string_mean_curvature(s, t) -> np.ndarray:
    """(nv,) the string model's vertex ``mean_curvature`` (REF's values):
    ``σ F·N/(N·N)`` with the vertex's edges in REF's ring order
    (:func:`ring_pairs`), ``a`` and ``b`` the far ends of the first and the
    second edge, ``F = u(b − v) − u(v − a)`` (u: unit vector; minus the
    length gradient), ``N = rot90(x_b − x_a)/2`` in the xy plane and ``σ``
    +1 when the first edge comes into the vertex, −1 when it goes out.  0 at
    vertices with one edge."""
    k, v, e1, e2 = ring_pairs(s, np.arange(s.nv))
    t1, t2, a, b = turn_vectors(t, v, e1, e2)
    F = t2 / np.linalg.norm(t2, axis=1)[:, None] - t1 / np.linalg.norm(t1, axis=1)[:, None]
    d = t1 + t2
    N = 0.5 * np.stack([-d[:, 1], d[:, 0]], axis=1)
    sign = np.where(s.E[e1, 1] == v, 1.0, -1.0)
    out = np.zeros(s.nv)
    with np.errstate(divide="ignore", invalid="ignore"):
        out[v] = sign * np.einsum("ij,ij->i", F[:, :2], N) / np.einsum("ij,ij->i", N, N)
    return out
