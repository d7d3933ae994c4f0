"""The Hessian in the string model (``hessian``, ``hessian_seek`` and the
eigenvalue commands on a surface of dimension 1).

Free motions (measured on ``evolver-nox-d``): a vertex moves in the space
coordinates of the surface (x, y for ``SPACE_DIMENSION 2``).  With
``hessian_normal`` (the default) a vertex with exactly two edges moves
perpendicular to the chord between its two neighbours (REF's "volume
gradient" direction: in the plane one direction, in space the plane normal
to the chord); ends, junctions of three or more edges and vertices on level-set
constraints keep every motion their constraints allow.

The Hessian of the Lagrangian is the sum of analytic sparse parts:

* edge tension ``Σ T_e L_e`` (:func:`pyevolver.methods.basic.edge_length_hessian`,
  edge vectors with their torus wraps);
* body areas ``A = Σ -(x_h - x_t)(y_t + y_h)/2`` (a constant bilinear form
  per chain edge), weighted by minus the prescribed pressure, with the
  constraint CONTENT integrands at the vertices (``C(head) - C(tail)``);
* gravity ``Σ -Gρ (x_h - x_t)(y_t² + y_t y_h + y_h²)/6`` per chain edge;
* constraint ENERGY integrands at their vertices (second derivatives of
  the formula);
* named quantities through the Hessians their methods register
  (:mod:`pyevolver.methods.registry`; string methods added there plug in
  without a change here), FIXED ones weighted by minus their multiplier.

Whatever part of the gradient these do not cover (a method registered
without a Hessian) is differentiated by central differences of its
analytic gradient (:func:`pyevolver.evolve.hessian.fd_hessian`), so the sum
is always the Hessian of the whole energy.

A fixed body area cannot be a constraint of REF's Hessian in the string
model: REF stops with ERROR 3362 ("Fixed quantity body_1_vol is not
connected to any mobile vertices.", slidestr.fe, closed chains alike), and
so does pyevolver (:func:`check_fixed_bodies`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..geometry.kernels import edge_vectors
from ..errors import UnsupportedError
from ..methods import string as SM
from ..methods.basic import edge_length_hessian
from ..model.string import chain_points, facet_entries
from . import gradient as GR
from .hessian import (MODEL_HESSIAN, Basis, _quantity_hessian, _sum, constraint_groups,
                      fd_hessian)


def check_fixed_bodies(s) -> None:
    """Refuse the Hessian of a string surface with a body of fixed area."""
    b = s.bodies
    for i in range(b.n):
        if not np.isnan(b.target[i]):
            raise UnsupportedError(
                "hessian in the string model with a body of fixed area",
                f"body {i + 1}: the Evolver (one thread) converts the area to a named "
                "quantity and takes a step pyevolver does not reproduce yet (slidestr.fe); "
                "with worker threads (-p1) it refuses (ERROR 3362)")


# ---------------------------------------------------------------------------
# free motions


def _neighbour_vectors(s):
    """(nv, 2, 3) the vectors from each vertex along its first two edges
    (torus wraps included) and (nv,) the number of edges at each vertex."""
    ev = edge_vectors(s.X, s.E, s.wrap_shift())
    v = np.concatenate([s.E[:, 0], s.E[:, 1]])
    vec = np.concatenate([ev, -ev])
    deg = np.bincount(v, minlength=s.nv)
    order = np.argsort(v, kind="stable")
    first = np.searchsorted(v[order], np.arange(s.nv))
    out = np.zeros((s.nv, 2, 3))
    two = np.nonzero(deg >= 2)[0]
    out[two, 0] = vec[order[first[two]]]
    out[two, 1] = vec[order[first[two] + 1]]
    return out, deg


def string_basis(s, mobile, normal=True):
    """The free motions of a string's vertices: ``(Basis, grads)`` as
    :func:`pyevolver.evolve.hessian.tangent_basis` returns them."""
    nv, dim = s.nv, s.sdim
    if "boundary" in s.vattr and np.any(s.vattr["boundary"][mobile]):
        raise UnsupportedError("the Hessian with parametric boundaries in the string model")
    cids = sorted(s.vcon)
    ncon = np.zeros(nv, np.int64)
    for c in cids:
        ncon += s.vcon[c]
    B = np.zeros((nv, 3, 3))
    ndof = np.zeros(nv, np.int64)
    full = np.zeros((3, 3))
    full[:dim, :dim] = np.eye(dim)
    free = mobile & (ncon == 0)
    B[free] = full
    ndof[free] = dim
    if normal:
        nb, deg = _neighbour_vectors(s)
        sel = np.nonzero(free & (deg == 2))[0]
        if len(sel):
            chord = nb[sel, 1] - nb[sel, 0]
            chord[:, dim:] = 0.0
            ok = np.linalg.norm(chord, axis=1) > 0
            sel, chord = sel[ok], chord[ok]
            # the orthogonal complement of the chord within the space coordinates
            U = np.linalg.svd(chord[:, :dim, None], full_matrices=True)[0]     # (n, dim, dim)
            B[sel] = 0.0
            B[sel, :dim, :dim - 1] = U[:, :, 1:]
            ndof[sel] = dim - 1
    grads = {}
    con = np.nonzero(mobile & (ncon > 0))[0]
    if len(con):
        if normal and dim == 3:
            nb, deg = _neighbour_vectors(s)
            if np.any(deg[con] == 2):
                raise UnsupportedError(
                    "hessian_normal at vertices on constraints of a string in space",
                    "not measured against the Evolver; hessian_normal off works")
        for key, sel, active, Gm in constraint_groups(s, con, cids):
            Gm[:, dim:, :] = 0.0
            U, S_, _ = np.linalg.svd(Gm[:, :dim, :], full_matrices=True)  # (n, dim, dim)
            rank = int(min(len(active), dim))
            B[sel] = 0.0
            B[sel, :dim, :dim - rank] = U[:, :, rank:]
            ndof[sel] = dim - rank
            grads[tuple(key)] = (sel, active, Gm)
    return Basis(B, ndof), grads


# ---------------------------------------------------------------------------
# analytic parts


def _pair_blocks(n, tail, head, Hxx):
    """COO triplets of per-edge 4x4 blocks in (x_t, y_t, x_h, y_h)."""
    verts = np.stack([tail, tail, head, head], axis=1)
    comp = np.array([0, 1, 0, 1])
    rows = (3 * verts[:, :, None] + comp[None, :, None])
    cols = (3 * verts[:, None, :] + comp[None, None, :])
    rows = np.broadcast_to(rows, Hxx.shape).ravel()
    cols = np.broadcast_to(cols, Hxx.shape).ravel()
    return sp.coo_matrix((Hxx.ravel(), (rows, cols)), shape=(3 * n, 3 * n))


def area_hessian(s, per_facet):
    """Hessian (3nv, 3nv) of ``Σ_f w_f A_f`` (chain terms and the constraint
    content integrands at the vertices)."""
    owner, _, _, tail, head = facet_entries(s)
    w = per_facet[owner]
    # a = -(x_h y_t + x_h y_h - x_t y_t - x_t y_h)/2
    H = np.zeros((len(w), 4, 4))
    H[:, 2, 1] = H[:, 1, 2] = -0.5
    H[:, 2, 3] = H[:, 3, 2] = -0.5
    H[:, 0, 1] = H[:, 1, 0] = 0.5
    H[:, 0, 3] = H[:, 3, 0] = 0.5
    parts = [_pair_blocks(s.nv, tail, head, H * w[:, None, None])]
    for formula, on in SM.vertex_integrand(s, "content"):
        f, v, c = SM.content_coefficients(s, on)
        if len(f):
            parts.append(_point_hessian(s, formula, v, c * per_facet[f]))
    return parts


def gravity_hessian(s, t, per_facet):
    """Hessian (3nv, 3nv) of ``Σ_f w_f Σ_e -(x_h - x_t)(y_t² + y_t y_h + y_h²)/6``."""
    owner, _, _, tail, head = facet_entries(s)
    w = per_facet[owner]
    Pt, Ph = chain_points(s, t)
    dx = Ph[:, 0] - Pt[:, 0]
    yt, yh = Pt[:, 1], Ph[:, 1]
    H = np.zeros((len(w), 4, 4))
    a, b = (2 * yt + yh) / 6.0, (yt + 2 * yh) / 6.0
    H[:, 0, 1] = H[:, 1, 0] = a
    H[:, 0, 3] = H[:, 3, 0] = b
    H[:, 2, 1] = H[:, 1, 2] = -a
    H[:, 2, 3] = H[:, 3, 2] = -b
    H[:, 1, 1] = H[:, 3, 3] = -dx / 3.0
    H[:, 1, 3] = H[:, 3, 1] = -dx / 6.0
    return _pair_blocks(s.nv, tail, head, H * w[:, None, None])


def _point_hessian(s, formula, idx, weights):
    """Block-diagonal Hessian of ``Σ_i w_i f(x_{idx_i})``."""
    P = s.X[idx]
    Hf = formula.hessian(s.param_env(), {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}, len(idx))
    Hf = Hf * np.asarray(weights, float)[:, None, None]
    rows = 3 * idx[:, None, None] + np.arange(3)[None, :, None]
    cols = 3 * idx[:, None, None] + np.arange(3)[None, None, :]
    return sp.coo_matrix((Hf.ravel(), (np.broadcast_to(rows, Hf.shape).ravel(),
                                       np.broadcast_to(cols, Hf.shape).ravel())),
                         shape=(3 * s.nv, 3 * s.nv))


def _analytic(s, t, cons, lam, hessian=True):
    """``(parts, gradient, complete)``: the analytic Hessian parts (3nv, 3nv),
    the gradient of the same terms, and False when a quantity's method has
    no analytic Hessian (its gradient is left out of ``gradient``)."""
    parts = []
    complete = True
    g = np.zeros((s.nv, 3))
    et = s.edge_tension
    nz = np.nonzero(et)[0]
    if len(nz):
        if hessian:
            parts.append(edge_length_hessian(t, nz, et[nz]))
        g = g + GR.edge_length_grad(t, nz, et[nz])
    for formula, on in SM.vertex_integrand(s, "energy"):
        idx = np.nonzero(on)[0]
        if hessian:
            parts.append(_point_hessian(s, formula, idx, np.ones(len(idx))))
        g[idx] += SM.point_gradients(s, formula, idx)
    b = s.bodies
    if b.n:
        if s.gravity_constant != 0 and s.gravity_on and np.any(b.density):
            w = np.asarray(s.gravity_constant * (b.facet_matrix.T @ b.density), float)
            if hessian:
                parts.append(gravity_hessian(s, t, w))
            g += SM.chain_grad(s, w, SM.gravity_derivs)
        pmask = ~np.isnan(b.pressure)
        if pmask.any():
            wb = np.where(pmask, -np.nan_to_num(b.pressure), 0.0)
            w = np.asarray(b.facet_matrix.T @ wb, float)
            if hessian:
                parts.extend(area_hessian(s, w))
            g += SM.facet_area_gradient(s, w)
    weighted = [(q, 1.0) for q in s.quantities.values() if q.kind == "energy" and q.modulus]
    weighted += [(q, -lam[len(cons.bodies) + k]) for k, q in enumerate(cons.quantities)]
    for q, wq in weighted:
        hq = _quantity_hessian(t, q, wq)
        if hq is None:
            complete = False
            continue
        if hessian:
            parts.extend(fn(*args, basis=None) for fn, args in hq)
        g = g + wq * GR.quantity_gradient(t, q)
    return parts, g, complete


def _vertex_blocks(m):
    """Only the 3x3 blocks of ``m`` that couple a vertex with itself."""
    c = m.tocoo()
    keep = (c.row // 3) == (c.col // 3)
    return sp.coo_matrix((c.data[keep], (c.row[keep], c.col[keep])), shape=c.shape)


def string_hessian_matrix(s, cons, lam, grad_fn, t=None):
    """The Hessian (3nv, 3nv) of the Lagrangian of a string surface, every
    coupling included (``grad_fn(t)`` its gradient, differentiated by
    central differences for the parts without an analytic Hessian)."""
    t = s.evaluate() if t is None else t
    parts, ga, complete = _analytic(s, t, cons, lam)
    H = _sum(parts) if parts else sp.csr_matrix((3 * s.nv, 3 * s.nv))
    rest = grad_fn(t) - ga
    scale = max(1.0, float(np.abs(ga).max()) if ga.size else 1.0)
    if not complete or np.abs(rest).max(initial=0.0) > 1e-10 * scale:
        def fun(X):
            tt = s.evaluate()
            return grad_fn(tt) - _analytic(s, tt, cons, lam, hessian=False)[1]
        H = H + fd_hessian(fun, s)
    return H.tocsr()


def string_lagrangian_hessian(s, cons, lam, grad_fn, basis):
    """``Tᵀ H T`` as REF's ``hessian`` uses it in the string model: only
    each vertex's own block of the Hessian (REF's string Hessian couples no
    two vertices: measured on open chains, closed loops with pressure and
    gravity, constraint integrands; its matrix, ``hessian_menu`` option D,
    is block diagonal, at twice these values, which gives the same step).

    Where a vertex moves in two or more directions (junctions, free ends,
    strings in space, ``hessian_normal off``) its whole block is kept.  REF
    keeps it too on small networks and on 100grain.fe ``g 5; hessian``
    (``-p1``), but elsewhere its block loses the cross terms of some edges,
    by a pattern that changes with REF's thread count (``-p1``, ``-p2`` and
    the default give three different, each reproducible, matrices on
    100grain.fe with autochop off): REF's error, not followed
    (docs/differences.md)."""
    t = s.evaluate()
    H = string_hessian_matrix(s, cons, lam, grad_fn, t).tocsr()
    T = basis.matrix()
    K = (T.T @ H @ T).tocsr()
    return K


class _StringModel:
    """The string model's entry in :data:`pyevolver.evolve.hessian.MODEL_HESSIAN`."""
    check = staticmethod(check_fixed_bodies)
    basis = staticmethod(string_basis)
    hessian = staticmethod(string_lagrangian_hessian)


MODEL_HESSIAN["string"] = _StringModel()
