"""Edge springs: ``hooke_energy``, ``hooke2_energy``, ``hooke3_energy`` and
the bending spring ``dihedral_hooke``.

Surface Evolver 2.70 manual, "Quantities and methods" (hooke_energy,
hooke2_energy, hooke3_energy, dihedral_hooke), with the defaults evolver-nox-d
actually uses (tests/methods/test_springs.py):

* ``hooke_energy``: ``|L − L₀|^p`` per edge, ``L₀`` the variable ``hooke_length``
  and ``p`` the variable ``hooke_power`` (default 2); ``p = 0`` gives
  ``−log|L − L₀|``.  When ``hooke_length`` is not set it is 0 in 2.70 (the
  manual's "average edge length of the initial datafile" is not what the
  program does), so the energy is then ``Σ L^p``.
* ``hooke2_energy``: the same with each edge's own rest length, the edge
  attribute ``hooke_size``, and the power ``hooke2_power``.  When the datafile
  does not declare ``hooke_size`` it is created at the first evaluation with
  the edges' current lengths; a declared ``hooke_size`` is used as it is.
* ``hooke3_energy``: ``½ |L − s|^p / s`` with ``s = hooke_size`` and
  ``p = hooke3_power``; ``p = 0`` gives ``−log|L − s|``; with
  ``frickenhaus_flag`` nonzero, edges shorter than ``s`` cost nothing.
* ``dihedral_hooke``: ``(1 − cos θ) L`` per edge with two facets, ``θ`` the
  angle between their normals (oriented alike across the edge); an edge with
  one facet counts ``2 L`` (θ = π) as in evolver-nox-d; edges with more than
  two facets are refused.

Gradients are analytic; so are the Hessians of the three ``hooke`` methods
(``dihedral_hooke`` uses the registry's finite differences of the gradient).
"""
from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import UnsupportedError
from ..model.records import edge_facets
from ..model.string import STRING_METHODS
from ._common import assemble, facet_points, n2_grad_dot, scatter
from .registry import register_method


def _param(s, name: str, default: float) -> float:
    """A variable's value.  The method's own variables (``hooke_length`` and
    ``hooke_power``, ``hooke2_power``, ``hooke3_power``) are created with their
    defaults when the method is first evaluated, as the Evolver does (they can
    then be printed and assigned); ``frickenhaus_flag`` is read only."""
    if name != "frickenhaus_flag" and name not in s.params:
        s.params[name] = default
    v = s.params.get(name)
    try:
        return default if v is None else float(v)
    except (TypeError, ValueError):
        return default


def _power_law(d: np.ndarray, p: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``f(d) = |d|^p`` (``−log|d|`` for p = 0) and its first and second
    derivatives, each (n,)."""
    ad = np.abs(d)
    sg = np.sign(d)
    with np.errstate(divide="ignore", invalid="ignore"):
        if p == 0:
            return -np.log(ad), -1.0 / d, 1.0 / d ** 2
        f = ad ** p
        f1 = p * ad ** (p - 1) * sg if p != 1 else sg
        f2 = p * (p - 1) * ad ** (p - 2) if p not in (1, 2) else np.full_like(d, 2.0 if p == 2
                                                                                 else 0.0)
    return f, f1, f2


def _edge_grad(t, idx, dEdL):
    """Gradient (nv, 3) from per-edge ``dE/dL`` (n,)."""
    s = t.surface
    d = t.edge_vec[idx]
    L = t.edge_length[idx]
    with np.errstate(divide="ignore", invalid="ignore"):
        g = np.nan_to_num((dEdL / L)[:, None] * d)
    return scatter(s.nv, s.E[idx, 1], g) - scatter(s.nv, s.E[idx, 0], g)


# ---- hooke_energy ------------------------------------------------------------------
def hooke(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``|L − hooke_length|^hooke_power``, shape (len(idx),)."""
    s = t.surface
    d = t.edge_length[idx] - _param(s, "hooke_length", 0.0)
    return _power_law(d, _param(s, "hooke_power", 2.0))[0]


def hooke_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, 3) of ``Σ w_e |L_e − L₀|^p``."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    d = t.edge_length[idx] - _param(s, "hooke_length", 0.0)
    f1 = _power_law(d, _param(s, "hooke_power", 2.0))[1]
    return _edge_grad(t, idx, np.asarray(w, float) * f1)


def hooke_hessian(t: Any, m: Any, idx: np.ndarray, w: np.ndarray,
                  basis: Any = None) -> Any:
    """Analytic Hessian of ``Σ w_e |L_e − L₀|^p`` (:func:`_spring_hessian`)."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    d = t.edge_length[idx] - _param(s, "hooke_length", 0.0)
    _, f1, f2 = _power_law(d, _param(s, "hooke_power", 2.0))
    return _spring_hessian(t, idx, w, f1, f2, basis)


def _spring_hessian(t, idx, w, f1, f2, basis):
    """Per-edge blocks ``[[K, −K], [−K, K]]`` of ``Σ w_e f(L_e)`` with
    ``K = f'' u uᵀ + (f'/L)(I − u uᵀ)``, ``u`` the unit edge vector."""
    s = t.surface
    L = t.edge_length[idx]
    w = np.asarray(w, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.nan_to_num(t.edge_vec[idx] / L[:, None])
        uu = np.einsum("ni,nj->nij", u, u)
        K = ((w * f2)[:, None, None] * uu
             + np.nan_to_num(w * f1 / L)[:, None, None] * (np.eye(3)[None] - uu))
    B = np.stack([np.stack([K, -K], 1), np.stack([-K, K], 1)], 1)
    return assemble(s.nv, s.E[idx], B, basis)


# ---- hooke2_energy, hooke3_energy ----------------------------------------------------
def hooke_size(t) -> np.ndarray:
    """(ne,) the edge attribute ``hooke_size``, created from the current edge
    lengths when the datafile did not declare it (as the Evolver does)."""
    s = t.surface
    key = ("edge", "hooke_size")
    arr = s.extra.get(key)
    if arr is None or len(arr) != s.ne:
        arr = np.array(t.edge_length, float)
        s.extra[key] = arr
    return np.asarray(arr, float)


def hooke2(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``|L − hooke_size|^hooke2_power``, shape (len(idx),)."""
    d = t.edge_length[idx] - hooke_size(t)[idx]
    return _power_law(d, _param(t.surface, "hooke2_power", 2.0))[0]


def hooke2_hessian(t: Any, m: Any, idx: np.ndarray, w: np.ndarray,
                   basis: Any = None) -> Any:
    """Analytic Hessian of ``Σ w_e |L_e − s_e|^p`` (:func:`_spring_hessian`)."""
    idx = np.asarray(idx, np.int64)
    d = t.edge_length[idx] - hooke_size(t)[idx]
    _, f1, f2 = _power_law(d, _param(t.surface, "hooke2_power", 2.0))
    return _spring_hessian(t, idx, w, f1, f2, basis)


def hooke2_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, 3) of ``Σ w_e |L_e − s_e|^p``."""
    idx = np.asarray(idx, np.int64)
    d = t.edge_length[idx] - hooke_size(t)[idx]
    f1 = _power_law(d, _param(t.surface, "hooke2_power", 2.0))[1]
    return _edge_grad(t, idx, np.asarray(w, float) * f1)


def _hooke3_parts(t, idx):
    s = t.surface
    size = hooke_size(t)[idx]
    d = t.edge_length[idx] - size
    p = _param(s, "hooke3_power", 2.0)
    f, f1, f2 = _power_law(d, p)
    if p != 0:
        with np.errstate(divide="ignore", invalid="ignore"):
            f, f1, f2 = 0.5 * f / size, 0.5 * f1 / size, 0.5 * f2 / size
    if _param(s, "frickenhaus_flag", 0.0):
        f, f1, f2 = (np.where(d < 0, 0.0, x) for x in (f, f1, f2))
    return f, f1, f2


def hooke3(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``½ |L − s|^p / s``, shape (len(idx),)."""
    return _hooke3_parts(t, idx)[0]


def hooke3_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, 3) of ``Σ w_e ½ |L_e − s_e|^p / s_e``."""
    idx = np.asarray(idx, np.int64)
    return _edge_grad(t, idx, np.asarray(w, float) * _hooke3_parts(t, idx)[1])


def hooke3_hessian(t: Any, m: Any, idx: np.ndarray, w: np.ndarray,
                   basis: Any = None) -> Any:
    """Analytic Hessian of ``Σ w_e ½ |L_e − s_e|^p / s_e`` (:func:`_spring_hessian`)."""
    idx = np.asarray(idx, np.int64)
    _, f1, f2 = _hooke3_parts(t, idx)
    return _spring_hessian(t, idx, w, f1, f2, basis)


# ---- dihedral_hooke ------------------------------------------------------------------
def _dihedral_parts(t, idx):
    """For the edges ``idx`` with two facets: positions ``k`` in idx, the
    facets ``fa, fb``, the sign making ``fb``'s normal consistent, normals
    ``Na, Nb`` (already signed), their lengths and ``cos θ``."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    ef, ek, val = edge_facets(s)
    k = np.nonzero(val[idx] == 2)[0]
    e = idx[k]
    fa, fb = ef[e, 0], ef[e, 1]
    sa = np.where(s.FE[fa, ek[e, 0]] >= 0, 1.0, -1.0)
    sb = np.where(s.FE[fb, ek[e, 1]] >= 0, 1.0, -1.0)
    sig = -sa * sb
    Na = t.facet_N2[fa]
    Nb = t.facet_N2[fb] * sig[:, None]
    la = np.linalg.norm(Na, axis=1)
    lb = np.linalg.norm(Nb, axis=1)
    with np.errstate(all="ignore"):
        c = np.nan_to_num(np.einsum("ij,ij->i", Na, Nb) / (la * lb), nan=1.0)
    return k, e, fa, fb, sig, Na, Nb, la, lb, c


def _valence(t, idx):
    """(len(idx),) facets per edge; edges with more than two are refused."""
    s = t.surface
    val = np.bincount(s.topology()[0].ravel(), minlength=s.ne)[np.asarray(idx, np.int64)]
    if (val > 2).any():
        raise UnsupportedError("dihedral_hooke on edges with more than two facets")
    return val


def dihedral_hooke(t: Any, m: Any, idx: np.ndarray) -> np.ndarray:
    """Per-edge ``(1 − cos θ) L``; ``2 L`` on an edge with one facet (the
    Evolver's value), 0 on an edge with none."""
    out = np.zeros(len(idx))
    if t.surface.nf == 0:
        return out
    val = _valence(t, idx)
    k, e, _, _, _, _, _, _, _, c = _dihedral_parts(t, idx)
    out[k] = (1.0 - c) * t.edge_length[e]
    one = val == 1
    out[one] = 2.0 * t.edge_length[np.asarray(idx, np.int64)[one]]
    return out


def dihedral_hooke_gradient(t: Any, m: Any, idx: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Gradient (nv, 3) of ``Σ w_e (1 − cos θ_e) L_e``:
    ``−L ∂cos + (1 − cos) ∂L`` with ``∂cos/∂N_a = (n_b − c n_a)/|N_a|``."""
    s = t.surface
    g = np.zeros((s.nv, 3))
    if s.nf == 0:
        return g
    w = np.asarray(w, float)
    one = _valence(t, idx) == 1
    g += _edge_grad(t, np.asarray(idx, np.int64)[one], 2.0 * w[one])
    k, e, fa, fb, sig, Na, Nb, la, lb, c = _dihedral_parts(t, idx)
    L = t.edge_length[e]
    we = w[k]
    g += _edge_grad(t, e, we * (1.0 - c))
    with np.errstate(all="ignore"):
        na = np.nan_to_num(Na / la[:, None])
        nb = np.nan_to_num(Nb / lb[:, None])
        Da = np.nan_to_num((nb - c[:, None] * na) / la[:, None])
        Db = np.nan_to_num((na - c[:, None] * nb) / lb[:, None]) * sig[:, None]
    coef = (-we * L)[:, None]
    P = facet_points(t)
    ga = n2_grad_dot(P[fa], coef * Da)
    gb = n2_grad_dot(P[fb], coef * Db)
    F = s.F
    g += scatter(s.nv, F[fa].ravel(), ga.reshape(-1, 3))
    g += scatter(s.nv, F[fb].ravel(), gb.reshape(-1, 3))
    return g


register_method("hooke_energy", "edge", hooke, hooke_gradient, hooke_hessian)
register_method("hooke2_energy", "edge", hooke2, hooke2_gradient, hooke2_hessian)
register_method("hooke3_energy", "edge", hooke3, hooke3_gradient, hooke3_hessian)
register_method("dihedral_hooke", "edge", dihedral_hooke, dihedral_hooke_gradient)
STRING_METHODS.update({"hooke_energy", "hooke2_energy", "hooke3_energy"})   # edges only
