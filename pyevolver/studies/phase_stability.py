"""Lowest eigenvalues of the constrained Hessian of a closed vesicle mesh.

At a critical point of the energy ``E`` (the discrete bending energy plus its
regularization) under fixed area and volume, the second variation is the
Hessian of the Lagrangian ``H = ∇²E − Σ μ_i ∇²g_i`` restricted to the
tangent space of the constraints, ``{x : ∇g_iᵀ x = 0}``, with the six rigid
motions (exact null directions on a closed surface) removed as well.  The
eigenvalues are those of the pencil ``(H, M)`` on that subspace, ``M`` the
lumped vertex-area mass matrix (a third of each vertex's star), so that
they approximate the continuum operator's (mesh-independent) spectrum: a
negative one is a direction in which the point is a saddle.

The smallest eigenvalues come from shift-and-invert Lanczos
(``scipy.sparse.linalg.eigsh``): with ``y = M^{1/2} x``, ``H' = M^{-1/2} H
M^{-1/2}`` and ``B'`` an orthonormal basis of ``M^{-1/2}`` (constraint
gradients, rigid motions), each inverse step solves the sparse bordered
system ``[[H' − σI, B'], [B'ᵀ, 0]]`` (LU factorized once), whose solution
lies in the subspace, so the removed directions never enter the Krylov
space.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ..evolve import gradient as GR
from ..errors import UnsupportedError
from ..evolve.hessian import (lagrangian_gradient, lagrangian_hessian, lowrank_border,
                              vertex_normals)
from ..evolve.iterate import _Constraints
from ..session.core import Session
from .vesicle_newton import _rigid_motions


def constrained_hessian(session: Session, normal: bool = True, without: tuple = ("harm",)
                        ) -> tuple[sp.csc_matrix, np.ndarray, np.ndarray]:
    """``(H, B, m)`` of :func:`constrained_system`, refused when the
    Hessian has a low-rank term (a FUNCTION quantity nonlinear in its
    instances' values: :func:`lowest_eigenvalues` takes it)."""
    H, B, m, W, _ = constrained_system(session, normal, without)
    if W is not None:
        raise UnsupportedError("constrained_hessian with a nonlinear FUNCTION quantity",
                               "its low-rank term is not in the sparse matrix")
    return H, B, m


def constrained_system(session: Session, normal: bool = True, without: tuple = ("harm",),
                       extra: tuple = ()) -> tuple:
    """``(H, B, m, W, sign)``: the Lagrangian's Hessian (sparse), the removed
    directions ``B`` (constraint gradients and rigid motions, as columns)
    and the lumped masses ``m``, in the coordinates of vertex motions along
    the vertex normals (``normal``, nv coordinates) or of all vertex
    coordinates (3nv).  The energy quantities named in ``without`` (the
    regularization) are left out: their modulus is 0 while the Hessian is
    computed.  The multipliers are the least squares fit of the energy's
    gradient on the constraints' (in the same coordinates).  The Hessian is
    ``H + W diag(sign) Wᵀ`` (W (n, r), None when r = 0): the low-rank terms
    of FUNCTION quantities nonlinear in their instances' values
    (:func:`~pyevolver.evolve.hessian.lowrank_border`) and ``c ∇q ∇qᵀ`` for
    each ``(q, c)`` of ``extra`` (the ADE term ``2k ∇M ∇Mᵀ`` of a point
    solved with the term linearised, :mod:`.phase_ade_points`)."""
    s = session.surface
    saved = {}
    for name in without:
        q = s.quantities.get(name)
        if q is not None:
            saved[name], q.modulus = q.modulus, 0.0
    try:
        session.recalc()
        t = s.evaluate()
        cons = _Constraints(s)
        nv = s.nv
        if normal:
            Nv = vertex_normals(s, t)
            T = sp.csr_matrix((Nv.ravel(), (np.arange(3 * nv), np.repeat(np.arange(nv), 3))),
                              shape=(3 * nv, nv))
        else:
            T = sp.identity(3 * nv, format="csr")
        gE = GR.energy_gradient(t)
        C = np.stack([g.ravel() for g in cons.gradients(t)], 1)
        lam = np.linalg.lstsq(T.T @ C, T.T @ gE.ravel(), rcond=None)[0]

        terms: list = []
        H = lagrangian_hessian(s, cons, lam, lagrangian_gradient(cons, lam),
                               lowrank=terms).tocsc()
        H = T.T @ (0.5 * (H + H.T)) @ T
        terms += [([name], np.array([[float(c)]])) for name, c in extra]
        W, sign = lowrank_border(t, terms, T) or (None, None)
        m = np.bincount(s.F.ravel(), weights=np.repeat(t.facet_area, 3), minlength=nv) / 3.0
        if not normal:
            m = np.repeat(m, 3)
        B = T.T @ np.column_stack([C, _rigid_motions(s.X)])
    finally:
        for name, mod in saved.items():
            s.quantities[name].modulus = mod
        session.recalc()
    return sp.csc_matrix(H), B, m, W, sign


def _basis(B, tol=1e-8):
    """Orthonormal basis of the columns of ``B`` (rank-revealing: columns
    that vanish, e.g. the rotation about the axis of a surface of revolution
    in normal coordinates, are dropped)."""
    U, S, _ = np.linalg.svd(B, full_matrices=False)
    return U[:, S > tol * S.max()]


def lowest_eigenvalues(session: Session, k: int = 4, normal: bool = True,
                       tol: float = 1e-8, extra: tuple = ()) -> np.ndarray:
    """The ``k`` smallest eigenvalues (ascending) of the constrained,
    mass-weighted Hessian (:func:`constrained_hessian`) of the session's
    surface at its current (converged) shape.

    A first Lanczos run on the operator itself (smallest algebraic, loose)
    locates the bottom of the spectrum ``e``; the shift-and-invert run then
    uses ``σ = min(e, 0) − 1 − |e|/10`` below it, so no eigenvalue is
    missed below the shift.  A low-rank term ``W diag(sign) Wᵀ``
    (:func:`constrained_system`; ``extra`` as there) enters the operator as
    a product and the bordered system as auxiliary unknowns (the border
    of :meth:`~pyevolver.evolve.hessian.HessianSystem.border`)."""
    H, B, m, W, sign = constrained_system(session, normal=normal, extra=extra)
    w = 1.0 / np.sqrt(m)
    Hs = (sp.diags(w) @ H @ sp.diags(w)).tocsc()
    Q = _basis(B / w[:, None])                  # B' = M^{-1/2} B
    n, nb = Hs.shape[0], Q.shape[1]
    Ws = None if W is None else w[:, None] * W  # M^{-1/2} W
    r = 0 if Ws is None else Ws.shape[1]

    def project(x):
        return x - Q @ (Q.T @ x)

    def mv(x):
        y = project(np.ravel(x))
        Hy = Hs @ y if Ws is None else Hs @ y + Ws @ (sign * (Ws.T @ y))
        return project(Hy)
    A = sla.LinearOperator((n, n), matvec=mv, dtype=float)
    rng = np.random.default_rng(0)
    v0 = project(rng.standard_normal(n))
    try:
        e = float(sla.eigsh(A, k=1, which="SA", v0=v0, tol=1e-3, maxiter=3000,
                            return_eigenvectors=False)[0])
    except sla.ArpackNoConvergence as exc:
        e = float(np.min(exc.eigenvalues)) if len(exc.eigenvalues) else 0.0
    sigma = min(e, 0.0) - 1.0 - 0.1 * abs(e)
    border = Q if Ws is None else np.hstack([Q, Ws])
    D = sp.diags(np.concatenate([np.zeros(nb), -sign])) if r else None
    K = sp.bmat([[Hs - sigma * sp.identity(n), sp.csc_matrix(border)],
                 [sp.csc_matrix(border.T), D]], format="csc")
    lu = sla.splu(K)

    def inv(x):
        return lu.solve(np.concatenate([project(np.ravel(x)), np.zeros(nb + r)]))[:n]
    OP = sla.LinearOperator((n, n), matvec=inv, dtype=float)
    vals = sla.eigsh(A, k=k, sigma=sigma, OPinv=OP, v0=v0, which="LM", tol=tol,
                     return_eigenvectors=False)
    return np.sort(vals)


def stability(eigenvalues: np.ndarray, tol: float = 1e-3) -> bool:
    """Stable (a local minimum) when the smallest eigenvalue is above ``-tol``."""
    return bool(eigenvalues[0] > -tol)
