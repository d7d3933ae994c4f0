"""Per-facet Hessian blocks of area and volume along one direction per vertex.

With ``hessian_normal`` each free vertex ``v`` moves along one unit vector
``u_v`` (its normal), so the Hessian of a sum over facets is assembled from
one 3 × 3 block per facet, ``K_ab = u_aᵀ (∂²E_f/∂x_a∂x_b) u_b`` (a, b the
facet's corners).  The kernels here compute those blocks from the corners
and directions gathered axis-major, arrays (3 axes, 3 corners, m), so that
every numpy call covers all facets and corners at once; the facet-major
forms of :func:`pyevolver.methods.basic.facet_area_hessian` and
:func:`~pyevolver.methods.basic.facet_volume_hessian` give the same blocks
(tests/methods/test_normal_blocks.py) and are kept for the general bases.

Area (a ≠ b, ε_ab = +1 when b = a + 2, −1 when b = a + 1, mod 3; e_a the
side opposite corner a; n the unit normal; |N| twice the area; w_a = e_a × u_a):

    K_ab = (w_a·w_b − (n·w_a)(n·w_b)) / (2|N|) + ½ ε_ab u_a·(n × u_b)

(the second derivatives of |N|/2, e.g. Hildebrandt et al. 2006 or any
text on discrete minimal surfaces).  Symmetric volume ``det[x0, x1, x2]/6``:
``K_ab = det[.., u_a in slot a, u_b in slot b, x_c in slot c]/6``; z-flux
volume ``Z cz/6`` with ``Z = z0 + z1 + z2`` and ``cz`` the doubled signed
area of the facet's projection on the xy-plane.
"""
from __future__ import annotations

import numpy as np

from .axis_major import NEXT, NEXT2, cross

#: the corner pairs (a, b), a < b, of a facet's off-diagonal blocks
PAIRS = ((0, 1), (0, 2), (1, 2))


def _dot(u, v):
    """Dot products along the first axis (3, ...)."""
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def _blocks(diag, off):
    """(m, 3, 3) symmetric blocks from the diagonal (3, m) and the
    off-diagonal entries ``off[(a, b)]`` (m,) of :data:`PAIRS`."""
    m = diag.shape[1]
    K = np.empty((m, 3, 3))
    for a in range(3):
        K[:, a, a] = diag[a]
    for (a, b), v in off.items():
        K[:, a, b] = v
        K[:, b, a] = v
    return K


def area_blocks(P: np.ndarray, U: np.ndarray, w: np.ndarray,
                E: np.ndarray | None = None) -> np.ndarray:
    """Blocks of ``Σ_f w_f A_f`` along the directions ``U``.

    Parameters
    ----------
    P : (3, 3, m) facet corners, axis-major (axis, corner, facet).
    U : (3, 3, m) each corner's direction, the same layout.
    w : (m,) weights.
    E : (3, 3, m) the side opposite each corner, ``P[:, c+2] − P[:, c+1]``,
        when the caller has it.

    Returns
    -------
    (m, 3, 3) blocks; zero on facets of zero area.
    """
    if E is None:
        E = P.take(NEXT2, axis=1) - P.take(NEXT, axis=1)      # side opposite each corner
    N = cross(E[:, 2], -E[:, 1])                              # (x1 − x0) × (x2 − x0)
    L = np.sqrt(_dot(N, N))
    ok = L > 0
    inv = np.divide(1.0, L, out=np.zeros_like(L), where=ok)
    n = N * inv
    W = cross(E, U)                                            # (3, 3, m)
    nw = _dot(n[:, None], W)                                   # (3, m)
    h = 0.5 * inv * w
    diag = (_dot(W, W) - nw * nw) * h
    off = {}
    for a, b in PAIRS:
        off[(a, b)] = (_dot(W[:, a], W[:, b]) - nw[a] * nw[b]) * h
    # ½ ε_ab u_a·(n × u_b) = ½ ε_ab n·(u_b × u_a), symmetric in (a, b)
    t = 0.5 * w
    off[(0, 2)] += t * _dot(n, cross(U[:, 2], U[:, 0]))      # ε_02 = +1
    off[(0, 1)] -= t * _dot(n, cross(U[:, 1], U[:, 0]))      # ε_01 = −1
    off[(1, 2)] -= t * _dot(n, cross(U[:, 2], U[:, 1]))      # ε_12 = −1
    K = _blocks(diag, off)
    if not ok.all():
        K[~ok] = 0.0
    return K


def volume_blocks(P: np.ndarray, U: np.ndarray, w: np.ndarray, symmetric: bool) -> np.ndarray:
    """Blocks of ``Σ_f w_f v_f`` along the directions ``U`` (layout of
    :func:`area_blocks`), for the symmetric or the z-flux facet volume."""
    m = P.shape[2]
    if symmetric:
        off = {(0, 1): _dot(U[:, 0], cross(U[:, 1], P[:, 2])),
               (0, 2): _dot(U[:, 0], cross(P[:, 1], U[:, 2])),
               (1, 2): _dot(P[:, 0], cross(U[:, 1], U[:, 2]))}
        for k in off:
            off[k] *= w / 6.0
        return _blocks(np.zeros((3, m)), off)
    x, y = P[0], P[1]
    Z = P[2, 0] + P[2, 1] + P[2, 2]
    gx = y.take(NEXT, axis=0) - y.take(NEXT2, axis=0)          # ∂cz/∂x_a
    gy = x.take(NEXT2, axis=0) - x.take(NEXT, axis=0)          # ∂cz/∂y_a
    du = gx * U[0] + gy * U[1]                                 # (3, m)
    uz = U[2]
    ux, uy = U[0], U[1]
    c = w / 6.0
    diag = 2 * uz * du * c
    off = {}
    for a, b in PAIRS:
        # C_ab = +1 when b = a + 1, −1 when b = a + 2 (mod 3)
        C = 1.0 if b == (a + 1) % 3 else -1.0
        off[(a, b)] = (Z * C * (ux[a] * uy[b] - ux[b] * uy[a])
                       + uz[a] * du[b] + du[a] * uz[b]) * c
    return _blocks(diag, off)
