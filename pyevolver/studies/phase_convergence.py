"""Convergence order of the discrete bending energy (issue 27, item 4).

For a shape with a known smooth energy, the discrete minimiser of
``W + λE`` (:mod:`~pyevolver.studies.phase_study`'s energy and solver) on
revolved meshes of decreasing edge length ``h``; the error ``W − W_smooth``
is fitted as ``C h^p``.  Two discretizations per shape: with the paper's
regularization at λ(h) = 0.3 · 642/nv (∝ h², the study's rule) and without
(λ = 0: the damped Newton iteration from the revolved start, which is
then free to move vertices tangentially).  Shapes: the unit sphere (area
fixed only; W = 4π) and the v = 0.85 prolate (area and volume fixed; the
axisymmetric reference).  The Clifford torus is not included.

    python -m pyevolver.studies.phase_convergence [--nv 160,320,640] [--out DIR]

writes ``convergence.csv`` and ``convergence.png``/``.pdf`` (log-log error
against h, fitted orders in the legend).
"""
from __future__ import annotations

import argparse
import csv
import io
import math
import os
import tempfile

import numpy as np

from ..session.core import Session
from .axisymmetric import canham_reference
from .meshes import write_fe
from .phase_mesh import mesh_quality, revolve
from .phase_study import lam_for
from .vesicle_newton import newton_lm

SHAPES = ("sphere", "prolate")


def _session(X, F, lam, v, directory):
    lines = ["quantity willmore energy method normal_sq_mean_curvature global",
             "quantity surf fixed = 4*pi method facet_area global"]
    if lam > 0:
        lines.append(f"quantity harm energy modulus {lam!r} method harmonic_energy global")
    path = os.path.join(directory, "c.fe")
    write_fe(path, X, F, header="\n".join(lines), face_attrs="tension 0")
    if v is not None:
        with open(path, "a") as fh:
            fh.write("\nbodies\n1 " + " ".join(str(i + 1) for i in range(len(F)))
                     + f" volume {v * 4 * math.pi / 3!r}\n")
    return Session.load(path, out=io.StringIO(), err=io.StringIO())


def point(shape: str, nv: int, regularized: bool, maxit: int = 60) -> dict:
    """One discrete minimiser: ``{shape, nv, h, lambda, W, W_smooth, error,
    converged, min_angle_deg}``."""
    if shape == "sphere":
        t = np.linspace(0, np.pi, 1601)
        s, r, z, v, Ws = t, np.sin(t), -np.cos(t), None, 4 * math.pi
    elif shape == "prolate":
        ref = canham_reference(0.85, "prolate", n=32)
        s, r, z, v, Ws = ref.s, ref.r, ref.z, 0.85, ref.W
    else:
        raise ValueError(f"unknown shape {shape!r}; expected one of {SHAPES}")
    X, F = revolve(s, r, z, nv, area=4 * math.pi)
    lam = lam_for(nv) if regularized else 0.0
    with tempfile.TemporaryDirectory() as tmp:
        sess = _session(X, F, lam, v, tmp)
        ok, _, _ = newton_lm(sess, maxit=maxit)
        W = float(sess.totals.quantity_values["willmore"])
        q = mesh_quality(sess.surface.X, sess.surface.F)
    return {"shape": shape, "nv": len(X), "h": q["h"], "lambda": lam, "W": W, "W_smooth": Ws,
            "error": W - Ws, "converged": bool(ok), "min_angle_deg": q["min_angle_deg"]}


def fit_order(h, err) -> tuple[float, float]:
    """``(p, C)`` of the least squares fit ``log|err| = log C + p log h``."""
    p, logc = np.polyfit(np.log(np.asarray(h)), np.log(np.abs(np.asarray(err))), 1)
    return float(p), float(math.exp(logc))


def study(sizes=(160, 320, 640), shapes=SHAPES) -> tuple[list[dict], list[dict]]:
    """All points and the fitted orders ``{shape, regularized, order, C}``
    (fitted on the converged points, at least two)."""
    rows, fits = [], []
    for shape in shapes:
        for reg in (True, False):
            pts = [dict(point(shape, nv, reg), regularized=reg) for nv in sizes]
            rows += pts
            ok = [p for p in pts if p["converged"] and p["error"] != 0]
            if len(ok) >= 2:
                p, C = fit_order([q["h"] for q in ok], [q["error"] for q in ok])
                fits.append({"shape": shape, "regularized": reg, "order": p, "C": C,
                             "sign": int(np.sign(ok[-1]["error"]))})
    return rows, fits


def plot(stem: str, rows: list[dict], fits: list[dict]) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for f in fits:
        pts = [r for r in rows if r["shape"] == f["shape"] and r["regularized"] == f["regularized"]
               and r["converged"]]
        lab = (f"{f['shape']}, {'λ(h) ∝ h²' if f['regularized'] else 'λ = 0'}: "
               f"order {f['order']:.2f}")
        ax.loglog([r["h"] for r in pts], [abs(r["error"]) / r["W_smooth"] for r in pts],
                  "o-" if f["regularized"] else "s--", label=lab)
    ax.set_xlabel("mean edge length h")
    ax.set_ylabel("|W − W_smooth| / W_smooth")
    ax.legend(fontsize=8)
    fig.tight_layout()
    for ext in ("png", "pdf"):
        fig.savefig(f"{stem}.{ext}", dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    p = argparse.ArgumentParser(prog="python -m pyevolver.studies.phase_convergence",
                                description=__doc__.split("\n")[0])
    p.add_argument("--nv", default="160,320,640")
    p.add_argument("--out", default=".")
    args = p.parse_args(argv)
    rows, fits = study(tuple(int(x) for x in args.nv.split(",")))
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "convergence.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    plot(os.path.join(args.out, "convergence"), rows, fits)
    for f in fits:
        print(f"{f['shape']} regularized={f['regularized']}: order {f['order']:.3f} "
              f"(C = {f['C']:.3g}, error sign {f['sign']:+d})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
