"""The paper's Figure 4: genus-0 Canham vesicles at three reduced volumes.

Minimise the bending energy W = ∫H² dA (``H = (κ1 + κ2)/2``, a round sphere
has W = 4π) of a closed genus-0 surface at fixed area ``A = 4π`` and fixed
volume ``V = v0 · 4π/3`` (shared/papers/pl-methods-biomembranes, §3 and
Fig. 4): v0 = 0.50 (stomatocyte), 0.62 (discocyte), 0.85 (prolate).  The area
is a FIXED ``facet_area`` quantity, the volume the body's; facets carry no
tension.  Two discretisations of W, each with its cure for bad triangles:

``NormalCur+harmonic``
    ``normal_sq_mean_curvature`` (h = (3/2) F·F/F·N per vertex) plus the
    paper's harmonic energy ``λ E``, ``E = (1/√3) Σ_edges |e|²``
    (``harmonic_energy``), minimised over all vertex coordinates by damped
    Newton steps (:func:`newton_lm`), with λ lowered by a continuation
    (:func:`harmonic_continuation`) while the mesh stays healthy.
``NormalCur+harmonic+u``
    the same energy and continuation, but each λ stage alternates Newton
    solves with equiangulation ``u`` (edge flips) until a solve is followed
    by no flip (:func:`_solve_stage`): the simplicial complex, and with it
    the equilateral conformal structure the harmonic term measures against,
    follows the surface.  On the stomatocyte this lets vertices flow through
    the neck into the inner bulb; on the prolate and the discocyte no edge
    flips and the runs are those of ``NormalCur+harmonic``.
``StarPerp+Evolver recipe``
    ``star_perp_sq_mean_curvature`` (h = (3/2) F·N/N·N) with the Evolver's
    smoothing recipe: cycles of vertex averaging ``V``, equiangulation ``u``
    and a batch of ``g`` steps (``datafiles/paper/vesicle_recipe.cmd``,
    which runs unchanged in ``evolver-nox-d``).
``StarPerp+recipe+Newton``
    the same cycles with the ``g`` batch shortened to 5 steps and followed by
    two ``hessian_seek`` Newton steps (pyevolver; ``evolver-nox-d`` refuses
    ``hessian`` with a FIXED quantity, its ERROR 3362).

Both energies are Σ_v h_v² A_v/3 with ``A_v`` the star area, so a sphere
gives 4π (not the (2H)² convention, 16π): the same normalisation as the
axisymmetric reference :func:`pyevolver.studies.axisymmetric.canham_reference`,
against which every run is measured.

Every run starts from the shipped 162-vertex datafile
``datafiles/paper/vesicle_<shape>_<perp|normal>.fe`` (an ellipsoid, an
oblate ellipsoid, or a sphere whose top cap is pushed in; each exactly at
A = 4π and the shape's v0) and goes coarse to fine: converge, refine ``r``,
converge again, ... through 642, 2,562 (and 10,242) vertices.  A row per
resolution reports the cumulative time.

    python -m pyevolver.studies.fig4_vesicles [--size small|full] [--out DIR]
        [--max-nv N] [--methods normal,normal_u,perp,perp_newton]
        [--shapes stomatocyte,discocyte,prolate] [--no-evolver]

writes ``fig4_vesicles.csv`` (one row per method, shape and resolution,
and the references' descriptors) and ``fig4_vesicles.png`` (the final
meshes' profiles over the reference's, and the error against time).
``small`` stops at 642 vertices, ``full`` at 2,562 (``--max-nv 10242`` goes
further).  The recipe is also run in ``evolver-nox-d`` when it is
installed (``--no-evolver``: not).  Numbers and discussion: docs/paper.md.
"""
from __future__ import annotations

import argparse
import io
import math
import os
import shutil
import subprocess
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
PAPER = os.path.join(HERE, "..", "..", "datafiles", "paper")
RECIPE = "vesicle_recipe.cmd"

#: shape -> (reduced volume, branch of the axisymmetric reference)
SHAPES = {"stomatocyte": (0.50, "stomatocyte"), "discocyte": (0.62, "oblate"),
          "prolate": (0.85, "prolate")}
#: sine modes of the reference per shape (converged to ≤ 1e-7 relative, see docs/paper.md)
REFERENCE_MODES = {"stomatocyte": 128, "discocyte": 24, "prolate": 24}
#: vertex count -> icosphere level
LEVELS = {162: 2, 642: 3, 2562: 4, 10242: 5}
METHODS = {
    "normal": ("normal_sq_mean_curvature", "NormalCur+harmonic"),
    "normal_u": ("normal_sq_mean_curvature", "NormalCur+harmonic+u"),
    "perp": ("star_perp_sq_mean_curvature", "StarPerp+Evolver recipe"),
    "perp_newton": ("star_perp_sq_mean_curvature", "StarPerp+recipe+Newton"),
}


# -- geometry of triangle meshes ------------------------------------------------------------

def area_volume(X, F):
    """Total area and enclosed volume of the closed mesh ``(X (nv, 3), F (nf, 3))``."""
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    A = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    V = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    return float(A), float(V)


def reduced_volume(X, F):
    """``v = 3V/(4π) / (A/(4π))^{3/2}`` (1 for a sphere)."""
    A, V = area_volume(X, F)
    return 3.0 * V / (4 * np.pi) / (A / (4 * np.pi)) ** 1.5


def min_angle(X, F):
    """Smallest corner angle of the triangles, in degrees."""
    P = X[F]
    out = np.inf
    for k in range(3):
        u = P[:, (k + 1) % 3] - P[:, k]
        v = P[:, (k + 2) % 3] - P[:, k]
        ang = np.arctan2(np.linalg.norm(np.cross(u, v), axis=1), np.einsum("ij,ij->i", u, v))
        out = min(out, float(ang.min()))
    return math.degrees(out)


def _deform(X, shape, p):
    """The initial shape family of each branch at parameter ``p``."""
    if shape in ("prolate", "discocyte"):
        return X * np.array([1.0, 1.0, p])              # ellipsoid, semi-axes 1, 1, p
    # a sphere whose cap z > p is reflected (smoothly) into the inside: a cup
    eps = 0.08
    out = X.copy()
    out[:, 2] = X[:, 2] - 2 * eps * np.logaddexp(0.0, (X[:, 2] - p) / eps)
    return out


def initial_shape(shape, level):
    """The start of a run: the icosphere of ``level`` deformed into the
    shape's family (prolate: an ellipsoid of revolution stretched along z;
    discocyte: one flattened along z; stomatocyte: a sphere with its top cap
    pushed in) at exactly the shape's reduced volume, scaled to area 4π.

    Returns ``X (nv, 3)``, ``F (nf, 3)``.
    """
    from scipy.optimize import brentq

    from .meshes import icosphere
    v0 = SHAPES[shape][0]
    X, F = icosphere(level)
    lo, hi = {"prolate": (1.0, 8.0), "discocyte": (0.02, 1.0),
              "stomatocyte": (-0.9, 0.99)}[shape]
    p = brentq(lambda p: reduced_volume(_deform(X, shape, p), F) - v0, lo, hi, xtol=1e-15)
    Y = _deform(X, shape, p)
    return Y * math.sqrt(4 * np.pi / area_volume(Y, F)[0]), F


# -- datafiles ------------------------------------------------------------------------------

def write_datafile(path, X, F, shape, method):
    """Write the Canham problem on ``(X, F)`` as an Evolver datafile.

    ``method`` "perp": ``star_perp_sq_mean_curvature`` (loads in
    ``evolver-nox-d`` too); "normal": ``normal_sq_mean_curvature`` plus the
    quantity ``harm`` (``harmonic_energy``, modulus λ = 1; pyevolver only).
    """
    from .meshes import write_fe
    v0 = SHAPES[shape][0]
    energy = METHODS[method][0]
    lines = [f"// Figure 4 of the PL-methods paper: the Canham problem, {shape} branch,",
             "// reduced volume v0, area 4*pi (FIXED quantity surf), volume v0*4*pi/3",
             "// (body 1), W = sum over vertices of h^2 A/3 (a sphere: 4*pi).",
             "// Written by pyevolver.studies.fig4_vesicles.",
             f"parameter v0 = {v0}",
             f"quantity willmore energy method {energy} global",
             "quantity surf fixed = 4*pi method facet_area global"]
    if method == "normal":
        lines += ["// harmonic energy regularization (1/sqrt 3) sum |e|^2; modulus = lambda",
                  "quantity harm energy modulus 1 method harmonic_energy global"]
    write_fe(path, X, F, header="\n".join(lines), face_attrs="tension 0")
    with open(path, "a") as fh:
        fh.write("\nbodies\n1 " + " ".join(str(i + 1) for i in range(len(F)))
                 + " volume v0*4*pi/3\n")
    return path


def datafile(shape, method, directory=PAPER):
    """Path of the shipped 162-vertex start ``vesicle_<shape>_<perp|normal>.fe``
    (written by :func:`write_datafile` when missing)."""
    kind = "normal" if method.startswith("normal") else "perp"
    path = os.path.join(directory, f"vesicle_{shape}_{kind}.fe")
    if not os.path.exists(path):
        os.makedirs(directory, exist_ok=True)
        X, F = initial_shape(shape, 2)
        write_datafile(path, X, F, shape, kind)
    return path


# -- damped Newton on all coordinates ----------------------------------------------------------

def _rigid_motions(X):
    """(3nv, 6) orthonormalised translations and infinitesimal rotations."""
    nv = len(X)
    R = np.zeros((3 * nv, 6))
    c = X - X.mean(0)
    for k in range(3):
        R[k::3, k] = 1.0
        e = np.zeros(3)
        e[k] = 1.0
        R[:, 3 + k] = np.cross(e, c).ravel()
    q, _ = np.linalg.qr(R)
    return q


def _bordered(K, B, r, d, cache):
    """Solve ``[[K, B], [Bᵀ, 0]] [y; μ] = [r; d]`` for the Newton step.

    With CHOLMOD, first as a positive definite K (supernodal Cholesky, about
    2.5 times faster than the LDLᵀ factorization; the symbolic analysis is
    kept in ``cache`` for the matrices of one pattern); when K is not
    positive definite, by the engine's indefinite solver
    (:func:`~pyevolver.evolve.hessian.solve_bordered`).
    """
    from ..evolve.hessian import _cholmod, solve_bordered
    chol = _cholmod()
    if chol is not None:
        try:
            f = cache.get("factor")
            if f is None:
                f = cache["factor"] = chol.analyze(K, mode="supernodal")
            f.cholesky_inplace(K)
            Z = f(np.column_stack([r, B]))
            mu = np.linalg.solve(B.T @ Z[:, 1:], B.T @ Z[:, 0] - d)
            y = Z[:, 0] - Z[:, 1:] @ mu
            if np.all(np.isfinite(y)):
                return y
        except (chol.CholmodNotPositiveDefiniteError, np.linalg.LinAlgError):
            pass
    return solve_bordered(K, B, r, d)[:K.shape[0]]


def newton_lm(session, tol=1e-9, maxit=80, mu=1e-2, guard=None):
    """Levenberg–Marquardt Newton iteration on all vertex coordinates.

    Each step solves the bordered system of ``min ½ dᵀ(H + μ D) d + ∇Lᵀ d``
    subject to the linearised fixed values (area quantity, body volume) and
    to no rigid motion (translations and rotations, exact null directions of
    the Lagrangian's Hessian ``H`` on a closed surface; the Evolver's
    ``hessian`` with ``hessian_normal`` off does not remove them).  ``D`` is
    the vertex area (a third of the star).  The move restores the fixed
    values as ``g`` does.  It is kept when the energy drops, and μ is then
    scaled by max(1/3, 1 − (2ρ − 1)³), ρ the ratio of the actual to the
    predicted decrease; otherwise μ grows by 2, 4, 8, ... and the step is
    solved again (Nielsen's rule, Madsen, Nielsen & Tingleff 2004,
    *Methods for non-linear least squares problems*, §3.2).  Multipliers
    are the least squares fit of ∇E on the constraint gradients.

    ``guard(surface)`` returning False stops the iteration (used to abandon
    a collapsing mesh early).  Returns ``(converged, steps, max |∇L|)``;
    converged when max |∇L| < ``tol`` with the fixed values met to 1e-10
    relative.
    """
    import scipy.sparse as sp

    from ..evolve import gradient as GR
    from ..evolve.hessian import lagrangian_hessian
    from ..evolve.iterate import _Constraints
    from ..constraints import restore_state, state
    s = session.surface
    it = session.iterator
    cons = _Constraints(s)
    mobile = ~s.vattr["fixed"]
    gnorm = math.inf
    nu = 2.0
    for step in range(maxit):
        t = s.evaluate()
        gE = GR.energy_gradient(t)
        gs = cons.gradients(t)
        C = np.stack([g.ravel() for g in gs], 1)
        lam = np.linalg.lstsq(C, gE.ravel(), rcond=None)[0]
        gL = gE.ravel() - C @ lam
        targets = cons.targets(s)
        resid = targets - cons.values(t)
        gnorm = float(np.abs(gL).max())
        if gnorm < tol and np.all(np.abs(resid) < 1e-10 * np.abs(targets)):
            return True, step, gnorm

        def grad_L(tt, lam=lam):
            g = GR.energy_gradient(tt)
            for lv, gg in zip(lam, cons.gradients(tt)):
                g = g - lv * gg
            return g
        H = lagrangian_hessian(s, cons, lam, grad_L).tocsc()
        mass = sp.diags(np.repeat(np.bincount(s.F.ravel(), weights=np.repeat(t.facet_area, 3),
                                              minlength=s.nv) / 3.0, 3)).tocsc()
        B = np.column_stack([C, _rigid_motions(s.X)])
        d = np.concatenate([resid, np.zeros(6)])
        E0 = t.energy
        X0 = state(s)
        cache = {}
        while True:
            dx = _bordered((H + mu * mass).tocsc(), B, -gL, d, cache)
            pred = -(gL @ dx + 0.5 * dx @ (H @ dx))
            tt = it._move(X0, dx.reshape(-1, 3), 1.0, cons, None, None, mobile, targets,
                          None, trial=True)
            if math.isfinite(tt.energy) and tt.energy <= E0 + 1e-13 * abs(E0):
                rho = (E0 - tt.energy) / pred if pred > 0 else 1.0
                mu = max(mu * max(1 / 3, 1 - (2 * rho - 1) ** 3), 1e-12)
                nu = 2.0
                break
            restore_state(s, X0)
            mu *= nu
            nu *= 2.0
            if mu > 1e12:
                session.recalc()
                return False, step, gnorm
        session.recalc()
        if guard is not None and not guard(s):
            return False, step + 1, gnorm
    return False, maxit, gnorm


def _solve_stage(session, maxit, guard, flips):
    """Minimise at the current λ: :func:`newton_lm`; with ``flips`` > 0,
    then equiangulate (``u`` sweeps until none flips) and solve again, at
    most ``flips`` times, until a solve is followed by no flip.  Returns
    ``(converged, Newton steps, edges flipped)``."""
    ok, steps, _ = newton_lm(session, maxit=maxit, guard=guard)
    flipped = 0
    for _ in range(flips):
        if guard is not None and not guard(session.surface):
            break
        n = 0
        for _ in range(50):
            k = session.equiangulate(echo=False)
            n += k
            if k == 0:
                break
        flipped += n
        if n == 0:
            break
        ok, k, _ = newton_lm(session, maxit=maxit, guard=guard)
        steps += k
    return ok, steps, flipped


def harmonic_continuation(session, lam_min=1e-3, factor=2.0, min_angle_deg=10.0,
                          maxit=80, require_converged=False, flips=0, log=None):
    """Lower λ (the modulus of quantity ``harm``) while the mesh stays healthy.

    At the current λ the surface is minimised by :func:`newton_lm` (at most
    ``maxit`` steps); then λ/``factor`` is tried from there, down to
    ``lam_min``.  A stage is kept while the smallest angle stays at least
    ``min_angle_deg`` (and, with ``require_converged``, Newton met its
    tolerance).  The first stage that fails is undone (the surface and λ of
    the last kept stage come back) and the continuation stops; after
    refining, :func:`run` calls it again from the λ reached.  The failure it
    guards against is abrupt: measured on all three shapes, the smallest
    angle drops from 35–45° to below 10° within one halving of λ while W
    drops sharply, mostly below the smooth minimum (docs/paper.md).

    ``flips`` > 0 lets the triangulation follow the surface: after each
    Newton solve the mesh is equiangulated (``u``) and solved again (see
    :func:`_solve_stage`), so the harmonic energy measures the distortion
    from the equilateral structure of the *current*, Delaunay-like
    triangulation instead of the icosphere's.  ``log`` (a list) receives
    one dict per stage.

    Returns the final λ.
    """
    import copy

    def healthy(surf):
        return min_angle(surf.X, surf.F) >= min_angle_deg

    def harm():
        return session.surface.quantities["harm"]

    def entry(lam, ok, n, nflip, good):
        s = session.surface
        return {"lambda": lam, "converged": ok, "steps": n, "flips": nflip, "kept": good,
                "W": session.totals.quantity_values["willmore"],
                "min_angle_deg": min_angle(s.X, s.F)}
    lam = harm().modulus
    ok, n, nflip = _solve_stage(session, maxit, None, flips)
    good = (ok or not require_converged) and healthy(session.surface)
    if log is not None:
        log.append(entry(lam, ok, n, nflip, good))
    if not good:
        return lam
    while lam / factor >= lam_min * (1 - 1e-12):
        keep = copy.deepcopy(session.surface)
        harm().modulus = lam / factor
        session.recalc()
        ok, n, nflip = _solve_stage(session, maxit, healthy, flips)
        good = (ok or not require_converged) and healthy(session.surface)
        if log is not None:
            log.append(entry(lam / factor, ok, n, nflip, good))
        if not good:
            session._replace_surface(keep)
            harm().modulus = lam
            session.recalc()
            break
        lam = harm().modulus
    return lam


# -- shape descriptors ---------------------------------------------------------------------------

def _line_hits(X, F, o, d):
    """Sorted distinct parameters ``t`` where the line ``o + t d`` meets the
    triangles (Möller–Trumbore, vectorised)."""
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    e1, e2 = b - a, c - a
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-14 * np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1)
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = o - a
    u = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    v = (q @ d) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    eps = 1e-10
    hit = ok & (u >= -eps) & (v >= -eps) & (u + v <= 1 + eps)
    t = np.sort(t[hit])
    if len(t) == 0:
        return t
    keep = np.concatenate([[True], np.diff(t) > 1e-9])
    return t[keep]


def _classify(hw, dlo, dhi):
    """Shape type from height/width and the two pole depths."""
    if max(dlo, dhi) > 0.3 and abs(dhi - dlo) > 0.3:
        return "stomatocyte"
    if hw < 1 and min(dlo, dhi) > 0.02:
        return "discocyte"
    if max(dlo, dhi) <= 0.02:
        if abs(hw - 1) < 0.02:
            return "sphere"
        return "prolate" if hw > 1 else "oblate"
    return "other"


def mesh_descriptors(X, F):
    """Symmetry descriptors of a closed mesh, comparable with
    :func:`reference_descriptors`.

    The symmetry axis is the eigenvector of the surface's second-moment
    tensor (about its area centroid) whose eigenvalue is farthest from the
    other two.  With ``z`` the coordinate along it and ``r`` the distance
    from it:

    ``height_width``
        z-extent / (2 max r): > 1 prolate, < 1 oblate (reference 2.285 at
        v0 = 0.85, 0.274 at 0.62, 0.908 at 0.50).
    ``pole_depth_min``, ``pole_depth_max``
        where the axis pierces the surface (its poles), the depth of each
        pole below the extreme plane on its side, relative to the height,
        the smaller and the larger: both 0 for ellipsoid-like shapes, equal
        and positive for a biconcave discocyte (its dimples), 0 and large
        for a stomatocyte (its invagination).
    ``axis_crossings``
        how many times the axis pierces the surface (2 for all three shapes).
    ``axisym_dev``
        relative difference of the two lateral second moments (0 for a
        surface of revolution).
    ``type``
        sphere / prolate / oblate / discocyte / stomatocyte / other.
    """
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    fa = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    cen = (a + b + c) / 3.0
    g = (fa[:, None] * cen).sum(0) / fa.sum()
    D = cen - g
    M = np.einsum("f,fi,fj->ij", fa, D, D) / fa.sum()
    ev, evec = np.linalg.eigh(M)
    k = 0 if ev[2] - ev[1] < ev[1] - ev[0] else 2
    axis = evec[:, k]
    lat = [i for i in range(3) if i != k]
    Y = X - g
    z = Y @ axis
    r = np.linalg.norm(Y - np.outer(z, axis), axis=1)
    hits = _line_hits(X, F, g, axis)
    zmin, zmax = float(z.min()), float(z.max())
    H = zmax - zmin
    if len(hits):
        dlo, dhi = (hits[0] - zmin) / H, (zmax - hits[-1]) / H
    else:
        dlo = dhi = float("nan")
    hw = H / (2 * r.max())
    return {"type": _classify(hw, dlo, dhi), "height_width": float(hw),
            "pole_depth_min": float(min(dlo, dhi)), "pole_depth_max": float(max(dlo, dhi)),
            "axis_crossings": len(hits),
            "axisym_dev": float(abs(ev[lat[1]] - ev[lat[0]]) / ev[lat[1]])}


def reference_descriptors(res):
    """The same descriptors for an axisymmetric reference profile
    (:class:`~pyevolver.studies.axisymmetric.CanhamResult`), its poles
    at the two ends of the profile."""
    z, r = res.z, res.r
    zmin, zmax = float(z.min()), float(z.max())
    H = zmax - zmin
    lo, hi = sorted([float(z[0]), float(z[-1])])
    hw = H / (2 * r.max())
    dlo, dhi = (lo - zmin) / H, (zmax - hi) / H
    return {"type": _classify(hw, dlo, dhi), "height_width": float(hw),
            "pole_depth_min": float(min(dlo, dhi)), "pole_depth_max": float(max(dlo, dhi)),
            "axis_crossings": 2, "axisym_dev": 0.0}


# -- runs ----------------------------------------------------------------------------------------

_REFERENCES = {}


def reference(shape):
    """The axisymmetric reference (:func:`canham_reference`) of a shape, cached."""
    if shape not in _REFERENCES:
        from .axisymmetric import canham_reference
        v0, branch = SHAPES[shape]
        _REFERENCES[shape] = canham_reference(v0, branch, n=REFERENCE_MODES[shape])
    return _REFERENCES[shape]


def record(shape, label, X, F, W, area, volume, seconds, cpu_seconds, **extra):
    """One result row: energy, error against the reference, mesh health,
    descriptors (see :func:`mesh_descriptors`)."""
    v0 = SHAPES[shape][0]
    ref = reference(shape).W
    row = {"method": label, "shape": shape, "v0": v0, "resolution": len(X),
           "seconds": float(seconds),
           "cpu_seconds": None if cpu_seconds is None else float(cpu_seconds),
           "energy": float(W),
           "reference": float(ref), "rel_error": float((W - ref) / ref),
           "min_angle_deg": min_angle(X, F),
           "area_error": float(area - 4 * np.pi),
           "volume_error": float(volume - v0 * 4 * np.pi / 3)}
    row.update(mesh_descriptors(X, F))
    row.update(extra)
    return row


def _levels(max_nv, first_nv=162):
    """The resolutions of a run: ``(nv, solve)`` from 162 up to ``max_nv``,
    ``solve`` False below ``first_nv`` (those are only refined)."""
    for nv in (max_nv, first_nv):
        if nv not in LEVELS:
            raise ValueError(f"resolution {nv} is not one of {sorted(LEVELS)}")
    return [(nv, nv >= first_nv) for nv in sorted(LEVELS) if nv <= max_nv]


def _recipe_text(directory=PAPER):
    with open(os.path.join(directory, RECIPE)) as fh:
        return fh.read()


#: "normal_u": at most this many equiangulate-and-solve rounds per λ stage
FLIP_ROUNDS = 10

NEWTON_CYCLE = "cycle := { V; u; g 5; hessian_seek; hessian_seek }"


def run(shape, method, max_nv=2562, first_nv=162, directory=PAPER, lam_min=1e-3,
        recipe_vars=None, progress=None):
    """Run one method on one shape coarse to fine up to ``max_nv`` vertices.

    ``method`` is a key of :data:`METHODS`.  Returns ``(session, rows)`` with
    one :func:`record` per resolution (times cumulative from the 162-vertex
    start).  Resolutions below ``first_nv`` are only refined (the run
    starts solving at ``first_nv``).  ``recipe_vars`` overrides variables of
    the recipe (``recipe_g``, ``recipe_tol``, ``recipe_max``).  ``progress(row)``
    is called after each resolution.
    """
    from .. import Session
    if shape not in SHAPES:
        raise ValueError(f"unknown shape {shape!r}; expected one of {', '.join(SHAPES)}")
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; expected one of {', '.join(METHODS)}")
    label = METHODS[method][1]
    s = Session.load(datafile(shape, method, directory), out=io.StringIO(), err=io.StringIO())
    harmonic = method.startswith("normal")
    if not harmonic:
        s.run(_recipe_text(directory))
        for name, value in (recipe_vars or {}).items():
            s.run(f"{name} := {value!r}")
        if method == "perp_newton":
            s.run(NEWTON_CYCLE)
    rows = []
    w0, c0 = time.perf_counter(), time.process_time()
    for k, (nv, solve) in enumerate(_levels(max_nv, first_nv)):
        if k:
            s.refine(echo=False)
        if not solve:
            continue
        extra = {}
        if harmonic:
            log = []
            lam = harmonic_continuation(s, lam_min=lam_min, log=log,
                                        flips=FLIP_ROUNDS if method == "normal_u" else 0)
            kept = [r for r in log if r.get("kept", r["converged"])]
            extra = {"lambda": lam, "newton_steps": sum(r["steps"] for r in log),
                     "flips": sum(r["flips"] for r in log),
                     "converged": bool(kept),
                     "continuation": " ".join(
                         f"{r['lambda']:g}:{r['W']:.5f}/{r['min_angle_deg']:.1f}deg/"
                         f"{r['steps']}{'' if r.get('kept', r['converged']) else 'x'}"
                         + (f"/u{r['flips']}" if r["flips"] else "")
                         for r in log)}
        else:
            s.run("relax")
            extra = {"cycles": int(s.variables["recipe_cycles"])}
        t = s.totals
        row = record(shape, label, s.surface.X, s.surface.F, t.quantity_values["willmore"],
                     t.total_area, t.volumes[0], time.perf_counter() - w0,
                     time.process_time() - c0, **extra)
        rows.append(row)
        if progress is not None:
            progress(row)
    return s, rows


def run_evolver(shape, max_nv=642, first_nv=162, directory=PAPER,
                executable="evolver-nox-d", recipe_vars=None, timeout=3600):
    """The recipe run in the Surface Evolver (``evolver-nox-d``) on the same
    shipped datafile, refined up to ``max_nv`` vertices.  Its mesh after
    each resolution is printed by the script and measured here exactly as
    pyevolver's.  Returns the rows (label "StarPerp+Evolver recipe (REF)"),
    or None when the executable is missing.
    """
    exe = shutil.which(executable)
    if exe is None:
        return None
    levels = _levels(max_nv, first_nv)
    lines = ["printf \"START %.6f\\n\", clock"]
    lines += [f"{name} := {value!r}" for name, value in (recipe_vars or {}).items()]
    for k, (nv, solve) in enumerate(levels):
        if k:
            lines.append("r")
        if not solve:
            continue
        lines += ["relax", "report",
                  ("foreach vertex vv do printf \"VX %d %.17g %.17g %.17g\\n\", "
                   "vv.id, vv.x, vv.y, vv.z"),
                  ("foreach facet ff do printf \"FC %d %d %d\\n\", ff.vertex[1].id, "
                   "ff.vertex[2].id, ff.vertex[3].id"),
                  "printf \"END\\n\""]
    script = "\n".join(lines) + "\nq\nq\n"
    with tempfile.TemporaryDirectory() as tmp:
        fe = shutil.copy(datafile(shape, "perp", directory), tmp)
        cmd = shutil.copy(os.path.join(directory, RECIPE), tmp)
        w0 = time.perf_counter()
        out = subprocess.run([exe, "-p1", "-f", os.path.basename(cmd), os.path.basename(fe)],
                             input=script, capture_output=True, text=True, cwd=tmp,
                             timeout=timeout, check=False).stdout
        wall = time.perf_counter() - w0
    rows = []
    start = None
    V, Fc, rep = {}, [], None
    for line in out.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "START":
            start = float(parts[1])
        elif parts[0] == "FIG4" and len(parts) == 7 and parts[1].isdigit():
            rep = parts
            V, Fc = {}, []
        elif parts[0] == "VX":
            V[int(parts[1])] = [float(x) for x in parts[2:5]]
        elif parts[0] == "FC":
            Fc.append([int(x) for x in parts[1:4]])
        elif parts[0] == "END" and rep is not None:
            ids = sorted(V)
            index = {v: i for i, v in enumerate(ids)}
            X = np.array([V[v] for v in ids])
            F = np.array([[index[v] for v in f] for f in Fc])
            # the Evolver's clock: its elapsed execution time (no processor time)
            elapsed = float(rep[6]) - (start or 0.0)
            rows.append(record(shape, METHODS["perp"][1] + " (REF)", X, F, float(rep[2]),
                               float(rep[3]), float(rep[4]), elapsed, None,
                               cycles=int(rep[5])))
            rep = None
    if len(rows) != sum(solve for _, solve in levels):
        raise RuntimeError(f"{executable} did not complete the recipe on {shape} "
                           f"({len(rows)} of {len(levels)} resolutions)")
    rows[-1]["wall_seconds_total"] = wall
    return rows


# -- the study ------------------------------------------------------------------------------------

CHART_KEYS = ("method", "v0", "resolution", "seconds", "energy", "reference", "rel_error",
              "min_angle_deg")


def chart_records(full: bool = False, max_nv: int | None = None, methods=None,
                  shapes=None) -> list:
    """Rows for the accuracy-versus-time chart: one per method, shape and
    resolution (162, 642, 2,562 vertices; 10,242 too with ``full``; or up
    to ``max_nv``).

    Each dict has ``method`` (a label of :data:`METHODS`), ``v0``,
    ``resolution`` (vertex count), ``seconds`` (wall time, cumulative over
    the coarser resolutions of the run), ``energy`` (W), ``reference``
    (the axisymmetric W), ``rel_error`` ((W − W_ref)/W_ref, signed),
    ``min_angle_deg``, plus the shape and its descriptors.
    """
    if max_nv is None:
        max_nv = 10242 if full else 2562
    rows = []
    for method in (methods or list(METHODS)):
        for shape in (shapes or list(SHAPES)):
            _, r = run(shape, method, max_nv)
            rows.extend(r)
    return rows


def _write_csv(path, rows):
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with open(path, "w") as fh:
        fh.write(",".join(keys) + "\n")
        for r in rows:
            fh.write(",".join("" if r.get(k) is None else str(r.get(k)) for k in keys) + "\n")


def _profile(X, F):
    """(r, z) of the vertices in the symmetry frame of :func:`mesh_descriptors`,
    z centred on the extent and oriented so that the deeper pole is on top."""
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    fa = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    cen = (a + b + c) / 3.0
    g = (fa[:, None] * cen).sum(0) / fa.sum()
    D = cen - g
    ev, evec = np.linalg.eigh(np.einsum("f,fi,fj->ij", fa, D, D))
    axis = evec[:, 0 if ev[2] - ev[1] < ev[1] - ev[0] else 2]
    z = (X - g) @ axis
    r = np.linalg.norm((X - g) - np.outer(z, axis), axis=1)
    hits = _line_hits(X, F, g, axis)
    if len(hits) and (z.max() - hits[-1]) < (hits[0] - z.min()):
        z, hits = -z, -hits[::-1]
    return r, z - 0.5 * (z.max() + z.min())


def plot(path, results):
    """The final meshes' profiles over the references' (one row per shape,
    one column per method) and W's relative error against time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    shapes = [s for s in SHAPES if any(k[0] == s for k in results)]
    labels, timed = [], []
    for (_, label), (mesh, _) in results.items():
        if mesh is not None and label not in labels:
            labels.append(label)
        if label not in timed:
            timed.append(label)
    fig, axes = plt.subplots(len(shapes), len(labels) + 1,
                             figsize=(3.2 * (len(labels) + 1), 3.2 * len(shapes)),
                             squeeze=False)
    for i, shape in enumerate(shapes):
        ref = reference(shape)
        zr = ref.z - 0.5 * (ref.z.max() + ref.z.min())
        lo, hi = sorted([zr[0], zr[-1]])
        if (zr.max() - hi) < (lo - zr.min()):          # deeper pole on top, as _profile
            zr = -zr
        for j, label in enumerate(labels):
            ax = axes[i, j]
            item = results.get((shape, label))
            ax.plot(ref.r, zr, "r-", lw=0.8)
            ax.plot(-ref.r, zr, "r-", lw=0.8)
            if item is not None:
                (X, F), rows = item
                r, z = _profile(X, F)
                ax.plot(np.concatenate([r, -r]), np.concatenate([z, z]), "k.", ms=1)
                last = rows[-1]
                ax.set_title(f"{label}\n{shape} {last['resolution']}: W = {last['energy']:.4f} "
                             f"({100 * last['rel_error']:+.2f}%)", fontsize=7)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
        ax = axes[i, -1]
        for label in timed:
            item = results.get((shape, label))
            if item is None:
                continue
            rows = item[1]
            ax.loglog([r["seconds"] for r in rows], [abs(r["rel_error"]) for r in rows],
                      "o-" if item[0] is not None else "s--", label=label, ms=3)
        ax.axhline(0.01, color="0.6", lw=0.5)
        ax.set_xlabel("seconds", fontsize=7)
        ax.set_ylabel("|W - W_ref| / W_ref", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.set_title(f"{shape}, v0 = {SHAPES[shape][0]}", fontsize=8)
        if i == 0:
            ax.legend(fontsize=5, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m pyevolver.studies.fig4_vesicles",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", choices=["small", "full"], default="small",
                    help="small: up to 642 vertices; full: up to 2,562")
    ap.add_argument("--max-nv", type=int, choices=sorted(LEVELS),
                    help="finest resolution (overrides --size)")
    ap.add_argument("--methods", default=",".join(METHODS),
                    help="comma-separated keys of " + ", ".join(METHODS))
    ap.add_argument("--shapes", default=",".join(SHAPES))
    ap.add_argument("--no-evolver", action="store_true",
                    help="do not run the recipe in evolver-nox-d")
    ap.add_argument("--out", default=".")
    a = ap.parse_args(argv)
    max_nv = a.max_nv or (642 if a.size == "small" else 2562)
    methods = [m for m in a.methods.split(",") if m]
    shapes = [s for s in a.shapes.split(",") if s]
    for m in methods:
        if m not in METHODS:
            ap.error(f"unknown method {m!r}; choose from {', '.join(METHODS)}")
    for s in shapes:
        if s not in SHAPES:
            ap.error(f"unknown shape {s!r}; choose from {', '.join(SHAPES)}")
    os.makedirs(a.out, exist_ok=True)
    rows, results = [], {}

    def show(r):
        print(f"{r['method']:28s} {r['shape']:11s} {r['resolution']:6d}  W = {r['energy']:.6f}"
              f"  ({100 * r['rel_error']:+.3f}%)  {r['type']:11s} h/w {r['height_width']:.3f}"
              f"  poles {r['pole_depth_min']:.3f} {r['pole_depth_max']:.3f}"
              f"  min angle {r['min_angle_deg']:.1f}  {r['seconds']:.1f} s", flush=True)
    for shape in shapes:
        ref = reference(shape)
        d = reference_descriptors(ref)
        row = {"method": "axisymmetric reference", "shape": shape, "v0": SHAPES[shape][0],
               "resolution": ref.n, "energy": ref.W, "reference": ref.W, "rel_error": 0.0}
        row.update(d)
        rows.append(row)
        print(f"{'axisymmetric reference':28s} {shape:11s} n={ref.n:<4d} W = {ref.W:.6f}  "
              f"{d['type']:11s} h/w {d['height_width']:.3f}  poles {d['pole_depth_min']:.3f} "
              f"{d['pole_depth_max']:.3f}", flush=True)
        for m in methods:
            s, r = run(shape, m, max_nv, progress=show)
            rows.extend(r)
            results[(shape, METHODS[m][1])] = ((s.surface.X.copy(), s.surface.F.copy()), r)
        if not a.no_evolver and "perp" in methods:
            r = run_evolver(shape, max_nv)
            if r is None:
                print("evolver-nox-d not found: no reference Evolver run")
            else:
                for x in r:
                    show(x)
                rows.extend(r)
                results[(shape, r[0]["method"])] = (None, r)
    csv = os.path.join(a.out, "fig4_vesicles.csv")
    _write_csv(csv, rows)
    try:
        plot(os.path.join(a.out, "fig4_vesicles.png"), results)
    except ImportError:
        print("matplotlib not installed: no PNG")
        return 0
    print("wrote", csv, "and fig4_vesicles.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
