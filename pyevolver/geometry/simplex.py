"""Kernels of the simplex model: k-simplices in R^d given by their corners.

* the k-dimensional volume ("area") of a simplex with sides
  ``S_i = x_i − x_0`` (i = 1..k): ``√det(S Sᵀ) / k!`` (the Gram
  determinant), and its gradient ``∂A/∂S = A (S Sᵀ)⁻¹ S``;
* the signed content of the cone from the origin over a k-simplex in
  R^(k+1): ``det[x_0; x_1; …; x_k] / (k+1)!``, whose sum over the oriented
  facets of a closed surface is the enclosed (k+1)-volume; its gradient in
  corner i is the cofactor row of ``x_i`` over ``(k+1)!``.

All functions take stacked arrays (one row per simplex) and are vectorized.
"""
from __future__ import annotations

import math

import numpy as np


def simplex_sides(P: np.ndarray) -> np.ndarray:
    """Sides (n, k, d) ``x_i − x_0`` of simplices with corners ``P (n, k+1, d)``."""
    return P[:, 1:] - P[:, :1]


def simplex_areas(S: np.ndarray) -> np.ndarray:
    """(n,) k-volumes of simplices with sides ``S (n, k, d)``: ``√det(S Sᵀ)/k!``."""
    k = S.shape[1]
    G = np.einsum("nid,njd->nij", S, S)
    det = np.linalg.det(G) if len(S) else np.zeros(0)
    return np.sqrt(np.maximum(det, 0.0)) / math.factorial(k)


def simplex_area_grad(S: np.ndarray, area: np.ndarray) -> np.ndarray:
    """Per-corner gradients (n, k+1, d) of :func:`simplex_areas`: the sides get
    ``A (S Sᵀ)⁻¹ S``, corner 0 minus their sum; zero for degenerate simplices."""
    n, k, d = S.shape
    out = np.zeros((n, k + 1, d))
    ok = area > 0
    if ok.any():
        G = np.einsum("nid,njd->nij", S[ok], S[ok])
        dS = np.linalg.solve(G, S[ok]) * area[ok][:, None, None]
        out[ok, 1:] = dS
        out[ok, 0] = -dS.sum(axis=1)
    return out


def cone_contents(P: np.ndarray) -> np.ndarray:
    """(n,) signed contents ``det[x_0 … x_k] / (k+1)!`` of the cones from the
    origin over simplices with corners ``P (n, k+1, k+1)``."""
    m = P.shape[1]
    if not len(P):
        return np.zeros(0)
    return np.linalg.det(P) / math.factorial(m)


def cone_content_grad(P: np.ndarray) -> np.ndarray:
    """Per-corner gradients (n, k+1, k+1) of :func:`cone_contents`: the
    cofactors of the corner matrix over (k+1)!."""
    n, m, _ = P.shape
    out = np.empty((n, m, m))
    if not n:
        return out
    rows = np.arange(m)
    for i in range(m):
        R = P[:, rows != i]
        for j in range(m):
            sub = R[:, :, rows != j]
            out[:, i, j] = (-1.0) ** (i + j) * (np.linalg.det(sub) if m > 1 else 1.0)
    return out / math.factorial(m)
