"""The factorization behind the ``hessian`` step: one sparse LDLᵀ that gives
both the Newton step and the Hessian's index.

The constrained Newton system (:mod:`.hessian`) is

    [ K   B ] [ y  ]   [ r ]
    [ Bᵀ  0 ] [ −λ ] = [ d ]

with ``K`` (n, n) sparse symmetric, ``B`` (n, k) dense and k small.  REF's
warning 1825 wants the number of eigenvalues of ``K`` on ``Bᵀ y = 0`` below
``−δ`` (δ the zero tolerance); counting them needs a factorization of the
shifted matrix ``A = K + δI``.  :func:`newton_solve` factors ``A`` only,
once, and

* reads the index from the LDLᵀ pivots of ``A`` (Sylvester's law of
  inertia) and from the Schur complement ``Bᵀ A⁻¹ B`` of the border;
* solves the system with ``K`` itself by iterative refinement
  (``z ← z + M_A⁻¹ (rhs − M_K z)``, the bordered matrices with ``A`` and
  ``K``): each pass shrinks the error along an eigenvector of eigenvalue μ
  by ``δ / (μ + δ)``, so two or three passes reach round-off unless an
  eigenvalue lies within a few δ of 0; then it reports failure and the
  caller takes the exact path.

The factorization is SuperLU (scipy, so every install has it) in symmetric
mode (no pivoting off the diagonal: ``A = L D Lᵀ`` with ``U = D Lᵀ``) in a
geometric nested-dissection order (:func:`.ordering.nested_dissection`),
which on the 81,920-facet icospheres is as fast as CHOLMOD's simplicial
LDLᵀ on the area Hessian and three times faster on the two-ring Hessians of
the curvature energies (benchmarks/bench_hessian.py; docs/performance.md).
The order depends only on the sparsity pattern and the vertex positions; it
is kept per pattern (:data:`ORDER_CACHE`), so the repeated steps on one
mesh topology order once — a changed pattern (after ``r``, ``t``, ``u``,
pops, ...) misses the cache, and any order gives the same solution to
round-off.
"""
from __future__ import annotations

import hashlib
from collections import OrderedDict

import numpy as np
import scipy.sparse as sp

from .. import memory
from . import superlu
from .ordering import nested_dissection

#: unknowns below which SuperLU's own minimum-degree order is used
ND_MIN = 2000
#: matrices with this many entries or more: the heap's free pages are given
#: back before the factorization allocates (pyevolver.memory.give_back)
GIVE_BACK_NNZ = 100_000
#: sparsity-pattern digest -> nested-dissection permutation (a few recent ones)
ORDER_CACHE: "OrderedDict[bytes, np.ndarray]" = OrderedDict()
_CACHE_SIZE = 4


def pattern_key(K) -> bytes:
    """Digest of the sparsity pattern of the CSC/CSR matrix ``K``."""
    h = hashlib.blake2b(digest_size=16)
    h.update(np.asarray(K.shape, np.int64).tobytes())
    h.update(np.ascontiguousarray(K.indptr).tobytes())
    h.update(np.ascontiguousarray(K.indices).tobytes())
    return h.digest()


def ordering(K, points):
    """The fill-reducing permutation for ``K`` (None: let SuperLU order),
    from :data:`ORDER_CACHE` when ``K``'s pattern was seen before."""
    n = K.shape[0]
    if points is None or n <= ND_MIN:
        return None
    key = pattern_key(K)
    perm = ORDER_CACHE.get(key)
    if perm is None:
        perm = nested_dissection(points, K)
        ORDER_CACHE[key] = perm
        while len(ORDER_CACHE) > _CACHE_SIZE:
            ORDER_CACHE.popitem(last=False)
    else:
        ORDER_CACHE.move_to_end(key)
    return perm


class LDL:
    """``A + shift·I = P L D Lᵀ Pᵀ`` for a symmetric sparse ``A`` (SuperLU in
    symmetric mode).  ``pivots`` the diagonal of D (None when SuperLU had to pivot off
    the diagonal, so that its pivots say nothing about the inertia);
    :meth:`solve` for (n,) or (n, m) right-hand sides.  Raises RuntimeError
    when ``A`` is exactly singular."""

    def __init__(self, A, perm=None, shift=0.0):
        A = sp.csc_matrix(A)
        if A.nnz >= GIVE_BACK_NNZ:   # (the permuted copies and SuperLU's factors are
            memory.give_back()       # allocated beside the heap's free blocks: those go first)
        self.perm = perm
        if perm is not None:
            A = A.tocsr()[perm][:, perm].tocsc()
        if shift:                  # (after the permutation: one matrix less at the peak)
            A = A + shift * sp.identity(A.shape[0], format="csc")
        self._lu = superlu.factor(A, natural=perm is not None)
        del A
        self.pivots = superlu.pivots(self._lu)

    def solve(self, R):
        R = np.asarray(R, float)
        if self.perm is None:
            return self._lu.solve(R)
        out = np.empty_like(R)
        out[self.perm] = self._lu.solve(np.ascontiguousarray(R[self.perm]))
        return out


def border_negatives(S, D=None) -> int:
    """The negative eigenvalues a border adds to the inertia of a bordered
    matrix ``[[A, B], [Bᵀ, diag(D)]]`` (D None: zeros) beyond those of the
    matrix it stands for: one per constraint column (D = 0) and one per
    auxiliary unknown of a positive low-rank term (D < 0, see
    :meth:`.hessian.HessianSystem.border`), i.e. ``k − #(D > 0)``."""
    return S.shape[0] - (0 if D is None else int(np.sum(np.asarray(D) > 0)))


def negative_count(pivots, S, eps, D=None):
    """Eigenvalues below ``−eps`` of a matrix on ``Bᵀ y = 0`` from the pivots
    of its LDLᵀ and the Schur complement ``S = Bᵀ A⁻¹ B − diag(D)`` (None:
    no border): the inertia of the bordered matrix (Haynsworth: that of
    ``A`` plus that of ``−S``) less the negative ones the border adds
    (:func:`border_negatives`; the rule of :meth:`.eigen.ShiftedFactor.inertia`).
    With auxiliary unknowns (``D``) the count is that of ``A + W diag(±1) Wᵀ``."""
    below = int(np.sum(np.asarray(pivots) < -eps))
    if S is not None:
        s = np.linalg.eigvalsh(-0.5 * (S + S.T))
        below += int(np.sum(s < -eps)) - border_negatives(S, D)
    return max(below, 0)


def newton_solve(K, B, r, d, points=None, delta=0.0, eps=0.0, rtol=1e-14, stall=1e-12,
                 passes=10, D=None):
    """Solve the bordered system with ``K`` (lower block ``diag(D)``, zeros
    when None) by refinement on one factorization
    of ``K + δI``; returns ``(solution (n + k,), index)`` with ``index`` the
    number of eigenvalues of ``K + δI`` on ``Bᵀ y = 0`` below ``−eps``
    (None when the pivots do not tell), or None when the refinement does
    not reach the normwise backward error ``stall`` (it stops at ``rtol``
    or when a pass no longer halves the error: an eigenvalue of ``K`` near
    ``−δ``), or when ``K + δI`` is singular: the caller then solves with
    ``K`` directly."""
    n = K.shape[0]
    K = sp.csc_matrix(K)
    try:     # (K + δI is made in LDL, permuted: the factors' memory peaks there)
        f = LDL(K, ordering(K, points), shift=delta)
    except RuntimeError:
        return None
    k = 0 if B is None else B.shape[1]
    rhs = r if not k else np.concatenate([r, d])
    z0 = None
    if k:       # (the border's columns and the first right-hand side in one solve)
        Z = f.solve(np.column_stack([B, r]))
        ZB, z0 = Z[:, :k], Z[:, k]
        S = B.T @ ZB - (0.0 if D is None else np.diag(D))
        try:
            Sinv = np.linalg.inv(S)
        except np.linalg.LinAlgError:
            return None

    def precond(res, z=None):
        z = f.solve(res[:n]) if z is None else z
        if not k:
            return z
        mu = Sinv @ (B.T @ z - res[n:])
        return np.concatenate([z - ZB @ mu, mu])

    def apply(z):
        if not k:
            return K @ z
        return np.concatenate([K @ z[:n] + B @ z[n:],
                               B.T @ z[:n] + (0.0 if D is None else D * z[n:])])
    # normwise backward error ‖res‖ / (‖M‖ ‖z‖ + ‖rhs‖), ‖M‖ the largest row sum
    normM = float(abs(K).sum(axis=1).max()) if n else 0.0
    if k:
        normM = max(normM, float(np.abs(B).sum(axis=1).max() + np.abs(B).sum(axis=0).max()
                                 + (0.0 if D is None else np.abs(D).max())))
    with np.errstate(all="ignore"):
        z = precond(rhs, z0)
        best, best_err = None, np.inf
        for _ in range(passes):
            if not np.all(np.isfinite(z)):
                break
            res = rhs - apply(z)
            err = float(np.abs(res).max()) / (normM * float(np.abs(z).max())
                                               + float(np.abs(rhs).max()) or 1.0)
            improved = err <= 0.5 * best_err
            if err < best_err:
                best, best_err = z, err
            if err <= rtol or not improved:
                break
            z = z + precond(res)
    if best is None or best_err > stall:
        return None
    z = best
    index = None
    if f.pivots is not None:
        index = negative_count(f.pivots, S if k else None, eps, D)
    return z, index
