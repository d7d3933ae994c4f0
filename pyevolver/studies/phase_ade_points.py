"""Discrete area-difference-elasticity points and the ADE table of
docs/phase.md.

:func:`solve_ade_point` minimises the discrete ADE energy of
:func:`pyevolver.studies.phase_ade.ade_header` (plus the phase study's
regularization) on one branch; :func:`table` compares it, and the
SC/BC/ADE relations of :mod:`pyevolver.studies.phase_ade`, with the
axisymmetric reference::

    python -m pyevolver.studies.phase_ade_points [--nv 642] [--out DIR]

writes ``DIR/ade.csv`` and ``DIR/ade.md``.
"""
from __future__ import annotations

import argparse
import csv
import io
import os
import tempfile
import time

import numpy as np

from ..session.core import Session
from .axisymmetric import Helfrich, canham_reference
from .meshes import write_fe
from .phase_ade import (ade_energy_from_bc, bilayer_couple, effective_c0,
                        reduced_area_difference)
from .phase_mesh import revolve
from .phase_newton import restore
from .phase_reference import crossing, follow
from .phase_stability import lowest_eigenvalues, stability
from .phase_study import TYPES, crossing_linear, lam_for, method_for, read_rows
from .vesicle_shapes import mesh_descriptors
from .vesicle_newton import newton_lm


# -- discrete ADE points -------------------------------------------------------------------

def _point_session(X, F, v, lam, directory, c0, mu, method):
    """A point's session: the bending energy with ``h_zero = c0/2``, the
    harmonic regularization ``λE``, ``μ·M`` (an energy quantity ``mcq`` of
    the method ``mean_curvature_integral``, linear in M) and ``M`` itself
    (``mci``, info only); area ``4π`` and volume ``v·4π/3`` fixed."""
    path = os.path.join(directory, "ade_point.fe")
    hdr = "\n".join([
        "// discrete ADE point (pyevolver.studies.phase_ade_points)",
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
    with tempfile.TemporaryDirectory() as tmp:
        s = _point_session(X, F, v, lam, tmp, c0, mu, method)
        restore(s)
        ok, _, _ = newton_lm(s, maxit=maxit)
        q = s.totals.quantity_values
        return ok, s.surface.X.copy(), float(q["willmore"]), float(q["mci"])


def ade_eigenvalues(X, F, v, lam, c0, mu, k, method, count=3):
    """The ``count`` lowest eigenvalues of the constrained, mass-weighted
    Hessian of the discrete ADE energy at the mesh ``(X, F)`` solved with
    the term linearised (``W + μM``, :func:`_point_session`): the phase
    study's (:func:`~pyevolver.studies.phase_stability.lowest_eigenvalues`,
    λE left out) with the ADE term's second derivative ``2k ∇M ∇Mᵀ`` added
    as a rank-one term."""
    with tempfile.TemporaryDirectory() as tmp:
        s = _point_session(X, F, v, lam, tmp, c0, mu, method)
        return lowest_eigenvalues(s, k=count, extra=(("mci", 2.0 * k),))


def solve_ade_point(branch: str, v: float, model: Helfrich, nv: int, ref=None,
                    lam: float | None = None, method: str | None = None,
                    maxit: int = 60, tol: float = 1e-10, outer: int = 20,
                    eigen: bool = True) -> tuple[dict, np.ndarray, np.ndarray]:
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
    ``m = M/4π``, ``c0_eff``, the mesh's shape ``type`` and ``converged``
    (every inner solve converged, ``|μ − 2k(M − M0)|`` below ``tol`` and
    the shape still of its branch), and with ``eigen`` for a converged
    point ``eig1`` and ``stable`` (:func:`ade_eigenvalues`; stable: the
    lowest eigenvalue above −10⁻³, as the phase study marks its points);
    ``X, F`` the final mesh.
    """
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
    kind = mesh_descriptors(X, F, (0.0, 0.0, 1.0))["type"]
    row = {"branch": branch, "v": float(v), "c0": model.c0, "alpha": model.alpha,
           "m0": model.m0, "nv": len(X), "W": E, "W_ref": float(ref.W),
           "rel_err": E / ref.W - 1.0, "m": M / (4 * np.pi),
           "m_ref": float(ref.mean_curvature) / (4 * np.pi), "c0_eff": model.c0 - mu,
           "lambda": lam, "method": method, "type": kind,
           "converged": bool(converged and ok_all and kind in TYPES[branch]),
           "eig1": None, "stable": None}
    if eigen and row["converged"]:
        eig = ade_eigenvalues(X, F, v, lam, model.c0, mu, k, method)
        row.update(eig1=float(eig[0]), stable=stability(eig))
    row["seconds"] = time.perf_counter() - t0
    return row, X, F


# -- the table of docs/phase.md ----------------------------------------------------------------

#: (branch, v, model) of the ADE table
POINTS = [("prolate", 1.0, Helfrich(c0=0.5, alpha=1.4, m0=1.05)),
          ("prolate", 0.85, Helfrich(c0=0.5, alpha=1.4, m0=1.05)),
          ("prolate", 0.85, Helfrich(c0=0.0, alpha=5.0, m0=1.1)),
          ("oblate", 0.65, Helfrich(c0=0.0, alpha=1.4, m0=1.02)),
          ("stomatocyte", 0.55, Helfrich(c0=-0.5, alpha=1.4, m0=1.0))]
ADE_COLUMNS = ["branch", "v", "c0", "alpha", "m0", "E_ref", "m_ref", "c0_eff", "sc_rel_diff",
               "bc_rel_diff", "start", "closed_form_rel_diff", "nv", "E", "m", "rel_err",
               "converged", "method"]


def table(nv: int = 642, points=POINTS, log=print) -> list[dict]:
    """One row per point: the axisymmetric ADE reference ``E_ref`` (and
    ``m_ref``, ``c0_eff``), the relative differences of the two relations
    (``sc_rel_diff``: ``∫H² dA`` of the SC solve at ``c0_eff`` against the
    ADE shape's; ``bc_rel_diff``: :func:`ade_energy_from_bc` of a
    :func:`bilayer_couple` solve against ``E_ref``; both solves started
    from the ``c0 = 0`` shape, ``start = "c0=0"``, or where that reaches
    another critical point from the ADE shape, ``start = "ade"``), the
    sphere's closed form (v = 1), and with ``nv > 0`` the discrete point
    (:func:`solve_ade_point`)."""
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
        start = "c0=0"
        try:
            sc = canham_reference(v, branch, n=n, coef0=plain.coef, model=Helfrich(c0=ce))
            bc, _ = bilayer_couple(v, m, branch, n=n, coef0=plain.coef)
            ok = abs(sc.willmore / ref.willmore - 1) < 1e-6
        except RuntimeError:
            ok = False
        if not ok:
            # from the c0 = 0 shape the solves reach another critical point
            # (the stomatocyte): the relations are then checked from the ADE
            # shape itself (Newton on the SC and BC problems there)
            start = "ade"
            sc = canham_reference(v, branch, n=n, coef0=ref.coef, model=Helfrich(c0=ce))
            bc, _ = bilayer_couple(v, m, branch, n=n, c0=ce, coef0=ref.coef)
        row["start"] = start
        row.update(E_ref=ref.W, m_ref=m, c0_eff=ce,
                   sc_rel_diff=sc.willmore / ref.willmore - 1.0,
                   bc_rel_diff=ade_energy_from_bc(bc.willmore, m, model) / ref.W - 1.0)
        if nv and v < 1.0:
            d, _, _ = solve_ade_point(branch, v, model, nv, ref=ref, eigen=False)
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
           "BC + terms | solves from | closed form | vertices | E/4π | rel. error |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        conv = r.get("converged")
        err = ("not converged" if conv is False else f(r.get("rel_err"), "+.3%"))
        out.append(
            f"| {r['branch']} | {r['v']:.3f} | {r['c0']:g} | {r['alpha']:g} | {r['m0']:g} | "
            f"{r['E_ref'] / (4 * np.pi):.6f} | {r['m_ref']:.6f} | {r['c0_eff']:.5f} | "
            f"{f(r['sc_rel_diff'], '.1e')} | {f(r['bc_rel_diff'], '.1e')} | {r['start']} | "
            f"{f(r.get('closed_form_rel_diff'), '.1e')} | {f(r.get('nv'), 'd')} | "
            f"{f(r['E'] / (4 * np.pi) if r.get('E') is not None else None, '.5f')} | {err} |")
    return "\n".join(out) + "\n"


def read_table(path: str) -> list[dict]:
    """The rows of an ``ade.csv`` (:func:`~.phase_study.read_rows`, with
    empty cells left out and ``nv`` an integer), for :func:`markdown`."""
    return [{k: int(val) if k == "nv" else val for k, val in r.items() if val != ""}
            for r in read_rows(path)]


SWEEP_COLUMNS = ["branch", "v", "c0", "alpha", "m0", "nv", "W", "W_ref", "rel_err", "m",
                 "m_ref", "c0_eff", "lambda", "method", "type", "converged", "eig1", "stable",
                 "seconds"]


def sweep(volumes, model: Helfrich, nv: int, branches=("prolate", "oblate", "stomatocyte"),
          out: str | None = None, log=print) -> tuple[list[dict], list[dict]]:
    """The ADE branches on ``volumes``: the axisymmetric ADE reference
    followed along each branch (:func:`~pyevolver.studies.phase_reference.follow`),
    each point solved by :func:`solve_ade_point` from its reference; the
    crossings of the discrete branches (converged points, linear
    interpolation) and of the reference's (Brent's method); each converged
    point marked stable or not (:func:`ade_eigenvalues`, with the ADE
    Hessian's rank-one term ``2k ∇M ∇Mᵀ``).  With ``out``, writes
    ``out/ade_phase.csv`` and ``out/ade_transitions.csv``.  Returns
    ``(rows, transitions)``."""
    refs = {b: {p.v: p for p in follow(b, volumes, model)} for b in branches}
    rows = []
    for b in branches:
        for v, p in sorted(refs[b].items()):
            row, _, _ = solve_ade_point(b, v, model, nv, ref=p.result)
            rows.append(row)
            log(f"{b} v={v:.4f} E={row['W']:.6f} rel_err={row['rel_err']:+.5f} "
                f"m={row['m']:.5f} converged={row['converged']} {row['seconds']:.1f}s")
    trans = []
    for fa, fb in (("prolate", "oblate"), ("oblate", "stomatocyte")):
        if fa not in branches or fb not in branches:
            continue
        pa = [(r["v"], r["W"]) for r in rows if r["branch"] == fa and r["converged"]]
        pb = [(r["v"], r["W"]) for r in rows if r["branch"] == fb and r["converged"]]
        vref = crossing(list(refs[fa].values()), list(refs[fb].values()), model)
        trans.append({"c0": model.c0, "alpha": model.alpha, "m0": model.m0, "from": fa,
                      "to": fb, "v": crossing_linear(pa, pb), "v_ref": vref})
    if out is not None:
        os.makedirs(out, exist_ok=True)
        for name, cols, data in (("ade_phase.csv", SWEEP_COLUMNS, rows),
                                 ("ade_transitions.csv", list(trans[0]) if trans else [],
                                  trans)):
            with open(os.path.join(out, name), "w", newline="") as fh:
                w = csv.DictWriter(fh, fieldnames=cols, extrasaction="ignore")
                w.writeheader()
                for r in data:
                    w.writerow({k: ("" if r.get(k) is None else
                                    (f"{r[k]:.10g}" if isinstance(r[k], float) else r[k]))
                                for k in cols})
    return rows, trans


def _mark(stable) -> str:
    return {True: "yes", False: "no (saddle)"}.get(stable, "—")


def sweep_markdown(rows: list[dict], trans: list[dict]) -> str:
    """The tables of an ADE sweep (rows and transitions as :func:`read_table`
    reads ``ade_phase.csv`` and ``ade_transitions.csv``), energies as E/4π."""
    def f(x, spec):
        return "—" if x is None or x == "" else format(x, spec)
    out = ["| transition | discrete | axisymmetric reference |", "|---|---|---|"]
    for tr in trans:
        out.append(f"| {tr['from']}/{tr['to']} | {f(tr.get('v'), '.4f')} | "
                   f"{f(tr.get('v_ref'), '.4f')} |")
    out += ["", "| branch | v | vertices | E/4π | E_ref/4π | rel. error | Δa | Δa_ref | "
            "c0_eff | shape | lowest eigenvalue | stable |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    order = ["prolate", "oblate", "stomatocyte"]
    for r in sorted(rows, key=lambda r: (order.index(r["branch"]), r["v"])):
        err = f"{r['rel_err']:+.3%}" if r.get("converged") is True else "not converged"
        out.append(f"| {r['branch']} | {r['v']:.3f} | {r['nv']} | "
                   f"{r['W'] / (4 * np.pi):.5f} | {r['W_ref'] / (4 * np.pi):.5f} | {err} | "
                   f"{r['m']:.5f} | {r['m_ref']:.5f} | {r['c0_eff']:.4f} | {r.get('type', '—')} | "
                   f"{f(r.get('eig1'), '.4g')} | {_mark(r.get('stable'))} |")
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    """``python -m pyevolver.studies.phase_ade_points [--nv 642] [--out DIR]``:
    writes ``DIR/ade.csv`` and ``DIR/ade.md`` (the table of docs/phase.md);
    with ``--sweep --alpha A --m0 M [--c0 C] [--volumes v1,v2,...]
    [--branches ...]`` the ADE branches instead (:func:`sweep`)."""
    p = argparse.ArgumentParser(prog="python -m pyevolver.studies.phase_ade_points",
                                description="ADE reference relations and discrete points")
    p.add_argument("--nv", type=int, default=642, help="vertices of the discrete points "
                   "(0: the axisymmetric reference only)")
    p.add_argument("--out", default=".")
    p.add_argument("--sweep", action="store_true", help="sweep the ADE branches")
    p.add_argument("--c0", type=float, default=0.0)
    p.add_argument("--alpha", type=float, default=1.4)
    p.add_argument("--m0", type=float, default=1.0)
    p.add_argument("--volumes", default="0.55,0.6,0.65,0.7,0.75,0.8,0.85,0.9")
    p.add_argument("--branches", default="prolate,oblate,stomatocyte")
    args = p.parse_args(argv)
    if args.sweep:
        _, trans = sweep([float(x) for x in args.volumes.split(",")],
                         Helfrich(args.c0, args.alpha, args.m0), args.nv,
                         tuple(args.branches.split(",")), args.out,
                         log=lambda t: print(t, flush=True))
        for tr in trans:
            print(f"transition {tr['from']}/{tr['to']}: v = {tr['v']} (reference {tr['v_ref']})")
        return 0
    rows = table(args.nv, log=lambda t: print(t, flush=True))
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "ade.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=ADE_COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{r[k]:.10g}" if isinstance(r.get(k), float) else r.get(k, ""))
                        for k in ADE_COLUMNS})
    with open(os.path.join(args.out, "ade.md"), "w") as fh:
        fh.write(markdown(read_table(os.path.join(args.out, "ade.csv"))))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
