"""Quadratic-model kernels: the 6-node triangle patch and the 3-node edge.

In the Evolver's quadratic model (manual, "Model" chapter, "Quadratic model")
an edge is the quadratic curve through its tail, midpoint and head, and a
facet the quadratic patch through its three corners and three edge
midpoints.  Integrals over them use Gaussian quadrature: on edges the
3-point Gauss-Legendre rule (exact to degree 5, REF's default
``integral_order_1d``), on facets the 7-point degree-5 rule (Stroud T2:5-1,
the rule REF uses for ``integral_order_2d`` 3 in the quadratic model;
measured: the area of a curved 6-node triangle printed by REF equals this
rule's sum to 1e-15, and not the 12-point degree-6 rule's).

Node order of a patch: corners 0, 1, 2 then the midpoints of sides 01, 12,
20.  Node order of an edge: tail, head, midpoint.
"""
from __future__ import annotations

import numpy as np

_R15 = np.sqrt(15.0)
_A = (6.0 - _R15) / 21.0
_B = (6.0 + _R15) / 21.0
# 7-point degree-5 rule, barycentric points (7, 3) and weights summing to 1
TRI7_B = np.array([[1 / 3, 1 / 3, 1 / 3],
                   [1 - 2 * _A, _A, _A], [_A, 1 - 2 * _A, _A], [_A, _A, 1 - 2 * _A],
                   [1 - 2 * _B, _B, _B], [_B, 1 - 2 * _B, _B], [_B, _B, 1 - 2 * _B]])
TRI7_W = np.array([9 / 40] + [(155 - _R15) / 1200] * 3 + [(155 + _R15) / 1200] * 3)

# 3-point Gauss-Legendre on [0, 1]
GL3_T = np.array([0.5 - 0.5 * np.sqrt(0.6), 0.5, 0.5 + 0.5 * np.sqrt(0.6)])
GL3_W = np.array([5 / 18, 8 / 18, 5 / 18])


def tri6_shape(B: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Shape functions of the 6-node triangle at barycentric points.

    Parameters
    ----------
    B : (q, 3) barycentric coordinates ``(l0, l1, l2)``; the patch parameters
        are ``u = l1``, ``v = l2``.

    Returns
    -------
    N, Nu, Nv : (q, 6) arrays
        Values and ``d/du``, ``d/dv`` of the six Lagrange shape functions
        (node order: corners 0, 1, 2, midpoints 01, 12, 20).
    """
    l0, l1, l2 = B[:, 0], B[:, 1], B[:, 2]
    z = np.zeros_like(l0)
    N = np.stack([l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1),
                  4 * l0 * l1, 4 * l1 * l2, 4 * l2 * l0], axis=1)
    Nu = np.stack([1 - 4 * l0, 4 * l1 - 1, z, 4 * (l0 - l1), 4 * l2, -4 * l2], axis=1)
    Nv = np.stack([1 - 4 * l0, z, 4 * l2 - 1, -4 * l1, 4 * l1, 4 * (l0 - l2)], axis=1)
    return N, Nu, Nv


def edge3_shape(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shape functions of the 3-node edge at parameters ``T (q,)`` in [0, 1].

    Returns
    -------
    N, Nt : (q, 3) arrays
        Values and derivatives (node order: tail, head, midpoint).
    """
    T = np.asarray(T, float)
    N = np.stack([(1 - T) * (1 - 2 * T), T * (2 * T - 1), 4 * T * (1 - T)], axis=1)
    Nt = np.stack([4 * T - 3, 4 * T - 1, 4 - 8 * T], axis=1)
    return N, Nt


TRI7_N, TRI7_NU, TRI7_NV = tri6_shape(TRI7_B)
GL3_N, GL3_NT = edge3_shape(GL3_T)


def patch_frames(P: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points and tangents of quadratic patches at the 7 quadrature points.

    Parameters
    ----------
    P : (nf, 6, d) control points (corners, then midpoints 01, 12, 20).

    Returns
    -------
    X, Xu, Xv : (nf, 7, d) arrays
        Positions and the parameter derivatives ``dx/du``, ``dx/dv``; the
        area element is ``|Xu x Xv| du dv`` and the parameter triangle has
        area 1/2, so ``∫ f dA = Σ_q W_q/2 f_q |Xu x Xv|_q``.
    """
    X = np.einsum("qc,ncd->nqd", TRI7_N, P)
    Xu = np.einsum("qc,ncd->nqd", TRI7_NU, P)
    Xv = np.einsum("qc,ncd->nqd", TRI7_NV, P)
    return X, Xu, Xv


def edge_frames(P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points and tangents of quadratic edges at the 3 Gauss points.

    Parameters
    ----------
    P : (ne, 3, d) control points (tail, head, midpoint).

    Returns
    -------
    X, Xt : (ne, 3, d) arrays: positions and ``dx/dt``;
        ``∫ f ds = Σ_q GL3_W_q f_q |Xt_q|``.
    """
    return (np.einsum("qc,ncd->nqd", GL3_N, P), np.einsum("qc,ncd->nqd", GL3_NT, P))


def patch_points(P: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Positions (nf, k, d) of patches ``P (nf, 6, d)`` at barycentric points ``B (k, 3)``."""
    N = tri6_shape(np.asarray(B, float))[0]
    return np.einsum("qc,ncd->nqd", N, P)
