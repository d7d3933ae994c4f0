"""``hessian`` / ``hessian_seek``: Newton steps on the constrained problem.

The step solves the bordered (KKT) system

    [ Tᵀ H T   Tᵀ C ] [ dy ]   [ −Tᵀ ∇E ]
    [ Cᵀ T      0   ] [ −λ ] = [ t − v  ]

where ``H`` is the Hessian of the Lagrangian ``E − Σ λ_i g_i − Σ μ_v φ(x_v)``
(energy, fixed body volumes / FIXED quantities ``g_i`` with targets ``t``,
level-set constraints φ), ``C`` holds the gradients of the ``g_i`` and
``T`` maps the free coordinates ``dy`` of each mobile vertex (its tangent
space to its level-set constraints) to ``dx = T dy``.  Everything is a
sparse matrix; the system is solved by CHOLMOD's sparse LDLᵀ of the
Hessian block and a Schur complement for the border when scikit-sparse is
installed (extra ``pyevolver[cholmod]``), by a sparse LU factorization of
the bordered matrix (``scipy.sparse.linalg.splu``) otherwise.  After the move, vertices are projected
back onto their constraints and the fixed values restored as in ``g``.

Hessians: facet area (tension), edge length, facet volume (z-flux and
symmetric) and gravity are analytic (per-element 9×9 / 6×6 blocks); every
other term (constraint and boundary integrals, quantities, torus lifts) is
differentiated by central differences of its analytic gradient, with a
distance-2 vertex colouring so that one gradient pair per colour and
coordinate gives all columns (Curtis–Powell–Reid 1974; Coleman–Moré 1983).
"""
from __future__ import annotations

import warnings

import numpy as np
import scipy.sparse as sp

from ..constraints import boundary_eval, boundary_groups, vertex_coords
from ..errors import UnsupportedError, dimension_error
from ..geometry import kernels as G
from ..methods.basic import (edge_length_hessian, facet_area_hessian,  # noqa: F401
                             facet_gravity_hessian, facet_volume_hessian)
from ..methods.curvature import legacy_gradient
from ..methods.curvature_hessian import legacy_hessian
from ..methods.registry import lookup
from . import gradient as GR
from . import normal_assembly as NB
from . import quadratic_hessian as QH
from .iterate import _Constraints
from .ordering import nested_dissection


#: Hessians of other surface models, installed by their modules
#: (``"string"``: :mod:`.string_hessian`): objects with ``check(s)``,
#: ``basis(s, mobile, normal)`` and ``hessian(s, cons, lam, grad_fn, basis)``.
MODEL_HESSIAN: dict = {}


class Basis:
    """Per-vertex bases of the free motions: vertex ``v`` moves by
    ``B[v, :, :ndof[v]] @ dy[start[v]:start[v] + ndof[v]]``.

    ``B`` (nv, 3, d) with ``d`` the largest ``ndof`` (1 in the usual
    ``hessian_normal`` case); :meth:`matrix` is the same map as a sparse
    (3nv, ndof.sum()) matrix ``T``.
    """

    def __init__(self, B, ndof):
        self.ndof = np.asarray(ndof, np.int64)
        d = int(self.ndof.max()) if len(self.ndof) else 0
        self.B = np.ascontiguousarray(B[:, :, :max(d, 1)])
        self.start = np.concatenate([[0], np.cumsum(self.ndof)[:-1]]).astype(np.int64)
        self.n = int(self.ndof.sum())

    def matrix(self):
        nv, _, d = self.B.shape
        j = np.arange(d)
        use = j[None, :] < self.ndof[:, None]                      # (nv, d)
        v, jj = np.nonzero(use)
        rows = (3 * v[:, None] + np.arange(3)[None, :]).ravel()
        cols = np.repeat(self.start[v] + jj, 3)
        vals = self.B[v, :, jj].ravel()
        return sp.csr_matrix((vals, (rows, cols)), shape=(3 * nv, self.n))


def _vertex_adjacency(s):
    """(nv, nv) 0/1: vertices on one edge or facet, each its own neighbour."""
    nv = s.nv
    F = s.F
    r = np.concatenate([s.E[:, 0], s.E[:, 1]] + [F[:, i] for i in range(3)])
    c = np.concatenate([s.E[:, 1], s.E[:, 0]] + [F[:, (i + 1) % 3] for i in range(3)])
    A = sp.csr_matrix((np.ones(len(r)), (r, c)), shape=(nv, nv))
    return ((A + A.T + sp.identity(nv)) != 0).astype(np.float64).tocsr()


def distance2_coloring(s, seed=0, adjacency=None):
    """Colour vertices so that no two of a colour share a facet or an edge
    neighbour (Jones–Plassmann rounds on the square of the vertex graph;
    ``adjacency`` another 0/1 neighbour matrix).  Returns (nv,) colour
    numbers."""
    nv = s.nv
    A = _vertex_adjacency(s) if adjacency is None else adjacency
    A2 = (A @ A).tocsr()
    A2.setdiag(0)
    A2.eliminate_zeros()
    rng = np.random.default_rng(seed)
    weight = rng.permutation(nv).astype(float) + 1.0
    color = np.full(nv, -1, np.int64)
    k = 0
    rows = np.repeat(np.arange(nv), np.diff(A2.indptr))
    while (color < 0).any():
        live = color < 0
        wl = np.where(live, weight, 0.0)
        # max live-neighbour weight of each vertex
        nbw = np.zeros(nv)
        np.maximum.at(nbw, rows, wl[A2.indices])
        pick = live & (weight > nbw)
        color[pick] = k
        k += 1
    return color


def fd_hessian(fun, s, h=None, adjacency=None):
    """Sparse Hessian of a gradient function ``fun(X) -> (nv, 3)`` by central
    differences over a distance-2 colouring (of ``adjacency``, by default
    the vertices on one edge or facet)."""
    if s.nv == 0:
        return sp.csr_matrix((0, 0))
    X0 = s.X.copy()
    scale = float(np.max(np.ptp(X0, axis=0))) if len(X0) else 1.0
    h = h if h is not None else 1e-5 * max(scale, 1e-12)
    A = _vertex_adjacency(s) if adjacency is None else adjacency
    color = distance2_coloring(s, adjacency=A)
    A = A.tocoo()
    nb_r, nb_c = A.row, A.col                   # pairs (z, u) with z near u
    rows, cols, vals = [], [], []
    try:
        for col in range(color.max() + 1):
            members = color == col
            sel = members[nb_c]
            zr, uc = nb_r[sel], nb_c[sel]
            for k in range(3):
                s.X = X0.copy()
                s.X[members, k] += h
                gp = fun(s.X)
                s.X = X0.copy()
                s.X[members, k] -= h
                gm = fun(s.X)
                D = (gp - gm) / (2 * h)             # (nv, 3)
                for i in range(3):
                    rows.append(3 * zr + i)
                    cols.append(3 * uc + k)
                    vals.append(D[zr, i])
    finally:
        s.X = X0
    H = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(3 * s.nv, 3 * s.nv))
    return 0.5 * (H + H.T)


def _analytic_parts(s, t, cons, lam, basis=None, hessian=True, gradient=True, lowrank=None):
    """Analytic Hessian and gradient of the parts that have closed forms,
    and whether they cover the whole Lagrangian.

    The Hessian is (3nv, 3nv), or projected on ``basis`` (see
    :func:`pyevolver.methods._common.assemble`); with ``hessian=False`` only the gradient is formed
    (``H`` is None), with ``gradient=False`` only the Hessian (``g`` is None).
    ``lowrank``: the list that receives the dense low-rank terms of the
    FUNCTION quantities nonlinear in their instances' values (see
    :func:`_quantity_hessian`); None refuses such quantities.
    """
    if not hessian and lowrank is None:
        lowrank = []                 # (only the gradients: the rank terms are not formed)
    parts = []                       # (hessian function, args) of each analytic term
    # one direction per vertex: the facet terms' 3 × 3 blocks summed, assembled once
    blocks = NB.applies(t, basis) if hessian else None
    if blocks is not None:
        blocks.area(s.facet_tension)
    else:
        parts.append((facet_area_hessian, (t, s.facet_tension)))
    g = GR.corner_scatter(t, GR.facet_area_grad(t), s.facet_tension) if gradient else None
    complete = set(t.terms) <= {"facet_tension", "edge_tension", "gravity", "sq_curvature"}
    et = s.eattr.get("tension")
    if et is not None and np.any(et):
        nz = np.nonzero(et)[0]
        parts.append((edge_length_hessian, (t, nz, et[nz])))
        if gradient:
            g = g + GR.edge_length_grad(t, nz, et[nz])
    if getattr(t, "con_energy", 0.0):
        complete = False
    b = s.bodies
    if "gravity" in t.terms:
        if s.periods is None:
            w = s.gravity_constant * (b.facet_matrix.T @ b.density)
            parts.append((facet_gravity_hessian, (t, w)))
            if gradient:
                g = g + GR.corner_scatter(t, GR.facet_gravity_grad(t), w)
        else:
            complete = False
    plain_volume = s.periods is None and not GR.content_edge_terms(t)
    if b.n and not np.all(np.isnan(b.pressure)):
        complete = False
    if "sq_curvature" in t.terms:
        k = s.sq_curvature_modulus
        parts.append((lambda basis=None: k * legacy_hessian(t, basis), ()))
        if gradient:
            g = g + k * legacy_gradient(t)
    # named quantities: energies with weight 1, fixed ones with −λ
    weighted = [(q, 1.0) for q in s.quantities.values() if q.kind == "energy" and q.modulus]
    weighted += [(q, -lam[len(cons.bodies) + k]) for k, q in enumerate(cons.quantities)]
    for q, wq in weighted:
        hq = _quantity_hessian(t, q, wq, lowrank)
        if hq is None:
            complete = False
            continue
        parts.extend(hq)
        if gradient:
            g = g + wq * GR.quantity_gradient(t, q)
    if cons.bodies:
        if plain_volume:
            w = np.zeros(b.n)
            for k, i in enumerate(cons.bodies):
                w[i] = -lam[k]
            fw = b.facet_matrix.T @ w
            if blocks is not None:
                blocks.volume(fw, s.symmetric_content)
            else:
                parts.append((facet_volume_hessian, (t, fw, s.symmetric_content)))
            if gradient:
                g = g + GR.corner_scatter(t, GR.facet_volume_grad(t, s.symmetric_content), fw)
        else:
            complete = False
    H = None
    if hessian:
        mats = [fn(*args, basis=basis) for fn, args in parts]
        if blocks is not None:
            mats.append(blocks.matrix())
        H = _sum(mats)
    return H, g, complete


def _sum(mats):
    """CSR sum of sparse matrices of one shape: their COO entries
    concatenated and converted once (duplicates summed)."""
    if len(mats) == 1 and sp.isspmatrix_csr(mats[0]) and mats[0].has_canonical_format:
        return mats[0]
    coo = [m.tocoo() for m in mats]
    if len(coo) == 1:
        return coo[0].tocsr()
    return sp.csr_matrix((np.concatenate([c.data for c in coo]),
                          (np.concatenate([c.row for c in coo]),
                           np.concatenate([c.col for c in coo]))), shape=coo[0].shape)


def _function_derivatives(t, q):
    """``(names, ∂f/∂v (m,), ∂²f/∂v∂v (m, m))`` of the FUNCTION of ``q`` at
    the evaluation ``t``, ``names`` its m ``instance.value`` names."""
    env = t.instance_values(q)
    names = list(env)
    params = t.surface.param_env()
    return (names, q.function.gradient(params, env, 1, names)[0],
            q.function.hessian(params, env, 1, names)[0])


def _quantity_hessian(t, q, weight, lowrank=None):
    """Hessian terms ``[(function, args)]`` of ``weight × q``, or None when
    one of its methods has no analytic Hessian.

    A FUNCTION quantity ``f(v_1 .. v_m)`` of instance values has the Hessian
    ``Σ_i ∂f/∂v_i H_i + Σ_ij ∂²f/∂v_i∂v_j ∇v_i ∇v_jᵀ``.  The first sum is
    returned; the second, dense but of rank at most m, is appended to
    ``lowrank`` as ``(instance names, weight × modulus × ∂²f/∂v∂v (m, m))``
    (:func:`lowrank_border` forms it); with ``lowrank`` None a nonlinear
    FUNCTION is refused.  Its instances then need analytic Hessians: the
    central differences over a vertex colouring assume local couplings.
    """
    s = t.surface
    out = []
    if q.function is not None:
        names, d, second = _function_derivatives(t, q)
        nonlinear = bool(np.any(second != 0))
        if nonlinear:
            if lowrank is None:
                raise UnsupportedError(f"this Hessian with the quantity FUNCTION of {q.name}",
                                       "only functions linear in the instance values here; "
                                       "hessian and hessian_seek take nonlinear ones")
            lowrank.append(([n[:-6] for n in names], weight * q.modulus * second))
        for di, n in zip(d, names):
            if di or nonlinear:
                part = _quantity_hessian(t, s.quantities[n[:-6]], weight * q.modulus * di)
                if part is None:
                    if nonlinear:
                        raise UnsupportedError(
                            f"hessian with the nonlinear quantity FUNCTION of {q.name}",
                            f"{n} has no analytic Hessian")
                    return None
                if di:                  # (with di = 0 only checked: no zero matrices)
                    out.extend(part)
        return out
    for m, etype, idx, sign in q.methods:
        w = np.ones(len(idx)) if sign is None else np.asarray(sign, float)
        w = w * (m.modulus * q.modulus * weight)
        entry = lookup(m.method)
        if entry.hessian is None:
            if entry.no_hessian:
                raise UnsupportedError(f"hessian with method {m.method}", entry.no_hessian)
            return None
        if entry.hessian_applies is not None and not entry.hessian_applies(s):
            return None
        out.append((entry.hessian, (t, m, np.asarray(idx, np.int64), w)))
    return out


def lowrank_border(t, lowrank, T):
    """The low-rank terms of :func:`_quantity_hessian` on the free
    coordinates ``dy`` (``dx = T dy``) as ``W diag(sign) Wᵀ``.

    Each term ``(names, C)`` is ``G C Gᵀ`` with ``G`` (3nv, m) the gradients
    of the instances ``names``; with ``C = Q Λ Qᵀ`` its columns are
    ``Tᵀ G Q |Λ|^½`` and its signs ``sign Λ`` (zero eigenvalues dropped).
    Returns ``(W (n, r), sign (r,))``, or None when there is no term.
    """
    s = t.surface
    cols, signs = [], []
    for names, C in lowrank:
        w, Q = np.linalg.eigh(0.5 * (C + C.T))
        keep = np.abs(w) > 1e-14 * np.abs(w).max(initial=0.0)
        if not keep.any():
            continue
        G = np.stack([GR.quantity_gradient(t, s.quantities[n]).ravel() for n in names], axis=1)
        cols.append(np.asarray(T.T @ G) @ (Q[:, keep] * np.sqrt(np.abs(w[keep]))))
        signs.append(np.sign(w[keep]))
    if not cols:
        return None
    return np.hstack(cols), np.concatenate(signs)


def lagrangian_gradient(cons, lam):
    """``grad_L(t) -> (nv, 3)``: the gradient of E − Σ λ_i g_i at an
    evaluation ``t`` (the ``grad_fn`` of :func:`lagrangian_hessian`)."""
    def grad_L(tt):
        g = GR.energy_gradient(tt)
        for lv, gg in zip(lam, cons.gradients(tt) if len(cons) else []):
            g = g - lv * gg
        return g
    return grad_L


def lagrangian_hessian(s, cons, lam, grad_fn, basis=None, t=None, lowrank=None):
    """Sparse Hessian of E − Σ λ_i g_i (level-set terms excluded): (3nv, 3nv),
    or ``Tᵀ H T`` on a :class:`Basis`; ``t`` the surface's current
    evaluation when the caller has it.  ``lowrank``, a list, receives the
    low-rank terms of nonlinear FUNCTION quantities, which the sparse
    matrix leaves out (:func:`_quantity_hessian`); without it they are
    refused (UnsupportedError)."""
    if getattr(s, "order", 1) == 2:         # the quadratic model's hook
        t = s.evaluate() if t is None else t
        for q in s.quantities.values():     # (its differences assume local couplings)
            if q.function is not None and q.kind in ("energy", "fixed") and \
                    np.any(_function_derivatives(t, q)[2] != 0):
                raise UnsupportedError(f"hessian in the quadratic model with the nonlinear "
                                       f"quantity FUNCTION of {q.name}")
        return QH.lagrangian_hessian(s, grad_fn, basis, fd_hessian)
    t = s.evaluate() if t is None else t
    H, _, complete = _analytic_parts(s, t, cons, lam, basis, gradient=False, lowrank=lowrank)
    if complete:
        return H

    def rest(X):
        tt = s.evaluate()
        _, ga, _ = _analytic_parts(s, tt, cons, lam, hessian=False)
        return grad_fn(tt) - ga
    Hf = fd_hessian(rest, s)
    if basis is not None:
        T = basis.matrix()
        Hf = T.T @ Hf @ T
    return H + Hf


def vertex_normals(s, t):
    """(nv, 3) unit vertex normals of hessian_normal: the normalized sums of
    the facet area vectors (:func:`geometry.vertex_normals` without an order;
    not the ``vertex_normal`` attribute, see there)."""
    if getattr(s, "order", 1) == 2:
        return QH.node_normals(s)
    return G.vertex_normals(s.F, t.facet_N2, s.nv)


def _triple_edges(s):
    """Indices of edges with three or more facets (junction lines)."""
    idx = s.topology()[0]
    return np.nonzero(np.bincount(idx.ravel(), minlength=s.ne) >= 3)[0]


def constraint_groups(s, con, cids):
    """The vertices ``con`` grouped by the set of level-set constraints
    (ids ``cids``) they are on: yields ``(key, sel, active, Gm)``, ``key``
    the on/off row of the group, ``sel`` its vertices, ``active`` its
    constraint ids and ``Gm`` (n, 3, k) their formulas' gradients there."""
    env = s.param_env()
    on = np.stack([s.vcon[c][con] for c in cids], axis=1)
    keys, inv = np.unique(on, axis=0, return_inverse=True)
    inv = inv.ravel()
    for gi, key in enumerate(keys):
        sel = con[inv == gi]
        coords = vertex_coords(s, sel)
        active = [c for c, k in zip(cids, key) if k]
        Gm = np.stack([s.constraints[c].formula.gradient(env, coords, len(sel))
                       for c in active], axis=2)
        yield key, sel, active, Gm


def tangent_basis(s, mobile, normal=True, t=None):
    """The free motions of the vertices as a :class:`Basis`.

    Unconstrained vertices move freely (3 dof), or with ``normal`` (the
    Evolver's default ``hessian_normal``) only along their vertex normal;
    vertices on triple junction lines move perpendicular to the line and
    points where several junction lines meet keep all 3 dof.  Vertices on
    level-set constraints move in the constraint's tangent space (with
    ``normal``: along the normal projected onto it).  Also returns the
    constraint gradients per group, for :func:`constraint_curvature`.
    """
    nv = s.nv
    cids = sorted(s.vcon)
    ncon = np.zeros(nv, np.int64)
    for c in cids:
        ncon += s.vcon[c]
    B = np.zeros((nv, 3, 3))
    ndof_v = np.where(mobile, 3 - np.minimum(ncon, 3), 0)
    if normal:
        t = s.evaluate() if t is None else t
        nrm = vertex_normals(s, t)
        trip = _triple_edges(s)
        jcnt = np.bincount(s.E[trip].ravel(), minlength=nv)
        plain = mobile & (ncon == 0) & (jcnt == 0) & (np.linalg.norm(nrm, axis=1) > 0)
        line = mobile & (ncon == 0) & (jcnt == 2)
        ndof_v = np.where(plain, 1, ndof_v)
        ndof_v = np.where(line, 2, ndof_v)
        ndof_v = np.where(mobile & (ncon > 0) & (ncon < 3), 1, ndof_v)
        B[plain, :, 0] = nrm[plain]
        sel = np.nonzero(line)[0]
        if len(sel):
            # line direction: principal axis of the junction edges at the
            # vertex (Σ d dᵀ, independent of the edges' orientations)
            d = t.edge_vec[trip]
            dd = (d[:, :, None] * d[:, None, :]).reshape(-1, 9)
            M = np.zeros((nv, 9))
            for i in range(9):
                M[:, i] = np.bincount(s.E[trip].ravel(), weights=np.repeat(dd[:, i], 2),
                                      minlength=nv)
            u = np.linalg.eigh(M[sel].reshape(-1, 3, 3))[1][:, :, 2]
            Uu, _, _ = np.linalg.svd(u[:, :, None], full_matrices=True)
            B[sel, :, :2] = Uu[:, :, 1:3]
        free = mobile & (ncon == 0) & ~plain & ~line
    else:
        free = mobile & (ncon == 0)
    B[free] = np.eye(3)
    for bid, rows in boundary_groups(s, mobile):
        # parametric boundary: the tangent space of the curve or surface X(p)
        _, J = boundary_eval(s, bid, s.vattr["params"][rows])
        U = np.linalg.svd(J, full_matrices=False)[0]             # (n, 3, k)
        if normal:
            nt = np.einsum("nij,ni->nj", U, nrm[rows])
            nn = np.linalg.norm(nt, axis=1)
            v = np.where(nn[:, None] > 1e-12, nt / np.maximum(nn, 1e-300)[:, None],
                         np.eye(U.shape[2])[0][None, :])
            U = np.einsum("nij,nj->ni", U, v)[:, :, None]
        B[rows] = 0.0
        B[rows, :, :U.shape[2]] = U
        ndof_v[rows] = U.shape[2]
    con = np.nonzero(mobile & (ncon > 0))[0]
    grads = {}
    if len(con):
        for key, sel, active, Gm in constraint_groups(s, con, cids):
            U, S_, Vt = np.linalg.svd(Gm, full_matrices=True)
            kk = len(active)
            Tb = U[:, :, kk:]                                    # (n, 3, 3-k)
            if normal and kk < 3:
                # the normal projected on the tangent space (when it has a part there)
                nt = np.einsum("nij,ni->nj", Tb, nrm[sel])          # (n, 3-k)
                nn = np.linalg.norm(nt, axis=1)
                v = np.where(nn[:, None] > 1e-12, nt / np.maximum(nn, 1e-300)[:, None],
                             np.eye(3 - kk)[0][None, :])
                Tb = np.einsum("nij,nj->ni", Tb, v)[:, :, None]
            B[sel, :, :Tb.shape[2]] = Tb
            grads[tuple(key)] = (sel, active, Gm)
    return Basis(B, ndof_v), grads


def constraint_curvature(s, grads, force_grad):
    """Σ_v μ_v ∇²φ_c(x_v) with μ from the normal part of ``force_grad``
    (the Lagrangian gradient, (nv, 3)); sparse (3nv, 3nv) block diagonal."""
    rows, cols, vals = [], [], []
    env = s.param_env()
    for key, (sel, active, Gm) in grads.items():
        coords = vertex_coords(s, sel)
        GtG = np.einsum("nik,nil->nkl", Gm, Gm)
        rhs = np.einsum("nik,ni->nk", Gm, force_grad[sel])
        mu = np.linalg.solve(GtG, rhs[..., None])[..., 0]       # (n, k)
        Hs = np.zeros((len(sel), 3, 3))
        for j, c in enumerate(active):
            Hs += mu[:, j, None, None] * s.constraints[c].formula.hessian(env, coords, len(sel))
        for i in range(3):
            for k in range(3):
                rows.append(3 * sel + i)
                cols.append(3 * sel + k)
                vals.append(Hs[:, i, k])
    if not rows:
        return None
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(3 * s.nv, 3 * s.nv))


_ND_MIN = 2000     # unknowns: below this CHOLMOD's own AMD order is as good


def _cholmod():
    """scikit-sparse's CHOLMOD module, or None when it is not installed."""
    try:
        from sksparse import cholmod
    except ImportError:
        return None
    return cholmod


def solve_bordered(K, B, r, d, method=None, points=None, pivots=None, D=None):
    """Solve ``[[K, B], [Bᵀ, diag(D)]] [y; μ] = [r; d]`` (D None: zeros).

    K : sparse symmetric (n, n); B : (n, k) dense or None; r : (n,); d : (k,).
    Returns the stacked solution (n + k,).  ``method`` "cholmod" factors K
    with CHOLMOD's LDLᵀ (scikit-sparse; symmetric, indefinite allowed) and
    eliminates the k multipliers by the Schur complement ``Bᵀ K⁻¹ B``;
    "splu" factors the whole bordered matrix with SuperLU.  By default
    CHOLMOD when installed, SuperLU otherwise or when CHOLMOD meets a zero
    pivot.  ``points`` (n, 3), the position of each unknown, lets CHOLMOD
    eliminate in the geometric nested-dissection order of
    :func:`~pyevolver.evolve.ordering.nested_dissection` instead of its
    own AMD order (about half the factorization time on large surfaces).
    ``pivots``, a list: when CHOLMOD solved, it receives the LDLᵀ pivots of
    K and the Schur complement ``Bᵀ K⁻¹ B − diag(D)`` (None without a
    border), from which :mod:`.eigen` reads the inertia at no extra cost.
    ``D`` (k,): the border's diagonal block (:meth:`HessianSystem.border`:
    nonzero for the auxiliary unknowns of a low-rank term).
    """
    chol = _cholmod() if method in (None, "cholmod") else None
    if method == "cholmod" and chol is None:
        raise UnsupportedError("hessian solver cholmod", "scikit-sparse is not installed")
    if chol is not None:
        try:
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                perm = None
                if points is not None and K.shape[0] > _ND_MIN:
                    perm = nested_dissection(points, K)
                    Kp = K.tocsr()[perm][:, perm].tocsc()
                    f = chol.cholesky(Kp, mode="simplicial", ordering_method="natural")
                else:
                    f = chol.cholesky(K.tocsc(), mode="simplicial")
                R = r[:, None] if B is None else np.column_stack([r, B])
                if perm is None:
                    Z = f(R)
                else:
                    Z = np.empty_like(R)
                    Z[perm] = f(R[perm])
                if B is None:
                    sol = Z[:, 0]
                else:
                    S = B.T @ Z[:, 1:] - (0.0 if D is None else np.diag(D))
                    mu = np.linalg.solve(S, B.T @ Z[:, 0] - d)
                    y = Z[:, 0] - Z[:, 1:] @ mu
                    sol = np.concatenate([y, mu])
            if np.all(np.isfinite(sol)):
                if pivots is not None:
                    pivots.extend([f.D(), None if B is None else S])
                return sol
        except (chol.CholmodError, np.linalg.LinAlgError):
            pass
    if B is None:
        M, rhs = K.tocsc(), r
    else:
        M = sp.bmat([[K, sp.csc_matrix(B)], [sp.csc_matrix(B.T), None if D is None
                                               else sp.diags(D)]], format="csc")
        rhs = np.concatenate([r, d])
    try:
        import scipy.sparse.linalg as spla   # 0.1 s and 8 MB at start-up: when first used
        return spla.splu(M).solve(rhs)
    except RuntimeError as exc:
        # exactly singular (e.g. no energy on the free vertices): the
        # minimum-norm least-squares step, which is zero along the null space
        import scipy.sparse.linalg as spla
        sol, istop = spla.lsqr(M, rhs, atol=1e-15, btol=1e-15, iter_lim=10 * M.shape[0])[:2]
        if istop in (0, 1, 2, 4, 5) and np.all(np.isfinite(sol)):
            return sol
        raise UnsupportedError("hessian on a singular Hessian",
                               f"the bordered Hessian could not be factored ({exc})") from None


class HessianSystem:
    """The constrained Hessian of :func:`hessian_system`.

    ``K`` (n, n) sparse: the Hessian of the Lagrangian on the free
    coordinates ``dy`` (``dx = T dy``, ``T`` (3nv, n) of ``basis``); ``B``
    (n, k) the gradients of the k fixed values in those coordinates (None
    when k = 0); ``rhs`` (n,) = −Tᵀ∇E; ``d`` (k,) the target defects;
    ``lam`` (k,) the multipliers in ``K``; ``cons``, ``mobile`` as in
    :func:`newton_direction`.
    """

    def __init__(self, K, B, rhs, d, T, basis, lam, cons, mobile, X):
        self.K, self.B, self.rhs, self.d, self.T = K, B, rhs, d, T
        self.basis, self.lam, self.cons, self.mobile = basis, lam, cons, mobile
        self.points = np.repeat(X, basis.ndof, axis=0)   # (n, 3) where each unknown sits
        self.M = None               # the eigenvalue metric (n, n); None: the identity
        self.M_floor = 1.0          # a lower bound of the eigenvalues of M
        self.totals = None          # the evaluation K was formed at, when kept
        self.W = None               # (n, r) low-rank term W diag(Wsign) Wᵀ of K, when any
        self.Wsign = None           # (r,) ±1

    def border(self):
        """``(B, d, D)`` of the bordered system with the low-rank term as
        auxiliary unknowns ``z = diag(Wsign) Wᵀ y``:

            [ K    B   W          ] [ y  ]   [ rhs ]
            [ Bᵀ   0   0          ] [ −λ ] = [ d   ]
            [ Wᵀ   0   −diag(Wsign)] [ z  ]   [ 0   ]

        whose elimination of ``z`` leaves ``K + W diag(Wsign) Wᵀ``:
        ``B`` (n, k + r) the border, ``d`` (k + r,), ``D`` (k + r,) its
        diagonal block, None without a low-rank term (then ``B``, ``d`` are
        the system's own).  The multipliers are the first k of the border's
        unknowns.
        """
        if self.W is None:
            return self.B, self.d, None
        k = 0 if self.B is None else self.B.shape[1]
        B = self.W if self.B is None else np.hstack([self.B, self.W])
        d = np.zeros(self.W.shape[1]) if self.B is None else \
            np.concatenate([self.d, np.zeros(self.W.shape[1])])
        return B, d, np.concatenate([np.zeros(k), -self.Wsign])


def hessian_system(it, normal: bool = True, lowrank: bool = False) -> HessianSystem:
    """The Hessian of the Lagrangian on the free motions of the surface of
    the :class:`~pyevolver.evolve.iterate.Iterator` ``it`` and its border
    (the bordered system in this module's docstring).

    ``normal``: each vertex moves along its normal only (``hessian_normal``).
    The multipliers are those stored by the last ``g`` or ``hessian``.
    ``lowrank``: FUNCTION quantities nonlinear in their instances' values
    are taken, their low-rank terms in ``W``, ``Wsign``
    (:meth:`HessianSystem.border`); without it they are refused.
    """
    s = it.surface
    if s.X.shape[1] > 3:     # SPACE_DIMENSION 4..9: hessian_nd.system
        raise dimension_error(s.sdim, "this Hessian")
    model = MODEL_HESSIAN.get("string") if s.string else None
    if s.string:
        if model is None:
            raise UnsupportedError("hessian in the string model")
        model.check(s)
    mobile = it._mobile()
    cons = _Constraints(s)
    t = s.evaluate()
    gE = GR.energy_gradient(t)
    lam = np.zeros(len(cons))
    gs = []
    if len(cons):
        gs = cons.gradients(t)
        for g in gs:
            g[~mobile] = 0.0                                    # zero on fixed vertices
        # The Evolver's Hessian of the Lagrangian uses the multipliers stored
        # by the previous g or hessian step (the printed pressures), not ones
        # fitted to the current gradient: with these, hessian on mound.fe
        # after g 10 agrees with it to 15 digits.
        lam = np.array([s.bodies.lagrange[i] for i in cons.bodies] +
                       [q.pressure for q in cons.quantities], dtype=float)
        lam = np.nan_to_num(lam)

    grad_L = lagrangian_gradient(cons, lam)
    if model is not None:           # the string model's motions and energies
        basis, grads = model.basis(s, mobile, normal=normal)
        T = basis.matrix()
        K = model.hessian(s, cons, lam, grad_L, basis)
    else:
        basis, grads = tangent_basis(s, mobile, normal=normal, t=t)
        T = basis.matrix()
        terms = [] if lowrank else None
        K = lagrangian_hessian(s, cons, lam, grad_L, basis, t=t, lowrank=terms)
    gL = gE - sum((l * g for l, g in zip(lam, gs)), np.zeros_like(gE))
    Hc = constraint_curvature(s, grads, gL)
    if Hc is not None:
        K = K - T.T @ Hc @ T
    K = K.tocsc()
    rhs = -(T.T @ gE.ravel())
    B = d = None
    if len(cons):
        Cm = np.stack([g.ravel() for g in gs], axis=1)          # (3nv, k)
        B = np.asarray(T.T @ Cm)
        d = cons.targets(s) - cons.values(t)
    hs = HessianSystem(K, B, rhs, d, T, basis, lam, cons, mobile, s.X)
    hs.totals = t
    if model is None and terms:
        hs.W, hs.Wsign = lowrank_border(t, terms, T) or (None, None)
    return hs


def newton_direction(it, normal: bool = True):
    """The Newton motion (nv, 3) and new multipliers for the surface of the
    :class:`~pyevolver.evolve.iterate.Iterator` ``it``.

    ``normal``: move each vertex along its normal only (``hessian_normal``).
    Returns ``(dx, lam_new, cons, mobile)``.  The move restores the fixed
    values along the constraint gradients at the moved positions.
    """
    hs = hessian_system(it, normal, lowrank=True)
    K = hs.K
    B, d, D = hs.border()
    sol = solve_bordered(K, B, hs.rhs, d, points=hs.points, D=D)
    n = K.shape[0]
    lam_new = -sol[n:n + len(hs.cons)] if len(hs.cons) else hs.lam
    dy = sol[:n]
    dx = (hs.T @ dy).reshape(it.surface.X.shape)
    return dx, lam_new, hs.cons, hs.mobile
