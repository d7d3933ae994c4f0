"""Triangulated surfaces of revolution for the discrete phase study.

A generating curve ``(r(s), z(s))`` from pole to pole (``r = 0`` at both
ends, ``s`` arclength; e.g. the profile of an axisymmetric reference
:class:`~pyevolver.studies.axisymmetric.CanhamResult`) is revolved about the
z axis into a closed triangle mesh of about ``nv`` vertices with
near-equilateral triangles everywhere, also in a stomatocyte's narrow neck:
rings of vertices at equal arclength steps (the height of an equilateral
triangle of side ``h``, ``√3 nv h²/2 ≈ A``), each ring with
``round(2π r / h)`` vertices (at least 3; a graded mesh, ``min_ring``,
lowers the local ``h`` where a ring would get fewer than that), consecutive rings joined by the
"zipper" that always advances on the ring whose next vertex comes first in
angle, and a vertex on each pole joined to its ring by a fan.  The mesh is
oriented outwards (positive enclosed volume).
"""
from __future__ import annotations

import math

import numpy as np

from .vesicle_shapes import area_volume


def _zipper(a_idx, a_ang, b_idx, b_ang):
    """Triangles joining ring a to ring b (indices, angles in [0, 2π)):
    ``len(a) + len(b)`` triangles, oriented as ``(a_i, a_i+1, b_j)`` and
    ``(a_i, b_j+1, b_j)``."""
    na, nb = len(a_idx), len(b_idx)
    if na == 1 or nb == 1:                   # a pole: a fan
        if na == 1:
            return [(a_idx[0], b_idx[(j + 1) % nb], b_idx[j]) for j in range(nb)]
        return [(a_idx[i], a_idx[(i + 1) % na], b_idx[0]) for i in range(na)]
    # start both rings at their vertex of smallest angle; unroll the angles
    i0, j0 = int(np.argmin(a_ang)), int(np.argmin(b_ang))
    ai = np.roll(a_idx, -i0)
    bi = np.roll(b_idx, -j0)
    aa = np.unwrap(np.roll(a_ang, -i0))
    ba = np.unwrap(np.roll(b_ang, -j0))
    aa = np.append(aa, aa[0] + 2 * np.pi)
    ba = np.append(ba, ba[0] + 2 * np.pi)
    ai = np.append(ai, ai[0])
    bi = np.append(bi, bi[0])
    out = []
    i = j = 0
    while i < na or j < nb:
        if j >= nb or (i < na and aa[i + 1] <= ba[j + 1]):
            out.append((ai[i], ai[i + 1], bi[j]))
            i += 1
        else:
            out.append((ai[i], bi[j + 1], bi[j]))
            j += 1
    return out


def revolve(s: np.ndarray, r: np.ndarray, z: np.ndarray, nv: int,
            area: float | None = None, min_ring: int = 3,
            rng: np.random.Generator | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Revolve the generating curve ``(r(s), z(s))`` into a closed mesh.

    Parameters
    ----------
    s, r, z : ndarray
        The curve sampled from pole (``r = 0``) to pole, ``s`` increasing.
    nv : int
        Target number of vertices (the result has about as many).
    area : float, optional
        Scale the mesh to this total area (default: as revolved).
    min_ring : int, optional
        Fewest vertices on a ring away from the poles (default 3).  Above
        3 the mesh is graded: where ``2π r / h`` would give fewer (a
        stomatocyte's neck narrower than the mesh size), the local edge
        length drops to ``2π r / min_ring`` and the rings there come closer
        in proportion, so the triangles stay near-equilateral.  Within
        ``2h`` of a pole the length stays ``h``.
    rng : numpy Generator, optional
        Rotate each ring by a random angle (uniform over one vertex
        spacing) instead of every other ring by half a spacing: another
        triangulation of the same surface (the "zipper" joins the rings
        differently), for the spread of a result over starting meshes.

    Returns
    -------
    X (nv, 3), F (nf, 3)
    """
    s, r, z = (np.asarray(a, dtype=float) for a in (s, r, z))
    L = s[-1] - s[0]
    seg = np.hypot(np.diff(r), np.diff(z))
    A = float(np.sum(np.pi * (r[1:] + r[:-1]) * seg))
    h = math.sqrt(2 * A / (math.sqrt(3) * max(nv, 8)))
    # the local edge length along the curve and the rings equidistributed
    # in arclength / (its triangles' height)
    hloc = np.full(len(s), h)
    if min_ring > 3:
        far = np.minimum(s - s[0], s[-1] - s) > 2 * h
        hloc[far] = np.minimum(h, 2 * np.pi * r[far] / min_ring)
    rate = 2.0 / (math.sqrt(3) * hloc)                    # rings per unit arclength
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(s))])
    m = max(2, int(round(cum[-1])))
    sj = np.interp(cum[-1] * np.arange(m + 1) / m, cum, s)
    rj = np.interp(sj, s, r)
    zj = np.interp(sj, s, z)
    hj = np.interp(sj, s, hloc)
    pts, rings, angs = [], [], []
    for j in range(m + 1):
        n = 1 if j in (0, m) else max(min_ring, int(round(2 * np.pi * rj[j] / hj[j])))
        shift = 0.5 * (j % 2) if rng is None else rng.uniform()
        ang = (2 * np.pi * (np.arange(n) + shift) / n) % (2 * np.pi)
        rr = 0.0 if n == 1 else rj[j]
        first = sum(len(p) for p in pts)
        pts.append(np.stack([rr * np.cos(ang), rr * np.sin(ang), np.full(n, zj[j])], 1))
        rings.append(np.arange(first, first + n))
        angs.append(ang)
    X = np.vstack(pts)
    tris = []
    for j in range(m):
        tris += _zipper(rings[j], angs[j], rings[j + 1], angs[j + 1])
    F = np.array(tris, dtype=np.int64)
    if area_volume(X, F)[1] < 0:
        F = F[:, ::-1].copy()
    if area is not None:
        X = X * math.sqrt(area / area_volume(X, F)[0])
    return X, F


def mesh_quality(X: np.ndarray, F: np.ndarray) -> dict:
    """Quality numbers of a triangle mesh: the smallest angle (degrees),
    the mean edge length ``h`` and the largest ratio of a triangle's
    longest edge to its inradius, divided by that ratio for the
    equilateral triangle (``2√3``; 1 is perfect)."""
    P = X[F]
    e = np.stack([np.linalg.norm(P[:, (k + 1) % 3] - P[:, k], axis=1) for k in range(3)], 1)
    area = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    inradius = 2 * area / e.sum(1)
    cosines = []
    for k in range(3):
        u = P[:, (k + 1) % 3] - P[:, k]
        v = P[:, (k + 2) % 3] - P[:, k]
        cosines.append(np.einsum("ij,ij->i", u, v) / (np.linalg.norm(u, axis=1)
                                                       * np.linalg.norm(v, axis=1)))
    ang = np.degrees(np.arccos(np.clip(np.stack(cosines, 1), -1, 1)))
    with np.errstate(divide="ignore"):
        aspect = float(np.max(e.max(1) / inradius) / (2 * math.sqrt(3)))
    return {"min_angle_deg": float(ang.min()), "h": float(e.mean()), "aspect": aspect}
