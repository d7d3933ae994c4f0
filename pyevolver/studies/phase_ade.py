"""Spontaneous curvature and area-difference elasticity (ADE): the datafile
form of the energy and the relations between the three vesicle models.

The energy (Miao, Seifert, Wortis & Döbereiner 1994, *Budding transitions
of fluid-bilayer vesicles: the effect of area-difference elasticity*,
Phys. Rev. E 49, 5389, Eq. (2.1))

    F = (κ/2) ∮ (C1 + C2 − C0)² dA + (κ̄ π / (2 A D²)) (ΔA − ΔA0)²,

with the bilayer area difference ``ΔA = D ∮ (C1 + C2) dA = 2 D M``
(``M = ∫ H dA``, ``H = (C1 + C2)/2``), is in the units of this package
(``A = 4π R0²``, ``R0 = 1``; energies divided by ``2κ``; a sphere has
``∫H² dA = 4π``)

    E = ∫ (H − c0/2)² dA + (π α / A) (M − 4π m0)²,   F/(8πκ) = E/(4π),

``c0 = C0 R0``, ``α = κ̄/κ`` and ``m0 = ΔA0 / (8π D R0)`` the reduced
preferred area difference (1 for the sphere).  It is the model of
:class:`pyevolver.studies.axisymmetric.Helfrich`.

The spontaneous-curvature (SC), bilayer-couple (BC) and ADE models are
related by Legendre-type transforms (Miao et al. 1994, Sec. II; Seifert
1997, *Configurations of fluid membranes and vesicles*, Adv. Phys. 46, 13,
Sec. 4): with ``W_BC(v, m)`` the critical values of ``∫H² dA`` at fixed
area, reduced volume ``v`` and ``M = 4π m``,

* SC: ``E_SC = ∫H² dA − c0 M + π c0²``; its critical points are BC critical
  points, ``c0`` being the multiplier of ``M``: ``∂W_BC/∂M = c0``;
* ADE: ``E_ADE(v) = W_BC(v, m) − 4π c0 m + π c0² + 4π² α (m − m0)²``
  at the ``m`` where this is stationary; the ADE shape is the SC shape of
  the effective spontaneous curvature ``c0_eff = c0 − 2π α (m − m0)``
  (the derivative of the penalty with respect to M, moved into the SC
  term).  ``α → ∞`` gives the BC model at ``m = m0``, ``α = 0`` the SC model.

These are derived here from the energies above (the signs and factors are
those of our normalization); :func:`bilayer_couple` computes BC points by
solving the SC problem for the ``c0`` whose shape has ``M = 4π m``.

In a datafile (:func:`ade_header`) the ADE term is a FUNCTION quantity of a
``mean_curvature_integral`` method instance, the spontaneous curvature the
Evolver's ``h_zero`` (a mean curvature: ``h_zero = c0/2``); evolver-nox-d
2.70 and pyevolver print the same numbers for it (tests/methods/test_ade.py).
"""
from __future__ import annotations

import io
import os
import tempfile
import time

import numpy as np

from .axisymmetric import CanhamResult, Helfrich, canham_reference

#: the squared mean curvature methods of the phase study that honour h_zero
HZERO_METHODS = ("normal_sq_mean_curvature", "star_perp_sq_mean_curvature",
                 "star_normal_sq_mean_curvature")


def ade_header(c0: float = 0.0, alpha: float = 0.0, m0: float = 1.0, area: float = 4 * np.pi,
               method: str = "star_perp_sq_mean_curvature", bend: str = "willmore") -> str:
    """Datafile top section of the Helfrich/ADE energy in units of ``2κ``.

    ``∫(H − h_zero)² dA`` by ``method`` (a quantity named ``bend``) with
    ``h_zero = c0/2``, and for ``alpha > 0`` the ADE term
    ``(π α / area) (M − 4π m0 √(area/4π))²`` as the FUNCTION quantity ``ade``
    of the method instance ``mci`` (``mean_curvature_integral``, the exact
    ``Σ_e ½ L_e θ_e`` of a polyhedron).  ``area`` is the vesicle's (fixed)
    area, so that ``m0`` is reduced by ``R0 = √(area/4π)``.
    """
    if method not in HZERO_METHODS:
        raise ValueError(f"{method} does not take a spontaneous curvature (h_zero); "
                         f"one of {HZERO_METHODS}")
    lines = [f"parameter c0 = {c0!r}   // reduced spontaneous curvature C0*R0",
             "parameter h_zero = c0/2   // the Evolver's h_zero is a mean curvature",
             f"quantity {bend} energy method {method} global"]
    if alpha:
        r0 = float(np.sqrt(area / (4 * np.pi)))
        # (pyevolver's FUNCTION quantities take parameters and instance
        # values only, so the constants are parameters computed here)
        lines += [f"parameter alpha = {alpha!r}   // kappa_bar/kappa",
                  f"parameter m0 = {m0!r}   // reduced preferred area difference",
                  f"parameter ade_k = {np.pi * alpha / area!r}   // pi*alpha/A",
                  f"parameter ade_m0 = {4 * np.pi * m0 * r0!r}   // 4*pi*m0*R0",
                  "method_instance mci method mean_curvature_integral global",
                  "quantity ade energy function ade_k*(mci.value - ade_m0)^2"]
    return "\n".join(lines) + "\n"


# -- the axisymmetric models and their relations --------------------------------------------

def reduced_area_difference(res: CanhamResult) -> float:
    """``Δa = M / (4π R0)`` of a reference shape (area ``4π``: ``R0 = 1``);
    1 for the sphere (Seifert, Berndl & Lipowsky 1991, Eq. (2.6))."""
    return res.mean_curvature / (4 * np.pi)


def effective_c0(model: Helfrich, m: float) -> float:
    """``c0_eff = c0 − 2π α (m − m0)``: the spontaneous curvature whose SC
    problem has the ADE shape of reduced area difference ``m`` as a critical
    point (the ADE term's derivative ``2πα/A (M − 4π m0)`` with respect to
    ``M``, at ``A = 4π``, joins the SC term's ``−c0``)."""
    return model.c0 - 2 * np.pi * model.alpha * (m - model.m0)


def ade_energy_from_bc(w_bc: float, m: float, model: Helfrich) -> float:
    """``E_ADE = W_BC − 4π c0 m + π c0² + 4π² α (m − m0)²`` (area ``4π``),
    the ADE energy of the BC critical point of ``∫H² dA = w_bc`` at
    ``M = 4π m``."""
    return (w_bc - 4 * np.pi * model.c0 * m + np.pi * model.c0 ** 2
            + 4 * np.pi ** 2 * model.alpha * (m - model.m0) ** 2)


def bilayer_couple(v0: float, m: float, branch: str, n: int = 32, c0: float = 0.0,
                   coef0: np.ndarray | None = None, tol: float = 1e-12, maxit: int = 60,
                   max_step: float = 0.5) -> tuple[CanhamResult, float]:
    """The bilayer-couple critical point of ``∫H² dA`` at area ``4π``,
    reduced volume ``v0`` and ``M = ∫H dA = 4π m`` on ``branch``.

    It is the spontaneous-curvature critical point whose ``c0`` (the
    multiplier of ``M``, SBL 1991 Sec. II) gives ``M = 4π m``: the secant
    method on ``c0`` from ``c0`` (steps at most ``max_step``, halved while
    the SC solve fails), each SC problem solved by :func:`canham_reference`
    from the previous shape (``coef0`` first).  ``M`` changes slowly with
    ``c0`` (``∂²W_BC/∂M²`` is large), hence the step limit.

    Returns
    -------
    (result, c0)
        The SC result at the final ``c0`` (``result.willmore`` is ``W_BC``)
        and ``c0 = ∂W_BC/∂M``.
    """
    def solve(c, a0):
        with np.errstate(invalid="ignore", over="ignore"):
            return canham_reference(v0, branch, n=n, coef0=a0, model=Helfrich(c0=c))
    target = 4 * np.pi * m
    r1 = solve(c0, coef0)
    f1 = r1.mean_curvature - target
    c_prev, f_prev = None, None
    for _ in range(maxit):
        if abs(f1) < tol * target:
            return r1, c0
        if c_prev is None or f1 == f_prev:
            step = -np.sign(f1) * 0.05
        else:
            step = -f1 * (c0 - c_prev) / (f1 - f_prev)
        step = float(np.clip(step, -max_step, max_step))
        for _ in range(8):
            try:
                r2 = solve(c0 + step, r1.coef)
                break
            except (RuntimeError, np.linalg.LinAlgError):
                step *= 0.5
        else:
            break
        c_prev, f_prev = c0, f1
        c0, r1 = c0 + step, r2
        f1 = r1.mean_curvature - target
    raise RuntimeError(f"bilayer couple at v0={v0}, m={m}: M off by {f1:.2e}")


# -- discrete ADE points -------------------------------------------------------------------

def _point_session(X, F, v, lam, directory, c0, mu, method):
    """A point's session: the bending energy with ``h_zero = c0/2``, the
    harmonic regularization ``λE``, ``μ·M`` (an energy quantity ``mcq`` of
    the method ``mean_curvature_integral``, linear in M) and ``M`` itself
    (``mci``, info only); area ``4π`` and volume ``v·4π/3`` fixed."""
    from ..session.core import Session
    from .meshes import write_fe
    path = os.path.join(directory, "ade_point.fe")
    hdr = "\n".join([
        "// discrete ADE point (pyevolver.studies.phase_ade)",
        f"parameter v0 = {float(v)!r}",
        f"parameter c0 = {float(c0)!r}",
        "parameter h_zero = c0/2",
        f"quantity willmore energy method {method} global",
        "quantity surf fixed = 4*pi method facet_area global",
        f"quantity harm energy modulus {float(lam)!r} method harmonic_energy global",
        f"quantity mcq energy modulus {float(mu)!r} method mean_curvature_integral global",
        "quantity mci info_only method mean_curvature_integral global"])
    write_fe(path, X, F, header=hdr, face_attrs="tension 0")
    with open(path, "a") as fh:
        fh.write("\nbodies\n1 " + " ".join(str(i + 1) for i in range(len(F)))
                 + " volume v0*4*pi/3\n")
    return Session.load(path, out=io.StringIO(), err=io.StringIO())


def _linear_solve(X, F, v, lam, c0, mu, method, maxit):
    """Minimise ``W + λE + μM`` from the mesh ``(X, F)``: ``(converged, X,
    W, M)``."""
    from .phase_newton import restore
    from .vesicle_newton import newton_lm
    with tempfile.TemporaryDirectory() as tmp:
        s = _point_session(X, F, v, lam, tmp, c0, mu, method)
        restore(s)
        ok, _, _ = newton_lm(s, maxit=maxit)
        q = s.totals.quantity_values
        return ok, s.surface.X.copy(), float(q["willmore"]), float(q["mci"])


def solve_ade_point(branch: str, v: float, model: Helfrich, nv: int, ref=None,
                    lam: float | None = None, method: str | None = None,
                    maxit: int = 60, tol: float = 1e-10, outer: int = 20
                    ) -> tuple[dict, np.ndarray, np.ndarray]:
    """The discrete ADE minimiser on ``branch`` at reduced volume ``v``.

    The discrete ADE energy is ``W + k (M − M0)²`` (``k = πα/A``,
    ``A = 4π``, ``M0 = 4π m0``; W with ``h_zero = c0/2``; ``M`` the exact
    ``∫H dA`` of the polyhedron, ``mean_curvature_integral``), the energy of
    :func:`ade_header`, with the study's regularization ``λE`` added.  Its
    critical points are those of ``W + λE + μM`` with ``μ = 2k(M − M0)``
    (the ADE term linearised at its own ``M``: the effective spontaneous
    curvature of the smooth theory, ``c0_eff = c0 − μ``).  Each inner
    problem, μ fixed, is a spontaneous-curvature problem, minimised by
    the phase study's damped Newton (a linear term in the well-conditioned
    variable: ``M`` hardly moves with μ on the prolate branch, where fixing
    ``M`` instead — the bilayer couple — is very stiff); the outer
    iteration solves ``μ = 2k(M(μ) − M0)`` by the secant method.  Every
    solve starts from the previous mesh, the first from the axisymmetric
    ADE reference ``ref`` revolved into about ``nv`` vertices
    (:func:`~pyevolver.studies.phase_mesh.revolve`); λ(h) is the study's
    (:func:`~pyevolver.studies.phase_study.lam_for`), and so is the
    default ``method`` (:func:`~pyevolver.studies.phase_study.method_for`).

    Returns ``(row, X, F)``: the row has ``W`` (the discrete ADE energy,
    without λE), ``W_ref``, ``rel_err``, the discrete and the reference
    ``m = M/4π``, ``c0_eff`` and ``converged`` (every inner solve converged
    and ``|μ − 2k(M − M0)|`` below ``tol``); ``X, F`` the final mesh.
    """
    from .phase_mesh import revolve
    from .phase_reference import follow
    from .phase_study import lam_for, method_for
    t0 = time.perf_counter()
    method = method_for(model.c0, method)
    if ref is None:
        ref = follow(branch, [v], model)[0].result
    lam = lam_for(nv) if lam is None else lam
    X, F = revolve(ref.s, ref.r, ref.z, nv, area=4 * np.pi)
    k = np.pi * model.alpha / (4 * np.pi)
    M0 = 4 * np.pi * model.m0
    ok_all = True

    def f(mu, X):
        ok, X1, W, M = _linear_solve(X, F, v, lam, model.c0, mu, method, maxit)
        return ok, X1, W, M, mu - 2 * k * (M - M0)
    mu_a = 2 * k * (float(ref.mean_curvature) - M0)
    ok, X, W, M, fa = f(mu_a, X)
    ok_all &= ok
    mu_b = mu_a - fa                                  # one fixed-point step first
    converged = abs(fa) < tol
    mu = mu_a
    for _ in range(outer):
        if converged:
            break
        ok, X, W, M, fb = f(mu_b, X)
        ok_all &= ok
        mu = mu_b
        if abs(fb) < tol or fb == fa:
            converged = abs(fb) < tol
            break
        mu_a, fa, mu_b = mu_b, fb, mu_b - fb * (mu_b - mu_a) / (fb - fa)
    E = W + k * (M - M0) ** 2
    row = {"branch": branch, "v": float(v), "c0": model.c0, "alpha": model.alpha,
           "m0": model.m0, "nv": len(X), "W": E, "W_ref": float(ref.W),
           "rel_err": E / ref.W - 1.0, "m": M / (4 * np.pi),
           "m_ref": float(ref.mean_curvature) / (4 * np.pi), "c0_eff": model.c0 - mu,
           "lambda": lam, "method": method, "converged": bool(converged and ok_all),
           "seconds": time.perf_counter() - t0}
    return row, X, F


# -- the table of docs/phase.md ----------------------------------------------------------------

#: (branch, v, model) of the ADE table
POINTS = [("prolate", 1.0, Helfrich(c0=0.5, alpha=1.4, m0=1.05)),
          ("prolate", 0.85, Helfrich(c0=0.5, alpha=1.4, m0=1.05)),
          ("prolate", 0.85, Helfrich(c0=0.0, alpha=5.0, m0=1.1)),
          ("oblate", 0.65, Helfrich(c0=0.0, alpha=1.4, m0=1.02)),
          ("stomatocyte", 0.55, Helfrich(c0=-0.5, alpha=1.4, m0=1.0))]
ADE_COLUMNS = ["branch", "v", "c0", "alpha", "m0", "E_ref", "m_ref", "c0_eff", "sc_rel_diff",
               "bc_rel_diff", "bc_start", "closed_form_rel_diff", "nv", "E", "m", "rel_err",
               "converged", "method"]


def table(nv: int = 642, points=POINTS, log=print) -> list[dict]:
    """One row per point: the axisymmetric ADE reference ``E_ref`` (and
    ``m_ref``, ``c0_eff``), the relative differences of the two relations
    (``sc_rel_diff``: ``∫H² dA`` of the SC solve at ``c0_eff`` started from
    the ``c0 = 0`` shape against the ADE shape's; ``bc_rel_diff``:
    :func:`ade_energy_from_bc` of a :func:`bilayer_couple` solve against
    ``E_ref``), the sphere's closed form (v = 1), and with ``nv > 0`` the
    discrete point (:func:`solve_ade_point`)."""
    from .phase_reference import follow
    rows = []
    for branch, v, model in points:
        row = {"branch": branch, "v": v, "c0": model.c0, "alpha": model.alpha, "m0": model.m0}
        if v == 1.0:
            ref = canham_reference(1.0, branch, n=8, model=model)
            exact = (4 * np.pi * (1 - model.c0 / 2) ** 2
                     + 4 * np.pi ** 2 * model.alpha * (1 - model.m0) ** 2)
            row["closed_form_rel_diff"] = ref.W / exact - 1.0
            plain = canham_reference(1.0, branch, n=8)
        else:
            ref = follow(branch, [v], model)[0].result
            plain = follow(branch, [v])[0].result
        m = reduced_area_difference(ref)
        ce = effective_c0(model, m)
        n = ref.n
        sc = canham_reference(v, branch, n=n, coef0=plain.coef, model=Helfrich(c0=ce))
        try:
            bc, _ = bilayer_couple(v, m, branch, n=n, coef0=plain.coef)
        except RuntimeError:        # the secant from c0 = 0 left the branch: from c0_eff
            bc, _ = bilayer_couple(v, m, branch, n=n, c0=ce, coef0=plain.coef)
            row["bc_start"] = "c0_eff"
        row.update(E_ref=ref.W, m_ref=m, c0_eff=ce,
                   sc_rel_diff=sc.willmore / ref.willmore - 1.0,
                   bc_rel_diff=ade_energy_from_bc(bc.willmore, m, model) / ref.W - 1.0)
        if nv and v < 1.0:
            d, _, _ = solve_ade_point(branch, v, model, nv, ref=ref)
            row.update(nv=d["nv"], E=d["W"], m=d["m"], rel_err=d["rel_err"],
                       converged=d["converged"], method=d["method"])
        log(", ".join(f"{k}={row[k]:.6g}" if isinstance(row[k], float) else f"{k}={row[k]}"
                      for k in row))
        rows.append(row)
    return rows


def markdown(rows: list[dict]) -> str:
    """The table of docs/phase.md (energies as ``E/4π``)."""
    def f(x, spec):
        return "—" if x is None or x == "" else format(x, spec)
    out = ["| branch | v | c0 | α | m0 | E_ref/4π | Δa = m_ref | c0_eff | SC at c0_eff | "
           "BC + terms | closed form | vertices | E/4π | rel. error |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        conv = r.get("converged")
        err = ("not converged" if conv is False else f(r.get("rel_err"), "+.3%"))
        out.append(
            f"| {r['branch']} | {r['v']:.3f} | {r['c0']:g} | {r['alpha']:g} | {r['m0']:g} | "
            f"{r['E_ref'] / (4 * np.pi):.6f} | {r['m_ref']:.6f} | {r['c0_eff']:.5f} | "
            f"{f(r['sc_rel_diff'], '.1e')} | {f(r['bc_rel_diff'], '.1e')} | "
            f"{f(r.get('closed_form_rel_diff'), '.1e')} | {f(r.get('nv'), 'd')} | "
            f"{f(r['E'] / (4 * np.pi) if r.get('E') is not None else None, '.5f')} | {err} |")
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    """``python -m pyevolver.studies.phase_ade [--nv 642] [--out DIR]``:
    writes ``DIR/ade.csv`` and ``DIR/ade.md`` (the table of docs/phase.md)."""
    import argparse
    import csv
    p = argparse.ArgumentParser(prog="python -m pyevolver.studies.phase_ade",
                                description="ADE reference relations and discrete points")
    p.add_argument("--nv", type=int, default=642, help="vertices of the discrete points "
                   "(0: the axisymmetric reference only)")
    p.add_argument("--out", default=".")
    args = p.parse_args(argv)
    rows = table(args.nv, log=lambda t: print(t, flush=True))
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "ade.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=ADE_COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{r[k]:.10g}" if isinstance(r.get(k), float) else r.get(k, ""))
                        for k in ADE_COLUMNS})
    with open(os.path.join(args.out, "ade.md"), "w") as fh:
        fh.write(markdown(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
