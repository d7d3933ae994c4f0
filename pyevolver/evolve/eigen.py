"""Eigenvalues of the constrained Hessian: the inertia of ``eigenprobe``,
the eigenvalues of ``ritz`` and ``lanczos``, the inverse iteration of
``eigenprobe(λ, n)``, the ``saddle`` move and the inertia warning of
``hessian``.

The Hessian is the one ``hessian`` steps with (:func:`.hessian.hessian_system`):
``K`` (n, n), the Hessian of the Lagrangian on the free coordinates ``y``
of the vertices (with ``hessian_normal`` one per vertex: the motion along
its unit normal; otherwise three, or the tangent space of its constraints),
bordered by the gradients ``B`` (n, k) of the k fixed volumes and quantities.
The eigenproblem is the Evolver's (eigentut.htm §3, §5, §6, §8): the metric
is the identity on ``y``, or with ``linear_metric`` the mass matrix of
:func:`metric`, restricted to the motions that keep the fixed values,
``Bᵀ y = 0``.  With ``Z`` (n, n − k) an orthonormal basis of that subspace
the eigenvalues are those of ``Zᵀ K Z`` (``Zᵀ K Z w = μ Zᵀ M Z w``);
measured: cube.fe, mound.fe after ``g 10`` and catbody.fe give
evolver-nox-d's eigenvalues to 1e-9 or better.

Inertia (the counts below, at and above λ; "at" means within ``eps``,
``hessian_epsilon``): Sylvester's law of inertia on a sparse LDLᵀ
factorization of ``A = K − σM`` (CHOLMOD's simplicial LDLᵀ when
scikit-sparse is installed, SuperLU in symmetric mode otherwise, as
:func:`.newton._factor`) and the Haynsworth inertia additivity of the
bordered matrix, ``In([[A, B], [Bᵀ, 0]]) = In(A) + In(−Bᵀ A⁻¹ B)``, from
which the k pairs of the border are removed.  The pivots' signs are not
reliable within round-off of an eigenvalue, so :func:`inertia` counts the
dense eigenvalues of small problems and otherwise factors at a shift in a
gap between the eigenvalues nearest λ.

The eigenvalues nearest λ use the shift-inverted operator
``OP = Z (Zᵀ (K − λM) Z)⁻¹ Zᵀ``, one bordered solve per application
(ARPACK's implicitly restarted Lanczos, ``scipy.sparse.linalg.eigsh``;
eigenvalue θ of OP ↔ μ = λ + 1/θ), or the dense ``Zᵀ K Z`` when the
problem is small (at most ``DENSE_MAX`` unknowns).
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp

from ..constraints import restore_state, state
from ..errors import CommandError, UnsupportedError, dimension_error
from .hessian import HessianSystem, _cholmod, hessian_system
from . import symfactor as SF
from . import string_hessian  # noqa: F401  (installs the string model's Hessian)

#: below this many unknowns the eigenvalues come from the dense matrix
DENSE_MAX = 800


@dataclass
class Inertia:
    """Counts of eigenvalues below, equal to and above a probe value."""
    below: int
    equal: int
    above: int

    def line(self) -> str:
        """The Evolver's ``Eigencounts:`` line (with its trailing space)."""
        return "Eigencounts:    %d <,  %d ==,  %d > \n" % (self.below, self.equal, self.above)


@dataclass
class EigenResult:
    """Eigenvalues near a probe value, with their inertia.

    ``values`` (m,) the ones nearest ``shift``, ascending;
    ``vectors`` (n, m) the eigenvectors on the free coordinates (unit
    length, ``Bᵀ v = 0``); ``motions`` maps one to vertex motions (nv, 3).
    """
    shift: float
    inertia: Inertia
    values: np.ndarray
    vectors: np.ndarray
    system: Any = None
    lines: list = field(default_factory=list)

    def motion(self, j: int) -> np.ndarray:
        """The vertex motion (nv, 3) of eigenvector ``j``."""
        return np.asarray(self.system.T @ self.vectors[:, j]).reshape(-1, 3)


def _ldl(A, points=None):
    """``(solve, pivots)`` of an LDLᵀ factorization of the symmetric sparse
    ``A`` without off-diagonal pivoting (CHOLMOD's simplicial LDLᵀ, or
    SuperLU in symmetric mode as :func:`.newton._factor`), or None when a
    pivot is zero.  With ``points`` (n, 3), the positions of the unknowns,
    and more than :data:`.symfactor.ND_MIN` of them: SuperLU in the cached
    nested-dissection order of :mod:`.symfactor` (faster on large surfaces)."""
    if points is not None and A.shape[0] > SF.ND_MIN:
        try:
            f = SF.LDL(A, SF.ordering(A, points))
        except RuntimeError:                  # exactly singular
            return None
        if f.pivots is not None:
            d = np.asarray(f.pivots)
            if np.all(np.isfinite(d)) and np.all(d != 0):
                return f.solve, d
            return None
    chol = _cholmod()
    if chol is not None:
        try:
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                f = chol.cholesky(A, mode="simplicial")
                d = f.D()
            if np.all(np.isfinite(d)) and np.all(d != 0):
                return f, np.asarray(d)
        except chol.CholmodError:
            pass
    import scipy.sparse.linalg as spla   # when first used (start-up time)
    try:
        lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                       options={"SymmetricMode": True})
    except RuntimeError:                  # exactly singular
        return None
    if np.array_equal(lu.perm_r, lu.perm_c):
        return lu.solve, lu.U.diagonal()
    return None


class ShiftedFactor:
    """A factorization of ``A = K − σI`` (n, n) (``K − σM`` with a metric ``M``): its solve, the inertia of
    its LDLᵀ pivots and the bordered solve with ``B``.

    Raises :class:`UnsupportedError` when ``A`` is singular (σ an
    eigenvalue of K to machine precision) and too large for the dense
    fallback, unless ``nudge``: then σ is moved by up to 1e-4 of K's mean
    diagonal until it factors (``self.sigma``), for shift-and-invert.
    ``points`` (n, d), where each unknown sits, lets large systems be
    factored in :mod:`.symfactor`'s nested-dissection order.  ``D`` (k,),
    the border's diagonal block (:meth:`.hessian.HessianSystem.border`;
    None: zeros): the inertia is then that of ``A + W diag(±1) Wᵀ`` on
    the constraints.
    """

    def __init__(self, K, B, sigma: float, eps: float, M=None, nudge: bool = False,
                 points=None, D=None):
        n = K.shape[0]
        Mm = sp.identity(n, format="csc") if M is None else M
        self.n, self.B, self.eps, self.D = n, B, eps, D
        self.solve: Callable
        self.pivots = None
        A = (K - sigma * Mm).tocsc()
        got = _ldl(A, points)
        if got is None and nudge and n:
            # σ an eigenvalue to machine precision (a rigid motion at 0): for
            # shift-and-invert any shift this near does, so move it a little
            scale = max(float(np.abs(K.diagonal()).mean()), 1e-300)
            for k in range(1, 4):
                sigma += 1e-10 * 100 ** k * scale
                A = (K - sigma * Mm).tocsc()
                got = _ldl(A, points)
                if got is not None:
                    break
        self.sigma = sigma
        if got is not None:
            self.solve, self.pivots = got
        if self.pivots is None:
            if n > 3 * DENSE_MAX:
                raise UnsupportedError(f"eigenvalues at the probe value {sigma:g}",
                                       "the shifted Hessian is singular there; "
                                       "probe slightly off the eigenvalue")
            w, V = np.linalg.eigh(A.toarray())
            self.pivots = w
            inv = np.where(np.abs(w) > eps, 1.0 / np.where(w == 0, 1.0, w), 0.0)
            self.solve = lambda R: V @ (inv[:, None] * (V.T @ R)) if np.ndim(R) == 2 \
                else V @ (inv * (V.T @ R))
        self.ZB = None
        self._bordered = None
        if B is not None:
            self.ZB = np.asarray(self.solve(np.asarray(B, float)))
            self.S = B.T @ self.ZB - (0.0 if D is None else np.diag(D))  # Bᵀ A⁻¹ B − D
            d = np.abs(np.asarray(self.pivots))
            if len(d) and d.min() <= 1e-10 * d.max():
                # A (nearly) singular, the bordered matrix perhaps not (a mode of
                # K that the constraints remove): solve with the bordered matrix
                import scipy.sparse.linalg as spla
                M = sp.bmat([[A, sp.csc_matrix(B)], [sp.csc_matrix(B.T),
                                                      None if D is None else sp.diags(D)]],
                            format="csc")
                try:
                    self._bordered = spla.splu(M)
                except RuntimeError:
                    pass

    def inertia(self) -> Inertia:
        """The inertia of ``A`` on the subspace ``Bᵀ y = 0``."""
        d = np.asarray(self.pivots)
        below = int(np.sum(d < -self.eps))
        equal = int(np.sum(np.abs(d) <= self.eps))
        above = len(d) - below - equal
        if self.B is not None:
            s = np.linalg.eigvalsh(-0.5 * (self.S + self.S.T))
            k = len(s)
            nneg = 0 if self.D is None else int(np.sum(np.asarray(self.D) < 0))
            below += int(np.sum(s < -self.eps)) - SF.border_negatives(self.S, self.D)
            equal += int(np.sum(np.abs(s) <= self.eps))
            above += int(np.sum(s > self.eps)) - (k - nneg)
            if below < 0 or above < 0:        # a degenerate border: count what is left
                below, above = max(below, 0), max(above, 0)
        return Inertia(below, equal, above)

    def op(self, x: np.ndarray) -> np.ndarray:
        """``y = OP x``: the solution of ``[[A, B], [Bᵀ, 0]] [y; μ] = [x; 0]``."""
        if self._bordered is not None:
            return self._bordered.solve(np.concatenate([x, np.zeros(self.B.shape[1])]))[:self.n]
        z = np.asarray(self.solve(x))
        if self.ZB is None:
            return z
        mu = np.linalg.lstsq(self.S, self.B.T @ z, rcond=None)[0]
        return z - self.ZB @ mu


def _null_basis(B, n):
    """(n, n − k) orthonormal basis of the vectors ``y`` with ``Bᵀ y = 0``."""
    if B is None:
        return None
    Q, R = np.linalg.qr(np.asarray(B, float), mode="complete")
    rank = int(np.sum(np.abs(np.diag(R)) > 1e-12 * max(np.abs(R).max(), 1e-300)))
    return Q[:, rank:]


def _factor(hs: HessianSystem, sigma: float, eps: float) -> ShiftedFactor:
    """:class:`ShiftedFactor` of ``hs`` at ``σ`` (nudged off an eigenvalue),
    its border with the low-rank term of a nonlinear FUNCTION quantity
    (:meth:`.hessian.HessianSystem.border`)."""
    B, _, D = hs.border()
    return ShiftedFactor(hs.K, B, sigma, eps, hs.M, nudge=True, points=hs.points, D=D)


def _dim(hs: HessianSystem) -> int:
    return hs.K.shape[0] - (0 if hs.B is None else hs.B.shape[1])


def _order(values, vectors, shift, m):
    """The m values nearest ``shift``, in ascending order (as REF prints them)."""
    key = np.lexsort((values, np.abs(values - shift)))[:m]
    key = key[np.argsort(values[key], kind="stable")]
    return values[key], vectors[:, key]


def _dense(hs: HessianSystem):
    """All eigenvalues (ascending) and eigenvectors (n, n − k) of ``Zᵀ K Z``
    (with a metric: of ``Zᵀ K Z w = μ Zᵀ M Z w``, the vectors M-orthonormal)."""
    Z = _null_basis(hs.B, hs.K.shape[0])
    Kd = hs.K.toarray()
    if hs.W is not None:
        Kd += (hs.W * hs.Wsign) @ hs.W.T
    Md = None if hs.M is None else hs.M.toarray()
    if Z is not None:
        Kd = Z.T @ Kd @ Z
        Md = None if Md is None else Z.T @ Md @ Z
    Kd = 0.5 * (Kd + Kd.T)
    if Md is None:
        w, V = np.linalg.eigh(Kd)
    else:
        # K v = μ M v with M = L Lᵀ: (L⁻¹ K L⁻ᵀ) u = μ u, v = L⁻ᵀ u (M-orthonormal)
        L = np.linalg.cholesky(0.5 * (Md + Md.T))
        C = np.linalg.solve(L, np.linalg.solve(L, Kd).T)
        w, U = np.linalg.eigh(0.5 * (C + C.T))
        V = np.linalg.solve(L.T, U)
    return w, (V if Z is None else Z @ V)


def _near(hs: HessianSystem, shift: float, m: int, eps: float, dense_max: int, seed: int = 0):
    """The m eigenpairs nearest ``shift`` (values ascending)."""
    n, dim = hs.K.shape[0], _dim(hs)
    m = max(0, min(int(m), dim))
    if m == 0:
        return np.zeros(0), np.zeros((n, 0))
    if dim <= dense_max or m >= dim - 1:
        w, V = _dense(hs)
        return _order(w, V, shift, m)
    import scipy.sparse.linalg as spla   # when first used (start-up time)
    fac = _factor(hs, shift, eps)
    v0 = fac.op(np.random.default_rng(seed).standard_normal(n))
    op = spla.LinearOperator((n, n), matvec=fac.op, dtype=float)
    try:
        if hs.M is None:
            theta, V = spla.eigsh(op, k=m, which="LM", v0=v0, tol=1e-14)
            return _order(fac.sigma + 1.0 / theta, V, shift, m)
        # generalized shift-invert mode: OP = (K − σM)⁻¹ M on the subspace,
        # self-adjoint in the M inner product
        mu, V = spla.eigsh(hs.K, k=m, M=hs.M, sigma=fac.sigma, OPinv=op, which="LM", v0=v0,
                           tol=1e-14)
    except spla.ArpackNoConvergence as exc:
        got = len(np.atleast_1d(getattr(exc, "eigenvalues", np.zeros(0))))
        raise CommandError(
            f"the eigenvalue iteration did not converge near {shift:g} ({got} of {m} "
            "eigenvalues found): the Hessian has many (nearly) equal eigenvalues there, "
            "e.g. motions that cost no energy; try another shift or fewer eigenvalues") \
            from None
    return _order(mu, V, shift, m)


def inertia(hs: HessianSystem, shift: float, eps: float = 1e-10,
            dense_max: int = DENSE_MAX) -> Inertia:
    """Counts of the eigenvalues μ of the constrained Hessian of ``hs``
    below, equal to and above ``shift``; "equal" means ``|μ − shift| ≤ eps``
    (``hessian_epsilon``).

    Small problems (dimension ≤ ``dense_max``) count the dense eigenvalues.
    Otherwise the eigenvalues nearest the shift (shift-and-invert) give the
    equal ones, and the count below is the inertia of one LDLᵀ
    factorization at a shift σ in the widest gap between them below the
    window (so that no eigenvalue is near σ: the signs of the pivots of an
    LDLᵀ without pivoting are not reliable within ~1e-8 of an eigenvalue),
    plus the nearest eigenvalues between σ and the window.
    """
    dim = _dim(hs)
    if dim <= 0:
        return Inertia(0, 0, 0)
    if dim <= dense_max:
        w = _dense(hs)[0]
        below = int(np.sum(w < shift - eps))
        equal = int(np.sum(np.abs(w - shift) <= eps))
        return Inertia(below, equal, dim - below - equal)
    m = min(6, dim)
    while True:
        vals = _near(hs, shift, m, eps, dense_max)[0]
        dist = np.abs(vals - shift)
        if np.any(dist > eps) or m >= dim:
            break
        m = min(2 * m, dim)
    equal = int(np.sum(dist <= eps))
    if m >= dim:
        below = int(np.sum(vals < shift - eps))
        return Inertia(below, equal, dim - below - equal)
    rmax = float(dist.max())
    pts = np.sort(np.concatenate([[shift - rmax, shift - eps], vals[vals < shift - eps]]))
    gap = int(np.argmax(np.diff(pts)))
    sigma = 0.5 * (pts[gap] + pts[gap + 1])
    below = _factor(hs, sigma, 0.0).inertia().below
    below += int(np.sum((vals >= sigma) & (vals < shift - eps)))
    return Inertia(below, equal, max(dim - below - equal, 0))


def nearest(hs: HessianSystem, shift: float, m: int, eps: float = 1e-10,
            dense_max: int = DENSE_MAX, seed: int = 0) -> EigenResult:
    """The ``m`` eigenvalues of the constrained Hessian nearest ``shift``.

    Parameters
    ----------
    hs : HessianSystem
        From :func:`.hessian.hessian_system`.
    shift : float
        The probe value λ.
    m : int
        How many (at most the dimension n − k).
    eps : float
        The half width of "equal" in the inertia (``hessian_epsilon``).
    dense_max : int
        Up to this dimension the dense ``Zᵀ K Z`` (LAPACK ``eigh``);
        above it shift-and-invert ARPACK with the bordered solve.

    Returns
    -------
    EigenResult
        The m values nearest ``shift``, ascending.
    """
    inert = inertia(hs, shift, eps, dense_max)
    vals, vecs = _near(hs, shift, m, eps, dense_max, seed)
    return EigenResult(shift, inert, vals, vecs, hs)


def lowest(hs: HessianSystem, eps: float = 1e-10, dense_max: int = DENSE_MAX,
           m: int = 1) -> EigenResult:
    """The ``m`` lowest eigenvalues of the constrained Hessian and their
    eigenvectors, ascending (a shift below Gershgorin's bound, so that
    ``K − σM`` is positive definite and the lowest eigenvalues are the
    nearest)."""
    K = hs.K.tocsr()
    if K.shape[0] == 0:
        return EigenResult(0.0, Inertia(0, 0, 0), np.zeros(0), np.zeros((0, 0)), hs)
    diag = K.diagonal()
    off = np.asarray(abs(K).sum(axis=1)).ravel() - np.abs(diag)
    lb = float(np.min(diag - off))                 # λ_min(K) ≥ lb (Gershgorin)
    if hs.W is not None:                           # W diag(±1) Wᵀ ≥ −Σ_{−1} |w|²
        lb -= float(np.sum(hs.W[:, hs.Wsign < 0] ** 2))
    if hs.M is not None:
        # μ_min ≥ min(lb, 0) / λ_min(M), with λ_min(M) ≥ hs.M_floor > 0
        lb = min(lb, 0.0) / hs.M_floor
    sigma = lb - 1e-3 * max(abs(lb), 1.0)
    vals, vecs = _near(hs, sigma, m, eps, dense_max)
    return EigenResult(sigma, inertia(hs, 0.0, eps, dense_max), vals, vecs, hs)


@dataclass
class ProbeResult:
    """``eigenprobe(λ, n)``: the inertia, the eigenvalue the inverse
    iteration converged to (or its last estimate) and its eigenvector
    (n,), pointed downhill; ``lines`` the progress REF prints."""
    inertia: Inertia
    value: float
    vector: np.ndarray
    iterations: int
    lines: list
    system: Any = None

    def motion(self) -> np.ndarray:
        """The vertex motion (nv, 3) of the eigenvector."""
        return np.asarray(self.system.T @ self.vector).reshape(-1, 3)


def inverse_iteration(hs: HessianSystem, shift: float, maxit: int, eps: float = 1e-10,
                      seed: int = 0, rtol: float = 1e-14) -> ProbeResult:
    """Inverse power iteration with ``(K − λI)⁻¹`` on the constrained
    subspace from a random start (the manual's ``eigenprobe(λ, n)``), at
    most ``maxit`` iterations after the first.  The estimate is
    ``λ + 1/(xᵀ OP x)`` for the unit iterate x; REF's progress lines
    ``k  ev = ...`` are made at k = 0, every tenth and the last."""
    n = hs.K.shape[0]
    if n == 0:
        return ProbeResult(Inertia(0, 0, 0), math.nan, np.zeros(0), 0, [], hs)
    fac = _factor(hs, shift, eps)
    inert = inertia(hs, shift, eps)
    Mx = (lambda v: v) if hs.M is None else (lambda v: hs.M @ v)
    rng = np.random.default_rng(seed)
    x = fac.op(rng.standard_normal(n))
    x /= math.sqrt(float(x @ Mx(x)))
    lines = []
    ev_old = math.nan
    ev = math.nan
    k = 0
    for k in range(int(maxit) + 1):
        Mxk = Mx(x)
        y = fac.op(Mxk)
        q = float(Mxk @ y)                        # xᵀ M OP M x, x M-unit
        ev = fac.sigma + 1.0 / q if q != 0 else fac.sigma
        ny = math.sqrt(max(float(y @ Mx(y)), 0.0))
        x = y / ny if ny > 0 else x
        done = abs(ev - ev_old) <= rtol * max(1.0, abs(ev))
        if k % 10 == 0 or done or k == int(maxit):
            lines.append("%d  ev = %20.15f\n" % (k, ev))
        if done:
            break
        ev_old = ev
    if float(x @ hs.rhs) < 0:          # rhs = −∇E: point downhill
        x = -x
    return ProbeResult(inert, ev, x, k, lines, hs)


@dataclass
class SaddleResult:
    """``saddle``: the lowest eigenvalue, the step along its eigenvector
    (None when it is not negative: no move) and the energy after."""
    value: float
    step: float | None = None
    energy: float = math.nan
    area: float = math.nan
    totals: Any = None
    warnings: list = field(default_factory=list)


def _seek(E: Callable[[float], float], smax: float) -> float:
    """The step in [0, smax] of least ``E``: scale 1 doubled while E falls
    (halved until it falls), then a golden-section search in the bracket
    (the energy along an unstable mode is far from a parabola, so the
    parabolic step of ``g``'s search falls short)."""
    e0 = E(0.0)
    s = min(1.0, smax)
    e = E(s)
    if e < e0:
        while True:
            if s >= smax:
                return s
            s2 = min(2.0 * s, smax)
            e2 = E(s2)
            if not e2 < e:
                hi = s2
                break
            s, e = s2, e2
    else:
        for _ in range(40):
            s /= 2.0
            e = E(s)
            if e < e0:
                break
        else:
            return 0.0
        hi = 2.0 * s
    # golden-section search on [0, hi] (its minimum bracketed by s)
    g = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = 0.0, hi
    x1, x2 = b - g * (b - a), a + g * (b - a)
    f1, f2 = E(x1), E(x2)
    while b - a > 1e-6 * hi:
        if f1 < f2:
            b, x2, f2 = x2, x1, f1
            x1 = b - g * (b - a)
            f1 = E(x1)
        else:
            a, x1, f1 = x1, x2, f2
            x2 = a + g * (b - a)
            f2 = E(x2)
    x, f = (x1, f1) if f1 < f2 else (x2, f2)
    return x if f < e else s


def saddle_step(it, normal: bool = True, max_step: float | None = None,
                eps: float = 1e-10, mix: float | None = None) -> SaddleResult:
    """The ``saddle`` command on the surface of the
    :class:`~pyevolver.evolve.iterate.Iterator` ``it``: when the lowest
    eigenvalue of the constrained Hessian is negative, a line search for
    the lowest energy along its unit eigenvector (for a multiple eigenvalue
    the one along the force's part in the eigenspace), both ways, the step at
    most ``max_step`` in size (:func:`_seek`); the fixed values are
    restored after the move as in ``g``.
    ``mix``: the eigenvector of the ``linear_metric`` with that mix.
    """
    if it.surface.X.shape[1] > 3:
        raise dimension_error(it.surface.sdim, "the Hessian's eigenvalues", "need")
    hs = hessian_system(it, normal, lowrank=True)
    if mix is not None:
        metric(hs, it.surface, mix)
    low = lowest(hs, eps, m=4)
    if not len(low.values):
        return SaddleResult(math.nan)
    value = float(low.values[0])
    if not value < -eps:
        return SaddleResult(value)
    s = it.surface
    # a multiple lowest eigenvalue (a symmetric shape): within its eigenspace
    # the direction of the force −∇E (any vector of it when there is none)
    same = np.abs(low.values - value) <= 1e-8 * max(1.0, abs(value))
    V = low.vectors[:, same]
    c = V.T @ hs.rhs
    small = 1e-12 * max(float(np.linalg.norm(hs.rhs)), 1e-300)
    v = V @ c if float(np.linalg.norm(c)) > small else V[:, 0]
    dx = np.asarray(hs.T @ v).reshape(-1, 3)
    dx /= max(float(np.linalg.norm(dx)), 1e-300)          # a unit motion
    cons, mobile = hs.cons, hs.mobile
    targets = cons.targets(s)
    X0 = state(s)
    smax = math.inf if max_step is None else abs(float(max_step))
    best = (math.inf, 0.0)
    for sign in (1.0, -1.0):
        def E(scale, sign=sign):
            e = it._move(X0, dx, sign * scale, cons, None, None, mobile, targets, None,
                         trial=True).energy
            return e if math.isfinite(e) else math.inf
        scale = _seek(E, min(smax, 1e6))
        e = E(scale)
        if e < best[0]:
            best = (e, sign * scale)
    if not best[0] < E(0.0):
        best = (math.inf, 0.0)                 # no lower energy along the eigenvector
    report: list[str] = []
    t = it._move(X0, dx, best[1], cons, None, None, mobile, targets, report)
    if not math.isfinite(t.energy):
        restore_state(s, X0)
        t = s.evaluate()
    it.cg_history = None
    return SaddleResult(value, best[1], t.energy, t.total_area, t, report)


def beyond_reference(surface) -> list[str]:
    """Notes for the Hessian commands where the Evolver 2.70 refuses and
    pyevolver goes on on purpose: gap energy (REF's ERROR 1604: "Cannot do
    gap energy Hessian").  (REF's ERROR 3362 for FIXED quantities of global
    methods, fixed volumes with content integrals or on a torus comes only
    with worker threads, ``-p1``: without them REF converts them to named
    quantities and steps as pyevolver does.)"""
    notes = []
    if "gap" in surface.evaluate().terms:
        notes.append("pyevolver: gap energy in the Hessian by differences of its gradient "
                     "(the Evolver refuses: ERROR 1604)")
    return notes


def metric(hs: HessianSystem, surface, mix: float = 0.5) -> HessianSystem:
    """Install the metric of ``linear_metric`` in ``hs`` (``hs.M``, (n, n)
    sparse, and ``hs.M_floor``, a lower bound of its eigenvalues) and
    return it.

    On the vertex values the metric is ``(1 − mix) M_star + mix M_lin``
    with ``M_star = diag(A_v / 3)`` (a third of the area of the facets at
    each vertex) and ``M_lin`` the integral of the linear interpolation,
    ``A_f / 12 · (1 + δ_ij)`` per facet (eigentut.htm §8, "Hessian with
    metric"; ``mix`` is ``linear_metric_mix``); on the free coordinates
    ``Tᵀ (M ⊗ I₃) T``.  Measured: cube.fe after ``g 10`` gives REF's
    eigenvalues for mix 0, 0.5 and 1 (0.6464353000714, 0.796433510134711,
    1.036886946140311).
    """
    s = surface
    if getattr(s, "string", False):
        raise UnsupportedError("linear_metric in the string model")
    if getattr(s, "quadratic", False) or getattr(s, "order", 1) != 1:
        raise UnsupportedError("linear_metric in the quadratic model",
                               "REF uses the quadratic interpolation metric there")
    t = s.evaluate()
    A = np.asarray(t.facet_area, float)
    F = s.F
    star = np.bincount(F.ravel(), weights=np.repeat(A / 3.0, 3), minlength=s.nv)
    i, j = np.meshgrid(np.arange(3), np.arange(3), indexing="ij")
    rows = F[:, i.ravel()].ravel()
    cols = F[:, j.ravel()].ravel()
    vals = (A[:, None] / 12.0 * np.where(i == j, 2.0, 1.0).ravel()[None, :]).ravel()
    Mv = (1.0 - mix) * sp.diags(star) + mix * sp.csr_matrix((vals, (rows, cols)),
                                                              shape=(s.nv, s.nv))
    T = hs.T
    hs.M = (T.T @ sp.kron(Mv, sp.identity(3)) @ T).tocsc()
    # M_lin ≥ diag(A_v/12) = M_star/4 (each facet's mass matrix A/12·(I + 11ᵀ) ≥ A/12·I)
    used = star[np.repeat(np.arange(s.nv), hs.basis.ndof)]
    hs.M_floor = float(((1.0 - mix) + mix / 4.0) * used.min()) if len(used) else 1.0
    if not hs.M_floor > 0:
        raise UnsupportedError("linear_metric with a mobile vertex on no facet",
                               "its mass is zero")
    return hs
