"""Parametric boundaries: points and Jacobians, moving vertices in
parameter space, snapshots of the coordinates (spec §6.3)."""
from __future__ import annotations

import numpy as np

from ..model.surface import Surface

# (X (nv, 3), boundary parameters (nv, k) or None)
State = tuple[np.ndarray, 'np.ndarray | None']


def boundary_eval(s: Surface, bid: int, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points and Jacobians of parametric boundary ``bid`` at parameters ``P``.

    Returns ``X`` (n, 3) and ``J`` (n, 3, k) with ``J[:, i, j] = ∂x_i/∂p_j``.
    """
    b = s.boundaries[bid]
    names = tuple(f"p{k + 1}" for k in range(b.nparams))
    env0 = s.param_env()
    P = P[:, :b.nparams]
    env = {nm: P[:, k] for k, nm in enumerate(names)}
    X = np.stack([f.values(env0, env, len(P)) for f in b.coords[:3]], axis=1)
    J = np.stack([f.gradient(env0, env, len(P), names) for f in b.coords[:3]], axis=1)
    return X, J


def boundary_groups(s: Surface, mask: np.ndarray | None = None) -> list[tuple[int, np.ndarray]]:
    """``(bid, rows)`` for each parametric boundary with vertices (among ``mask``)."""
    bnd = s.vattr.get("boundary")
    if bnd is None:
        return []
    out = []
    for bid in s.boundaries:
        sel = bnd == bid
        if mask is not None:
            sel &= mask
        rows = np.nonzero(sel)[0]
        if len(rows):
            out.append((bid, rows))
    return out


def solve_small(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Batched ``A[n]⁻¹ b[n]`` for small (k, k) systems; a singular system
    (a constraint gradient that vanishes, e.g. x² + y² = 1 at the origin)
    gets the least-squares solution instead of an error."""
    with np.errstate(all="ignore"):
        try:
            return np.linalg.solve(A, b[..., None])[..., 0]
        except np.linalg.LinAlgError:
            # (an infinite or NaN system, from a runaway vertex, would make
            # the SVD fail: it gets a zero matrix, hence a zero solution)
            bad = ~np.all(np.isfinite(A), axis=(1, 2))
            A = np.where(bad[:, None, None], 0.0, A)
            return np.einsum("nkl,nl->nk", np.linalg.pinv(A), b)


def state(s: Surface) -> State:
    """Snapshot of the coordinates (and boundary parameters) of ``s``."""
    P = s.vattr.get("params")
    return s.X.copy(), (None if P is None else P.copy())


def restore_state(s: Surface, st: State) -> None:
    """Put back the coordinates (and boundary parameters) of :func:`state`."""
    s.X = st[0].copy()
    if st[1] is not None:
        s.vattr["params"] = st[1].copy()


def displace(s: Surface, base: State, dX: np.ndarray) -> None:
    """Move the vertices of ``s`` from the snapshot ``base`` (see :func:`state`)
    by the spatial displacements ``dX`` (nv, 3).

    Vertices on a parametric boundary move in parameter space (spec §6.3):
    ``p = p0 + (JᵀJ)⁻¹ Jᵀ dx`` with ``J = ∂X/∂p`` at ``p0``, then
    ``x = X(p)``; the others move by ``dx``.
    """
    X0, P0 = base
    s.X = X0 + dX
    if P0 is None:
        return
    P = P0.copy()
    for bid, rows in boundary_groups(s):
        k = s.boundaries[bid].nparams
        _, J = boundary_eval(s, bid, P0[rows])
        JtJ = np.einsum("nik,nil->nkl", J, J)
        rhs = np.einsum("nik,ni->nk", J, dX[rows])
        with np.errstate(all="ignore"):
            dp = solve_small(JtJ, rhs)
        P[rows, :k] = P0[rows, :k] + np.nan_to_num(dp)
        s.X[rows], _ = boundary_eval(s, bid, P[rows])
    s.vattr["params"] = P
