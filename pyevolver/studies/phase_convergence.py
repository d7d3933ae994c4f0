"""Convergence order of the discrete bending energy (issue 27, item 4).

For a shape with a known smooth energy, the discrete minimiser of
``W + λE`` (:mod:`~pyevolver.studies.phase_study`'s energy and solver) on
revolved meshes of decreasing edge length ``h``; the error ``W − W_smooth``
is fitted as ``C h^p``.  Two discretizations per shape: with the paper's
regularization at λ(h) = 0.3 · 642/nv (∝ h², the study's rule) and without
(λ = 0: the damped Newton iteration from the revolved start, which is
then free to move vertices tangentially).  Shapes: the unit sphere (area
fixed only; W = 4π), the v = 0.85 prolate (area and volume fixed; the
axisymmetric reference) and the Clifford torus (the torus of revolution
with radii √2 and 1, area fixed; W = 2π², the least Willmore energy of a
torus: Marques & Neves, Ann. Math. 179, 683, 2014), meshed by
:func:`~pyevolver.studies.meshes.torus_offset` with ``m`` points around the
minor circle and ``2m`` rows, ``2m²`` ≈ nv vertices.

    python -m pyevolver.studies.phase_convergence [--nv 160,320,640] [--shapes ...]
        [--out DIR] [--keep]

writes ``convergence.csv`` and ``convergence.png``/``.pdf`` (log-log error
against h, fitted orders in the legend); ``--keep`` keeps the rows of the
other shapes already in ``DIR/convergence.csv`` (run one shape again).
"""
from __future__ import annotations

import argparse
import csv
import io
import math
import os
import tempfile

import numpy as np

from ..geometry import kernels as G
from ..session.core import Session
from .axisymmetric import canham_reference
from .meshes import torus_offset, write_fe
from .phase_mesh import mesh_quality, revolve
from .phase_study import lam_for
from .vesicle_newton import newton_lm

SHAPES = ("sphere", "prolate", "clifford")


def _session(X, F, lam, v, directory, area="4*pi"):
    lines = ["quantity willmore energy method normal_sq_mean_curvature global",
             f"quantity surf fixed = {area} method facet_area global"]
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
    elif shape == "clifford":
        m = max(4, round(math.sqrt(nv / 2)))
        X, F = torus_offset(m, 2 * m, R=math.sqrt(2.0), r=1.0)
        v, Ws = None, 2 * math.pi ** 2
    else:
        raise ValueError(f"unknown shape {shape!r}; expected one of {SHAPES}")
    area = "4*pi"
    if shape == "clifford":          # (W is scale-invariant: the mesh's own area is kept)
        area = repr(float(G.corner_geometry(np.ascontiguousarray(X.T),
                                            np.ascontiguousarray(np.asarray(F).T))[2].sum()))
    else:
        X, F = revolve(s, r, z, nv, area=4 * math.pi)
    lam = lam_for(nv) if regularized else 0.0
    with tempfile.TemporaryDirectory() as tmp:
        sess = _session(X, F, lam, v, tmp, area)
        ok, _, _ = newton_lm(sess, maxit=maxit)
        W = float(sess.totals.quantity_values["willmore"])
        q = mesh_quality(sess.surface.X, sess.surface.F)
    return {"shape": shape, "nv": len(X), "h": q["h"], "lambda": lam, "W": W, "W_smooth": Ws,
            "error": W - Ws, "converged": bool(ok), "min_angle_deg": q["min_angle_deg"]}


def fit_order(h, err) -> tuple[float, float]:
    """``(p, C)`` of the least squares fit ``log|err| = log C + p log h``."""
    p, logc = np.polyfit(np.log(np.asarray(h)), np.log(np.abs(np.asarray(err))), 1)
    return float(p), float(math.exp(logc))


def fits_of(rows: list[dict]) -> list[dict]:
    """The fitted orders ``{shape, regularized, order, C, sign}`` of each
    shape and discretization with at least two converged points."""
    fits = []
    for shape in dict.fromkeys(r["shape"] for r in rows):
        for reg in (True, False):
            ok = [p for p in rows if p["shape"] == shape and p["regularized"] == reg
                  and p["converged"] and p["error"] != 0]
            if len(ok) >= 2:
                p, C = fit_order([q["h"] for q in ok], [q["error"] for q in ok])
                fits.append({"shape": shape, "regularized": reg, "order": p, "C": C,
                             "sign": int(np.sign(ok[-1]["error"]))})
    return fits


def study(sizes=(160, 320, 640), shapes=SHAPES) -> tuple[list[dict], list[dict]]:
    """All points and the fitted orders (:func:`fits_of`; on the converged
    points, at least two)."""
    rows = [dict(point(shape, nv, reg), regularized=reg)
            for shape in shapes for reg in (True, False) for nv in sizes]
    return rows, fits_of(rows)


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


def _typed(row: dict) -> dict:
    """A row read back from convergence.csv with its numbers and flags."""
    out = dict(row)
    for k in ("h", "lambda", "W", "W_smooth", "error", "min_angle_deg"):
        out[k] = float(row[k])
    out["nv"] = int(row["nv"])
    for k in ("converged", "regularized"):
        out[k] = row[k] == "True"
    return out


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    p = argparse.ArgumentParser(prog="python -m pyevolver.studies.phase_convergence",
                                description=__doc__.split("\n")[0])
    p.add_argument("--nv", default="160,320,640")
    p.add_argument("--shapes", default=",".join(SHAPES))
    p.add_argument("--out", default=".")
    p.add_argument("--keep", action="store_true",
                   help="keep the other shapes' rows of OUT/convergence.csv")
    args = p.parse_args(argv)
    shapes = tuple(args.shapes.split(","))
    rows, _ = study(tuple(int(x) for x in args.nv.split(",")), shapes)
    csv_path = os.path.join(args.out, "convergence.csv")
    if args.keep and os.path.exists(csv_path):
        with open(csv_path) as fh:
            old = [_typed(r) for r in csv.DictReader(fh) if r["shape"] not in shapes]
        rows = old + rows
    fits = fits_of(rows)
    os.makedirs(args.out, exist_ok=True)
    with open(csv_path, "w", newline="") as fh:
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
