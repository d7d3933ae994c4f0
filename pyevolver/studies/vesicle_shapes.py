"""Figure 4's vesicles: start shapes, datafiles and shape descriptors.

The geometry of :mod:`pyevolver.studies.fig4_vesicles` (the study runner):
area, volume, reduced volume and smallest angle of a closed triangle mesh,
the start shape of each branch (a deformed icosphere at the branch's reduced
volume and area 4π), its datafile, and the symmetry descriptors that tell a
prolate, a discocyte and a stomatocyte apart.
"""
from __future__ import annotations

import math
import os

import numpy as np
from scipy.optimize import brentq

from .axisymmetric import CanhamResult
from .meshes import icosphere, write_fe

HERE = os.path.dirname(os.path.abspath(__file__))
PAPER = os.path.join(HERE, "..", "..", "datafiles", "paper")
RECIPE = "vesicle_recipe.cmd"

#: shape -> (reduced volume, branch of the axisymmetric reference)
SHAPES = {"stomatocyte": (0.50, "stomatocyte"), "discocyte": (0.62, "oblate"),
          "prolate": (0.85, "prolate")}
#: sine modes of the reference per shape (converged to ≤ 1e-7 relative, see docs/paper.md)
REFERENCE_MODES = {"stomatocyte": 128, "discocyte": 24, "prolate": 24}
#: vertex count -> icosphere level
LEVELS = {162: 2, 642: 3, 2562: 4, 10242: 5}
METHODS = {
    "normal": ("normal_sq_mean_curvature", "NormalCur+harmonic"),
    "normal_u": ("normal_sq_mean_curvature", "NormalCur+harmonic+u"),
    "perp": ("star_perp_sq_mean_curvature", "StarPerp+Evolver recipe"),
    "perp_newton": ("star_perp_sq_mean_curvature", "StarPerp+recipe+Newton"),
}


# -- geometry of triangle meshes ------------------------------------------------------------

def area_volume(X: np.ndarray, F: np.ndarray) -> tuple[float, float]:
    """Total area and enclosed volume of the closed mesh ``(X (nv, 3), F (nf, 3))``."""
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    A = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    V = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    return float(A), float(V)


def reduced_volume(X: np.ndarray, F: np.ndarray) -> float:
    """``v = 3V/(4π) / (A/(4π))^{3/2}`` (1 for a sphere)."""
    A, V = area_volume(X, F)
    return 3.0 * V / (4 * np.pi) / (A / (4 * np.pi)) ** 1.5


def min_angle(X: np.ndarray, F: np.ndarray) -> float:
    """Smallest corner angle of the triangles, in degrees."""
    P = X[F]
    out = np.inf
    for k in range(3):
        u = P[:, (k + 1) % 3] - P[:, k]
        v = P[:, (k + 2) % 3] - P[:, k]
        ang = np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("ij,ij->i", u, v))
        out = min(out, float(ang.min()))
    return math.degrees(out)


def _deform(X, shape, p):
    """The initial shape family of each branch at parameter ``p``."""
    if shape in ("prolate", "discocyte"):
        return X * np.array([1.0, 1.0, p])              # ellipsoid, semi-axes 1, 1, p
    # a sphere whose cap z > p is reflected (smoothly) into the inside: a cup
    eps = 0.08
    out = X.copy()
    out[:, 2] = X[:, 2] - 2 * eps * np.logaddexp(0.0, (X[:, 2] - p) / eps)
    return out


def initial_shape(shape: str, level: int) -> tuple[np.ndarray, np.ndarray]:
    """The start of a run: the icosphere of ``level`` deformed into the
    shape's family (prolate: an ellipsoid of revolution stretched along z;
    discocyte: one flattened along z; stomatocyte: a sphere with its top cap
    pushed in) at exactly the shape's reduced volume, scaled to area 4π.

    Returns ``X (nv, 3)``, ``F (nf, 3)``.
    """
    v0 = SHAPES[shape][0]
    X, F = icosphere(level)
    lo, hi = {"prolate": (1.0, 8.0), "discocyte": (0.02, 1.0),
              "stomatocyte": (-0.9, 0.99)}[shape]
    p = brentq(lambda p: reduced_volume(_deform(X, shape, p), F) - v0, lo, hi, xtol=1e-15)
    Y = _deform(X, shape, p)
    return Y * math.sqrt(4 * np.pi / area_volume(Y, F)[0]), F


# -- datafiles ------------------------------------------------------------------------------

def write_datafile(path: str, X: np.ndarray, F: np.ndarray, shape: str, method: str) -> str:
    """Write the Canham problem on ``(X, F)`` as an Evolver datafile.

    ``method`` "perp": ``star_perp_sq_mean_curvature`` (loads in
    ``evolver-nox-d`` too); "normal": ``normal_sq_mean_curvature`` plus the
    quantity ``harm`` (``harmonic_energy``, modulus λ = 1; pyevolver only).
    """
    v0 = SHAPES[shape][0]
    energy = METHODS[method][0]
    lines = [f"// Figure 4 of the PL-methods paper: the Canham problem, {shape} branch,",
             "// reduced volume v0, area 4*pi (FIXED quantity surf), volume v0*4*pi/3",
             "// (body 1), W = sum over vertices of h^2 A/3 (a sphere: 4*pi).",
             "// Written by pyevolver.studies.fig4_vesicles.",
             f"parameter v0 = {v0}",
             f"quantity willmore energy method {energy} global",
             "quantity surf fixed = 4*pi method facet_area global"]
    if method == "normal":
        lines += ["// harmonic energy regularization (1/sqrt 3) sum |e|^2; modulus = lambda",
                  "quantity harm energy modulus 1 method harmonic_energy global"]
    write_fe(path, X, F, header="\n".join(lines), face_attrs="tension 0")
    with open(path, "a") as fh:
        fh.write("\nbodies\n1 " + " ".join(str(i + 1) for i in range(len(F)))
                 + " volume v0*4*pi/3\n")
    return path


def datafile(shape: str, method: str, directory: str = PAPER) -> str:
    """Path of the shipped 162-vertex start ``vesicle_<shape>_<perp|normal>.fe``
    (written by :func:`write_datafile` when missing)."""
    kind = "normal" if method.startswith("normal") else "perp"
    path = os.path.join(directory, f"vesicle_{shape}_{kind}.fe")
    if not os.path.exists(path):
        os.makedirs(directory, exist_ok=True)
        X, F = initial_shape(shape, 2)
        write_datafile(path, X, F, shape, kind)
    return path

# -- shape descriptors ---------------------------------------------------------------------------

def _line_hits(X, F, o, d):
    """Sorted distinct parameters ``t`` where the line ``o + t d`` meets the
    triangles (Möller–Trumbore, vectorised)."""
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    e1, e2 = b - a, c - a
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-14 * np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1)
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = o - a
    u = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    v = (q @ d) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    eps = 1e-10
    hit = ok & (u >= -eps) & (v >= -eps) & (u + v <= 1 + eps)
    t = np.sort(t[hit])
    if len(t) == 0:
        return t
    keep = np.concatenate([[True], np.diff(t) > 1e-9])
    return t[keep]


#: the largest relative difference of the lateral second moments of a
#: surface of revolution about a given axis (converged phase-study shapes:
#: below 0.01; a prolate lying across the axis: 0.75)
AXISYM_MAX = 0.1


def _classify(hw, dlo, dhi):
    """Shape type from height/width and the two pole depths."""
    if max(dlo, dhi) > 0.3 and abs(dhi - dlo) > 0.3:
        return "stomatocyte"
    if hw < 1 and min(dlo, dhi) > 0.02:
        return "discocyte"
    if max(dlo, dhi) <= 0.02:
        if abs(hw - 1) < 0.02:
            return "sphere"
        return "prolate" if hw > 1 else "oblate"
    return "other"


def mesh_descriptors(X: np.ndarray, F: np.ndarray, axis: np.ndarray | None = None) -> dict:
    """Symmetry descriptors of a closed mesh, comparable with
    :func:`reference_descriptors`.

    The symmetry axis is ``axis`` when given (shape (3,): a mesh revolved
    about a known axis; a deep stomatocyte's second moments are nearly
    isotropic, so they cannot find its axis), else the eigenvector of the
    surface's second-moment tensor (about its area centroid) whose
    eigenvalue is farthest from the other two.  About a given axis a
    surface whose lateral moments differ by more than :data:`AXISYM_MAX`
    (relative) is of type ``other``: not a surface of revolution about it
    (a prolate lying across the axis is no oblate).  With ``z`` the coordinate along it and ``r`` the distance
    from it:

    ``height_width``
        z-extent / (2 max r): > 1 prolate, < 1 oblate (reference 2.285 at
        v0 = 0.85, 0.274 at 0.62, 0.908 at 0.50).
    ``pole_depth_min``, ``pole_depth_max``
        where the axis pierces the surface (its poles), the depth of each
        pole below the extreme plane on its side, relative to the height,
        the smaller and the larger: both 0 for ellipsoid-like shapes, equal
        and positive for a biconcave discocyte (its dimples), 0 and large
        for a stomatocyte (its invagination).
    ``axis_crossings``
        how many times the axis pierces the surface (2 for all three shapes).
    ``axisym_dev``
        relative difference of the two lateral second moments (0 for a
        surface of revolution).
    ``type``
        sphere / prolate / oblate / discocyte / stomatocyte / other.
    """
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    fa = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    cen = (a + b + c) / 3.0
    g = (fa[:, None] * cen).sum(0) / fa.sum()
    D = cen - g
    M = np.einsum("f,fi,fj->ij", fa, D, D) / fa.sum()
    ev, evec = np.linalg.eigh(M)
    given = axis is not None
    if axis is None:
        k = 0 if ev[2] - ev[1] < ev[1] - ev[0] else 2
        axis = evec[:, k]
        lat = [evec[:, i] for i in range(3) if i != k]
    else:
        axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
        e = np.eye(3)[np.argmin(np.abs(axis))]
        u = np.cross(axis, e)
        u /= np.linalg.norm(u)
        w = np.cross(axis, u)
        P = np.array([u, w])                     # the lateral moments, diagonalised
        ev2, vec2 = np.linalg.eigh(P @ M @ P.T)
        lat = [vec2[:, 0] @ P, vec2[:, 1] @ P]
    m_lat = sorted(float(d @ M @ d) for d in lat)
    Y = X - g
    z = Y @ axis
    r = np.linalg.norm(Y - np.outer(z, axis), axis=1)
    hits = _line_hits(X, F, g, axis)
    zmin, zmax = float(z.min()), float(z.max())
    H = zmax - zmin
    if len(hits):
        dlo, dhi = (hits[0] - zmin) / H, (zmax - hits[-1]) / H
    else:
        dlo = dhi = float("nan")
    hw = H / (2 * r.max())
    dev = (m_lat[1] - m_lat[0]) / m_lat[1]
    kind = _classify(hw, dlo, dhi)
    if given and dev > AXISYM_MAX:
        kind = "other"                   # not a surface of revolution about that axis
    return {"type": kind, "height_width": float(hw),
            "pole_depth_min": float(min(dlo, dhi)), "pole_depth_max": float(max(dlo, dhi)),
            "axis_crossings": len(hits),
            "axisym_dev": dev}


def reference_descriptors(res: CanhamResult) -> dict:
    """The same descriptors for an axisymmetric reference profile
    (:class:`~pyevolver.studies.axisymmetric.CanhamResult`), its poles
    at the two ends of the profile."""
    z, r = res.z, res.r
    zmin, zmax = float(z.min()), float(z.max())
    H = zmax - zmin
    lo, hi = sorted([float(z[0]), float(z[-1])])
    hw = H / (2 * r.max())
    dlo, dhi = (lo - zmin) / H, (zmax - hi) / H
    return {"type": _classify(hw, dlo, dhi), "height_width": float(hw),
            "pole_depth_min": float(min(dlo, dhi)), "pole_depth_max": float(max(dlo, dhi)),
            "axis_crossings": 2, "axisym_dev": 0.0}


def _profile(X, F):
    """(r, z) of the vertices in the symmetry frame of :func:`mesh_descriptors`,
    z centred on the extent and oriented so that the deeper pole is on top."""
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    fa = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    cen = (a + b + c) / 3.0
    g = (fa[:, None] * cen).sum(0) / fa.sum()
    D = cen - g
    ev, evec = np.linalg.eigh(np.einsum("f,fi,fj->ij", fa, D, D))
    axis = evec[:, 0 if ev[2] - ev[1] < ev[1] - ev[0] else 2]
    z = (X - g) @ axis
    r = np.linalg.norm((X - g) - np.outer(z, axis), axis=1)
    hits = _line_hits(X, F, g, axis)
    if len(hits) and (z.max() - hits[-1]) < (hits[0] - z.min()):
        z, hits = -z, -hits[::-1]
    return r, z - 0.5 * (z.max() + z.min())

