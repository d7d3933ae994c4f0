"""The mobility of ``g``: how a step turns forces into velocities.

The Evolver's manual (model.htm, "Mobility"): the velocity is ``M f`` for a
mobility tensor M, and "the same inner product has to be used in projecting
the velocity tangent to the constraints".  Implemented here:

* unit mobility (the default): M = I;
* ``area_normalization``: M = diag(1 / a_v), a_v one third of the area of
  vertex v's star of facets (one half of the length of its star of edges in
  the string model);
* ``approximate_curvature``: M = S⁻¹ with S the mass matrix of the linear
  interpolation over the facets (edges in the string model).

The iterator applies M to the tangent-projected force and to the
tangent-projected constraint gradients, so the Lagrange multipliers
(pressures) and the restoring motions are those of the metric.  Measured on
evolver-nox-d by printing ``v_velocity`` (cube.fe: with area normalization
the corner velocity 1.2 and face-centre velocity 2.4 are those of
``M (f - λ g)`` with ``λ = g·M f / g·M g``).
"""
from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp


def star_measure(t: Any) -> np.ndarray:
    """Per-vertex area associated with each vertex, shape (nv,).

    One third of the total area of the facets around the vertex; in the
    string model one half of the total length of its edges (toggle.htm,
    AREA_NORMALIZATION); in the simplex model 1/(k+1) of the k-volumes of
    its facets (REF's ``v_velocity / v_force``, measured).
    """
    s = t.surface
    if getattr(s, "simplex", 0):        # the simplex model: 1/(k+1) of each facet
        k1 = s.SF.shape[1]
        return np.bincount(s.SF.ravel(), weights=np.repeat(t.facet_area, k1),
                           minlength=s.nv) / k1
    if s.string or s.nf == 0 and s.ne:
        L = t.edge_length
        return (np.bincount(s.E[:, 0], weights=L, minlength=s.nv)
                + np.bincount(s.E[:, 1], weights=L, minlength=s.nv)) / 2.0
    A = np.repeat(t.facet_area, 3)
    return np.bincount(s.F.ravel(), weights=A, minlength=s.nv) / 3.0


def mass_matrix(t: Any) -> sp.csr_matrix:
    """The mass matrix (nv, nv) of linear interpolation: ∫ φ_i φ_j over the
    facets, A/12 (2 on the diagonal, 1 off it) per triangle of area A; over
    the edges in the string model, L/6 (2, 1) per edge of length L
    (model.htm, "Approximate polyhedral curvature")."""
    s = t.surface
    if s.string or s.nf == 0 and s.ne:
        V, w = s.E, t.edge_length / 6.0
    else:
        V, w = s.F, t.facet_area / 12.0
    k = V.shape[1]
    rows = np.repeat(V, k, axis=1).ravel()
    cols = np.tile(V, (1, k)).ravel()
    vals = (w[:, None] * (np.ones((k, k)) + np.eye(k)).ravel()[None, :]).ravel()
    return sp.csr_matrix((vals, (rows, cols)), shape=(s.nv, s.nv))


class Mobility:
    """The force-to-velocity conversion of one ``g`` step.

    Parameters
    ----------
    t : Totals
        The evaluation the conversion is taken at.
    area_normalization : bool
        M = diag(1 / star measure).
    """

    def __init__(self, t: Any, area_normalization: bool = False,
                 approximate_curvature: bool = False, mobile: np.ndarray | None = None):
        self.diag: np.ndarray | None = None
        self.lu: Any = None
        if approximate_curvature:
            S = mass_matrix(t)
            keep = np.ones(S.shape[0], bool) if mobile is None else np.asarray(mobile, bool)
            bnd = t.surface.vattr.get("boundary")
            if bnd is not None:
                # REF moves no vertex of a parametric boundary (cat.fe with its
                # rings free: the fixed rings' numbers)
                keep = keep & (bnd == 0)
            self.keep = np.nonzero(keep)[0]
            if len(self.keep):
                import scipy.sparse.linalg as spla   # 0.08 s at start-up: when first used
                self.lu = spla.splu(S[self.keep][:, self.keep].tocsc())
            return
        if area_normalization:
            a = star_measure(t)
            with np.errstate(divide="ignore"):
                self.diag = np.where(a > 0, 1.0 / np.where(a > 0, a, 1.0), 0.0)

    @property
    def identity(self) -> bool:
        """True for unit mobility."""
        return self.diag is None and self.lu is None

    def apply(self, vecs: list[np.ndarray]) -> list[np.ndarray]:
        """``M v`` for each (nv, dim) array of ``vecs``."""
        if self.lu is not None:
            out = []
            for v in vecs:
                w = np.zeros_like(v)
                w[self.keep] = self.lu.solve(np.ascontiguousarray(v[self.keep]))
                out.append(w)
            return out
        if self.diag is None:
            return vecs
        return [v * self.diag[:, None] for v in vecs]


def vertex_normals(t: Any) -> np.ndarray:
    """Per-vertex normals (nv, 3) of ``normal_motion``: the gradient of the
    volume, Σ over the vertex's facets of N/6 with N the facet's normal
    (x1 - x0) × (x2 - x0) (toggle.htm NORMAL_MOTION: "surface normal,
    defined as the volume gradient")."""
    s = t.surface
    N = np.repeat(t.facet_N2 / 6.0, 3, axis=0)
    out = np.zeros((s.nv, 3))
    for k in range(3):
        out[:, k] = np.bincount(s.F.ravel(), weights=N[:, k], minlength=s.nv)
    return out


def normal_project(t: Any, vel: np.ndarray) -> np.ndarray:
    """``vel`` (nv, 3) projected per vertex on the line of its normal
    (:func:`vertex_normals`); zero where the normal vanishes."""
    n = vertex_normals(t)
    nn = np.einsum("ij,ij->i", n, n)
    c = np.einsum("ij,ij->i", vel, n)
    with np.errstate(divide="ignore", invalid="ignore"):
        k = np.where(nn > 0, c / np.where(nn > 0, nn, 1.0), 0.0)
    return n * k[:, None]


def diffuse(t: Any, coeff: float, scale: float) -> np.ndarray:
    """The target volume changes (nb,) of one ``g`` step's gas diffusion.

    iterate.htm, "Diffusion": across each facet the amount
    ``scale * diffusion_constant * facet_area * pressure_difference`` goes
    from the body of higher pressure to the other (the outside has pressure
    0); the facet attribute ``facet_diffusion``, when defined, replaces the
    constant facet by facet.  The pressures are the bodies' current Lagrange
    multipliers (those of the last step: REF changes nothing on the first
    ``g`` of a file), the scale the current one (measured on a two-cube
    file: after ``g 2`` the targets moved by 0.1 * 0.181284 * A * p with the
    first step's scale and pressures and the facet areas after it).
    """
    s = t.surface
    b = s.bodies
    p = np.where(np.isnan(b.target), np.nan_to_num(b.pressure), b.lagrange)
    B = b.facet_matrix.tocsr()
    dp = B.T @ p                                    # (nf,) p(+ side) - p(- side)
    k = s.extra.get(("facet", "facet_diffusion"))
    w = (np.full(s.nf, coeff) if k is None else np.asarray(k, float)) * t.facet_area * dp
    return -scale * (B @ w)


def jiggle_vertices(s: Any, temperature: float, rng: np.random.Generator) -> np.ndarray:
    """Jiggle a surface in place (the ``jiggle`` toggle's perturbation of
    each ``g`` step): every vertex not FIXED nor on a parametric boundary
    moves by a Gaussian displacement of deviation ``temperature`` times the
    mean edge length (single.htm, ``j``), in the first ``sdim`` coordinates.

    Returns the indices (m,) of the moved vertices (the caller projects
    them to their constraints).  Random, so not REF's numbers: seeded by
    the caller's generator.
    """
    sigma = temperature * (float(np.mean(s.evaluate().edge_length)) if s.ne else 0.0)
    move = ~s.vattr["fixed"]
    if "boundary" in s.vattr:
        move &= s.vattr["boundary"] == 0
    idx = np.nonzero(move)[0]
    X = s.X.copy()
    X[idx, :s.sdim] += sigma * rng.standard_normal((len(idx), s.sdim))
    s.X = X
    return idx
