"""The fast path of ``g`` on plain surfaces (issue 24: small meshes).

A ``g`` step of :class:`~pyevolver.evolve.iterate.Iterator` on a small
surface spends its time in the fixed cost of a few hundred numpy calls
(eight or nine evaluations, the gradients, the restoring of the fixed
volumes), not in arithmetic.  On the surfaces most runs evolve — facet
tension, fixed body volumes, FIXED vertices, optionally energy quantities —
this module takes the same step with far fewer calls:

* the trial moves ``X0 + s v`` and the restoring corrections ``+ δ u`` are
  made on the facet corners, the directions gathered once per step (above
  20,000 facets each move's ``s v`` or ``Σ δ u`` is gathered instead: no
  corner arrays per direction kept); gathering commutes with the
  element-wise sums, so every coordinate is the same number as the general
  path's; only the actual move is written back to the vertices;
* the volumes after a displacement, before the restoring, are computed
  alone (the energy there is never read);
* with facet tension alone the energy, the area and volume gradients and
  the final :class:`~pyevolver.methods.totals.Totals` come from the same
  corner arrays, each gradient scattered with one ``bincount``;
* the scalar side (one fixed volume: the multiplier, the restoring
  coefficient, the convergence sum) is done in Python floats.

Every number is the general path's (the same products summed in the same
order: tests/evolve/test_fastpath.py compares the two bit for bit).  Any
rarer branch — a non-finite energy, a restoring that does not converge or
grows, a step that raises the energy — gives the step back, untouched, to
the general path (:func:`step` returns None), which takes it with its
warnings.  So do surfaces with anything else (level-set constraints,
boundaries, edge tension, gravity, pressures, the torus or a symmetry
group, FIXED quantities, optimizing parameters, other models) and the
toggles that change the motion (conj_grad, area normalization, normal
motion, approximate curvature, Runge-Kutta, diffusion, jiggle).

``PYEVOLVER_FASTPATH=0`` in the environment turns the fast path off.
"""
from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from ..geometry.kernels import geometry_of_corners
from ..methods._common import csr_matvec, finite
from ..methods import axis_major as AM
from ..methods.axis_major import NEXT as _NEXT, NEXT2 as _NEXT2, sides as _sides
from ..methods.totals import Totals
from . import gradient as GR


class _Fallback(Exception):
    """A branch the fast path leaves to the general step."""


def enabled() -> bool:
    """False when ``PYEVOLVER_FASTPATH`` is 0 / off."""
    return os.environ.get("PYEVOLVER_FASTPATH", "").strip().lower() not in ("0", "off", "no")


def _surface_ok(s) -> str | None:
    """The fast path's mode for the surface ``s``: ``"area"`` (facet
    tension and fixed volumes only), ``"generic"`` (energy quantities too:
    evaluated by the general code), or None (the general step)."""
    if (s.string or getattr(s, "simplex", 0) or s.X.shape[1] != 3 or s.nf == 0
            or getattr(s, "order", 1) != 1 or s.metric is not None or s.periods is not None
            or s.symmetry_group is not None or s.torus_filled or s.sq_curvature_modulus
            or s.vcon or s.econ or s.fcon or s.constraints or s.boundaries
            or getattr(s, "optimizing", None)):
        return None
    for key in ("boundary", "params"):
        v = s.vattr.get(key)
        if v is not None and (key == "params" or np.any(v)):
            return None
    et = s.eattr.get("tension")
    if et is not None and np.any(et):
        return None
    b = s.bodies
    if b.n:
        if not np.all(np.isnan(b.pressure)):
            return None
        if s.gravity_constant != 0 and s.gravity_on and np.any(b.density):
            return None
    mode = "area"
    for q in s.quantities.values():
        if q.kind not in ("energy", "info_only"):
            return None
        mode = "generic"
    return mode


def _settings_ok(st) -> bool:
    return not (st.conj_grad or st.area_normalization or st.normal_motion or st.runge_kutta
                or st.diffusion or st.jiggle or st.approximate_curvature)


class _Plan:
    """What the fast path keeps per surface and topology."""

    def __init__(self, s, mode):
        self.surface = s
        self.topo = s.topology()
        self.mode = mode
        self.Fc = s.facet_corners()                 # (3, nf)
        flat = self.topo[2].ravel()                 # facet-major, as corner_scatter
        self.flat = flat
        # small surfaces: the index of every corner coordinate, so that one
        # bincount scatters all; large ones scatter axis by axis with ``flat``
        # (the same sums, without index arrays of 9 and 9 k entries per facet)
        self.idx3 = None
        if s.nf <= AM.LOW_MEMORY_FACETS:
            nv = s.nv
            self.idx3 = np.concatenate((flat, flat + nv, flat + 2 * nv))
        b = s.bodies
        self.bodies = [i for i in range(b.n) if not math.isnan(b.target[i])]
        self.body_w = []
        # one body of all the facets in order, each +1 (csr_matvec's bincount
        # with the products by 1 left out: the same sum)
        self.one = None
        M = b.facet_matrix
        if b.n == 1 and getattr(M, "format", None) == "csr" and M.nnz == s.nf \
                and np.array_equal(M.indices, np.arange(s.nf)) and np.all(M.data == 1.0) \
                and b.volconst is not None and len(b.volconst) == 1:
            self.one = np.zeros(s.nf, np.int64)
            self.vc0 = float(b.volconst[0])
        if self.bodies:
            Bm = b.facet_matrix.tocsr()
            for i in self.bodies:
                w = np.zeros(Bm.shape[1])
                lo, hi = Bm.indptr[i], Bm.indptr[i + 1]
                np.add.at(w, Bm.indices[lo:hi], Bm.data[lo:hi])
                self.body_w.append(w)

    def valid_for(self, s) -> bool:
        return self.surface is s and self.topo is s.topology()

    # -- kernels on gathered corners (3 axes, 3 corners, nf) ---------------------
    def scatter(self, W):
        """Per-corner vectors ``W`` (3 axes, 3 corners, nf) summed into the
        vertices, (nv, 3) C-ordered (the order of corner_scatter's sums)."""
        nv = self.surface.nv
        if self.idx3 is None:
            return AM.scatter_by_axis(self.flat, W, nv)
        out = np.bincount(self.idx3, weights=W.transpose(0, 2, 1).ravel(), minlength=3 * nv)
        return np.ascontiguousarray(out.reshape(3, nv).T)

    def scatter_many(self, Ws):
        """:meth:`scatter` of several per-corner arrays (in one bincount on
        small surfaces)."""
        k = len(Ws)
        if k == 1 or self.idx3 is None:
            return [self.scatter(W) for W in Ws]
        nv = self.surface.nv
        idx = self.__dict__.get(("idx", k))
        if idx is None:
            idx = self.__dict__[("idx", k)] = np.concatenate(
                [self.idx3 + j * 3 * nv for j in range(k)])
        W = np.empty((k, 3, Ws[0].shape[2], 3))
        for j, Wj in enumerate(Ws):
            W[j] = Wj.transpose(0, 2, 1)
        out = np.bincount(idx, weights=W.ravel(), minlength=3 * k * nv).reshape(k, 3, nv)
        return [np.ascontiguousarray(o.T) for o in out]

    def gather(self, V):
        """(3, 3, nf) corners of the (nv, 3) vectors ``V``."""
        return np.ascontiguousarray(V.T).take(self.Fc, axis=1)

    def gathered(self, V):
        """The corners of the directions ``V`` (a list), kept during the
        step; None on large surfaces (:meth:`combo` gathers their sums)."""
        return None if self.idx3 is None else [self.gather(v) for v in V]

    def combo(self, coef, V, PV):
        """``Σ c_i v_i`` at the facet corners: of the gathered directions
        ``PV``, or the gathered sum when None (the same numbers: gathering
        commutes with the element-wise products and sums)."""
        return _combo(coef, PV) if PV is not None else self.gather(_combo(coef, V))

    def volumes(self, P, symmetric):
        """The constrained bodies' volumes at the corners ``P`` (the facet
        contents only), a list of floats."""
        if symmetric:
            vol = geometry_of_corners(P, True)[3]
        else:
            D = P[:2, 1:] - P[:2, :1]               # the sides' x and y
            cz = D[0, 0] * D[1, 1]
            cz -= D[1, 0] * D[0, 1]
            vol = np.add.reduce(P[2], axis=0)       # (z0 + z1) + z2
            vol /= 6.0
            vol *= cz
        return self.constrained(vol)

    def constrained(self, vol):
        """The constrained bodies' volumes from the facet contents ``vol``:
        :meth:`body_volumes`' numbers, a list of floats."""
        if self.one is not None:
            return [float(np.bincount(self.one, weights=vol, minlength=1)[0]) + self.vc0]
        vols = self.body_volumes(vol)
        return [float(vols[i]) for i in self.bodies]

    def body_volumes(self, vol):
        """The body volumes (Totals._volumes without edge contents)."""
        b = self.surface.bodies
        return csr_matvec(b.facet_matrix, vol) + b.volconst

    def volume_grads(self, P, a, b, N2T, symmetric, mobile_off, QE=None, also=None):
        """The constrained bodies' volume gradients (nv, 3), zero at the
        FIXED vertices (as ``body_volume_gradients`` and ``_constrained_dirs``;
        ``QE``: :func:`_sides` of the corners when known).  ``also``: one
        more per-corner array to scatter with them, returned first."""
        Q, E = _sides(P, a, b) if QE is None else QE
        g = np.empty_like(P)
        if symmetric:                   # corner c: Q[c+1] x Q[c+2] / 6
            g[:] = AM.cross(Q.take(_NEXT, axis=1), Q.take(_NEXT2, axis=1))
            g /= 6.0
        else:
            # _cz_grad times Z: corner c's x part y[c+1] - y[c+2] = -E[y][c],
            # its y part x[c+2] - x[c+1] = E[x][c]; z: cz / 6 (+ 0 Z)
            Z = np.add.reduce(Q[2], axis=0)
            Z /= 6.0
            np.multiply(E[1], -Z, out=g[0])
            np.multiply(E[0], Z, out=g[1])
            g[2] = N2T[2] / 6.0
        any_fixed = mobile_off.any()
        gw = [g] if self.one is not None else [g * w for w in self.body_w]   # (w = 1)
        out = self.scatter_many(([] if also is None else [also]) + gw)
        for v in out[0 if also is None else 1:]:
            if any_fixed:
                v[mobile_off] = 0.0
        return out

    def area_grad(self, P, a, b, N2T, area, tension, QE=None, scattered=True):
        """The facet-tension energy gradient (nv, 3) (``facet_area_grad``
        scattered with the tensions; per corner unless ``scattered``)."""
        _, E = _sides(P, a, b) if QE is None else QE
        L = 2.0 * area                          # (|N2| = 2 area exactly)
        if L.all():
            n = finite(N2T / L)
        else:
            with np.errstate(all="ignore"):
                n = finite(N2T / L)
        g = AM.cross(n[:, None, :], E)          # corner c: n x E[c]
        g *= 0.5
        g *= tension
        return self.scatter(g) if scattered else g


def _totals(s, geom, energy, vols):
    """The :class:`Totals` of a facet-tension surface from its corner
    geometry (what ``Totals.__init__`` sets on such a surface)."""
    P, N2T, area, vol, a, b = geom
    t = object.__new__(Totals)
    t.surface = s
    t._corner_xyz = P
    t._corner_sides = (a, b)
    t.facet_N2 = N2T.T
    t.facet_area = area
    t.facet_volume = vol
    t.total_area = float(area.sum())
    t.terms = {"facet_tension": energy}
    t.con_energy, t.con_content = 0.0, None
    t.volumes = vols
    t.quantity_values = {}
    t.energy = energy + 0.0
    return t


def _plan(it, s, settings, chained):
    """The iterator's plan for ``s`` (made or checked again unless the step
    continues a ``g n`` on the same surface), or None."""
    plan = it.__dict__.get("_fast_plan")
    if chained and plan is not None and plan.valid_for(s) and _settings_ok(settings):
        return plan             # (the last step was the fast path's, on this surface)
    it._fast_plan = None        # (any step of the general path drops the plan)
    if not enabled() or not _settings_ok(settings):
        return None
    mode = _surface_ok(s)
    if mode is None:
        return None
    return _Plan(s, mode)


def _light_totals(s, plan, P, symmetric):
    """The :class:`Totals` at the corners ``P`` (the vertices already
    moved there) without ``Totals.__init__``'s tests of every energy term:
    the facet tension, the bodies' volumes and the quantities, summed in
    ``Totals``' order."""
    geom = geometry_of_corners(P, symmetric)
    e = float(geom[2] @ s.facet_tension)
    t = _totals(s, geom, e, plan.body_volumes(geom[3]) if s.bodies.n else np.zeros(0))
    if s.quantities:
        e = t.energy
        for q in s.quantities.values():
            v = t.quantity_value(q)
            t.quantity_values[q.name] = v
            if q.kind == "energy":
                e += v
        t.energy = e
    return t


def _check(plan, s, t0):
    """The fast path's evaluation must be the general one's, bit for bit
    (a guard against energy terms this module does not know)."""
    if getattr(t0, "_corner_xyz", None) is None or type(t0) is not Totals:
        return False
    mine = _light_totals(s, plan, t0._corner_xyz, s.symmetric_content)
    return (mine.energy == t0.energy and set(vars(mine)) <= set(vars(t0))
            and mine.terms == t0.terms and mine.quantity_values == t0.quantity_values
            and np.array_equal(mine.volumes, t0.volumes))


def forget(it) -> None:
    """Drop the iterator's plan and last end state (the ``hessian`` step:
    it moves the surface, so the next ``g`` makes a new plan anyway, and
    the plan's arrays need not stay beside the factorization)."""
    it.__dict__.pop("_fast_plan", None)
    it.__dict__.pop("_end", None)


def step(it, settings, start, result_type, solve) -> Any:
    """One ``g`` step of the iterator ``it`` by the fast path, or None when
    the general step must take it (nothing changed then).  ``result_type``
    and ``solve``: iterate's StepResult and its solve of the small systems."""
    s = it.surface
    end = it.__dict__.get("_end")
    chained = (start is not None and end is not None and end[0] is start and start.surface is s
               and end[1].shape == s.X.shape and np.array_equal(end[1], s.X))
    plan = _plan(it, s, settings, chained)
    if plan is None:
        return None
    t0 = start if chained else s.evaluate()
    if plan is not it.__dict__.get("_fast_plan") and not _check(plan, s, t0):   # (a new plan)
        return None
    it._fast_plan = plan
    it.__dict__.pop("_end", None)
    try:
        return _step(it, plan, s, settings, t0, result_type, solve)
    except _Fallback:
        s.X = t0_X = it.__dict__.pop("_fast_X0")
        it._end = (t0, t0_X.copy())
        return None


def _step(it, plan, s, settings, t0, result_type, solve):
    X0 = s.X
    it._fast_X0 = X0
    mobile_off = s.vattr["fixed"]
    symmetric = s.symmetric_content
    area_mode = plan.mode == "area"
    tension = s.facet_tension
    P0 = getattr(t0, "_corner_xyz", None)
    if P0 is None:
        raise _Fallback
    a0, b0 = t0._corner_sides
    N2T0 = t0.facet_N2.T
    QE = _sides(P0, a0, b0)
    nb = len(plan.bodies)
    gs = None
    if area_mode and nb and plan.idx3 is not None:
        # (small surfaces: the area and volume gradients in one scatter)
        Ga = plan.area_grad(P0, a0, b0, N2T0, t0.facet_area, tension, QE, scattered=False)
        f, *gs = plan.volume_grads(P0, a0, b0, N2T0, symmetric, mobile_off, QE, also=Ga)
        f = -f
    elif area_mode:     # (large ones: each scattered as soon as made)
        f = -plan.area_grad(P0, a0, b0, N2T0, t0.facet_area, tension, QE)
    else:
        f = -GR.energy_gradient(t0)
    any_fixed = bool(mobile_off.any())
    motion: tuple = (s, f + 0.0, np.where(~mobile_off[:, None], X0, 0.0) if any_fixed
                     else X0.copy())
    if any_fixed:
        f[mobile_off] = 0.0
    s._one_sided_released = None
    tol = settings.target_tolerance
    if nb:
        targets = [float(s.bodies.target[i]) for i in plan.bodies]
        start_vols = [float(t0.volumes[i]) for i in plan.bodies]
        if gs is None:
            gs = plan.volume_grads(P0, a0, b0, N2T0, symmetric, mobile_off, QE)
        QE = Ga = None      # (three corner arrays fewer during the line search)
        A = _matrix(gs)
        bvec = [float((f * g).sum()) for g in gs]
        lam = np.array(_coefficients(A, bvec, solve))
        vel = f - _combo(lam, gs)
        Pus = plan.gathered(gs)
    else:
        QE = Ga = None
        lam = np.zeros(0)
        vel = f
        gs, A, Pus, targets = [], np.zeros((0, 0)), [], []
    motion += (vel,)
    Pv = plan.gathered([vel])

    def evaluate(P, X):
        """(geometry or Totals, energy, body volumes) at the corners ``P``
        (the vertices ``X``)."""
        if area_mode:
            geom = geometry_of_corners(P, symmetric)
            return geom, float(geom[2] @ tension), \
                plan.constrained(geom[3]) if nb else None
        s.X = X
        t = _light_totals(s, plan, P, symmetric)
        return t, t.energy, [float(t.volumes[i]) for i in plan.bodies]

    def diffs(vols):
        if nb == 1:
            d0 = targets[0] - vols[0]
            return [d0], abs(d0) / tol
        d = [tg - v for tg, v in zip(targets, vols)]
        return d, sum(abs(x) / tol for x in d)

    def move(scale):
        """The move by ``scale``: (geometry or Totals, energy, the
        corrections [(coefficients, directions)])."""
        # (at scale 0 the corners are P0's, to the sign of a zero: the
        # volumes are t0's)
        if scale != 0:
            P = plan.combo((scale,), [vel], Pv)
            P += P0             # (P0 + scale Pv: one corner array fewer at once)
        else:
            P = P0
        X = None if area_mode else X0 + scale * vel
        shifts = []
        if not nb:
            g, e, _ = evaluate(P, X)
            return g, e, shifts, None
        vols = start_vols if scale == 0 else plan.volumes(P, symmetric)
        d, err = diffs(vols)
        cur_us, cur_Pu, cur_A = gs, Pus, A
        for k in range(10):
            delta = _coefficients(cur_A, d, solve)
            if area_mode and P is not P0:     # (P only in the geometry g, replaced below)
                P += plan.combo(delta, cur_us, cur_Pu)
            else:
                P = P + plan.combo(delta, cur_us, cur_Pu)
            if X is not None:
                X = X + _combo(delta, cur_us)
            shifts.append((delta, cur_us))
            g, e, vols_new = evaluate(P, X)
            d_new, err_new = diffs(vols_new)
            if err_new <= 1.0:
                if k == 9:
                    raise _Fallback
                return g, e, shifts, vols_new
            if err_new > 1.01 * err:
                raise _Fallback
            improved = err_new < 0.5 * err
            d, err = d_new, err_new
            if not improved:
                if area_mode:
                    _, N2T, _, _, a, b = g
                else:
                    a, b = g._corner_sides
                    N2T = g.facet_N2.T
                cur_us = plan.volume_grads(P, a, b, N2T, symmetric, mobile_off)
                cur_A = _matrix(cur_us)
                cur_Pu = plan.gathered(cur_us)
        raise _Fallback

    def E(scale):
        e = move(scale)[1]
        if not math.isfinite(e):
            raise _Fallback
        return e

    if settings.fixed_scale:
        scale = settings.scale
        E0 = t0.energy
    else:
        scale, E0, _ = it._line_search(E, settings.scale, settings.scale_limit)
    actual = settings.scale_scale * scale
    g, e, shifts, last_vols = move(actual)
    if not math.isfinite(e) or (settings.check_increase and e > E0) \
            or (not settings.fixed_scale and e > E0 and scale > 0):
        raise _Fallback
    X = X0 + actual * vel
    for delta, us in shifts:
        X = X + _combo(delta, us)
    if not np.all(np.isfinite(X)):
        raise _Fallback
    s.X = X
    it.__dict__.pop("_fast_X0", None)
    if area_mode:
        if plan.one is not None and nb:     # (the volume the move ended with)
            vols = np.array(last_vols)
        else:
            vols = plan.body_volumes(g[3]) if s.bodies.n else np.zeros(0)
        t = _totals(s, g, e, vols)
    else:
        t = g
    b = s.bodies
    if b.n:
        b.lagrange[:] = 0.0
    for k, i in enumerate(plan.bodies):
        b.lagrange[i] = -lam[k]
    it._pbase = None
    it._carry = (gs, A)
    it.pressures_valid = True
    it._end = (t, X.copy())
    return result_type(t.energy, t.total_area, scale, b.lagrange.copy() if b.n else np.zeros(0),
                      {}, True, warnings=[], totals=t, motion=motion)


def _combo(coef, vecs):
    """``Σ c_i v_i`` (the general step's ``sum(c * v for ...)``; its
    leading ``0 +`` changes only the sign of a zero)."""
    if len(vecs) == 1:
        return coef[0] * vecs[0]
    return sum(c * v for c, v in zip(coef, vecs))


def _matrix(gs):
    """``_constrained_dirs``' matrix of the directions' products (1 on a
    zero diagonal)."""
    k = len(gs)
    A = np.empty((k, k))
    for i in range(k):
        for j in range(k):
            A[i, j] = float((gs[i] * gs[j]).sum())
    for i in range(k):
        if A[i, i] == 0:
            A[i, i] = 1.0
    return A


def _coefficients(A, d, solve):
    """The restoring coefficients ``A⁻¹ d`` (iterate._solve; one body in
    Python floats, the same division)."""
    if len(d) == 1:
        a = float(A[0, 0])
        if a != 0 and math.isfinite(a) and math.isfinite(d[0]):
            return (np.float64(d[0]) / a,)
    return tuple(solve(A, np.array(d)))
