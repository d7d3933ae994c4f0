"""The paper's Figure 1: PL Willmore energies fail on the genus-1 problem.

The regularly triangulated 5×9 torus (every vertex of valence 6,
:func:`pyevolver.studies.meshes.torus_grid`, radii √2 and 1) is minimized,
without smoothing, under four discrete Willmore energies
(shared/papers/pl-methods-biomembranes, §2 and Fig. 1):

========  =====================================  ===============================
label     pyevolver method                       minimizer
========  =====================================  ===============================
HKS       ``star_sq_mean_curvature``             ``g`` (the Evolver's descent)
MDSB      ``cotan_sq_mean_curvature``            ``bfgs``
EffArea   ``star_eff_area_sq_mean_curvature``    ``bfgs``
Bobenko   ``circle_willmore``                    ``bfgs`` (nonsmooth: ``g`` stalls)
========  =====================================  ===============================

Every run starts from the torus with its vertices moved by 1e-3 (seeded):
the exact grid is a critical point of each energy by symmetry (``g``
takes scale 0 there).  By the Marques–Neves theorem every smooth torus has
W ≥ 2π²; the PL energies end far below (paper: HKS 8.85, Bobenko 12.57 ≈ 4π)
with collapsing triangles.  The datafiles are ``datafiles/paper/torus5x9_*.fe``.

    python -m pyevolver.studies.fig1_torus [--steps 3000] [--iters 2000] [--out DIR]

writes ``fig1_torus.csv`` (label, method, minimizer, iterations, W, minimum
angle in degrees, seconds) and ``fig1_torus.png`` (the final surfaces).
"""
from __future__ import annotations

import argparse
import io
import math
import os
import time

import numpy as np

from ..atomic import atomic_write
from ..evolve.gradient import _facet_points
from ..methods.curvature import _angles
from ..model.surface import Surface
from ..session.core import Session
from .meshes import torus_grid, write_fe

RUNS = [("HKS", "star_sq_mean_curvature", "g"),
        ("MDSB", "cotan_sq_mean_curvature", "bfgs"),
        ("EffArea", "star_eff_area_sq_mean_curvature", "bfgs"),
        ("Bobenko", "circle_willmore", "bfgs")]
HERE = os.path.dirname(os.path.abspath(__file__))
PAPER = os.path.join(HERE, "..", "..", "datafiles", "paper")


def datafile(method: str, directory: str = PAPER) -> str:
    """Path of the shipped 5×9 torus datafile with ``method`` as its energy
    (written from :func:`torus_grid` when missing).

    Parameters
    ----------
    method : str
        A Willmore method name, e.g. ``"star_sq_mean_curvature"``.
    directory : str
        Where the datafile lives (``datafiles/paper``).
    """
    path = os.path.join(directory, f"torus5x9_{method}.fe")
    if not os.path.exists(path):
        os.makedirs(directory, exist_ok=True)
        X, F = torus_grid(5, 9, R=math.sqrt(2.0), r=1.0)
        header = (f"// The regular 5x9 torus of the paper's Figure 1 (radii sqrt 2 and 1),\n"
                  f"// energy {method} only (facets carry no tension).\n"
                  f"// Written by pyevolver.studies.fig1_torus.\n"
                  f"quantity willmore energy method {method} global")
        write_fe(path, X, F, header=header, face_attrs="tension 0")
    return path


def min_angle(surface: Surface) -> float:
    """Smallest corner angle of the surface's facets, in degrees."""
    ang, _ = _angles(_facet_points(surface.evaluate()))
    return float(np.degrees(ang.min()))


def run(label: str, method: str, minimizer: str, steps: int = 3000, iters: int = 2000,
        jitter: float = 1e-3, seed: int = 0) -> tuple[Session, dict]:
    """One run of :data:`RUNS`.

    Parameters
    ----------
    label, method, minimizer : str
        A row of :data:`RUNS` (minimizer ``"g"`` or ``"bfgs"``).
    steps, iters : int
        ``g`` steps, or ``bfgs`` iterations.
    jitter : float
        Standard deviation of the seeded random move of the vertices.
    seed : int
        Seed of that move.

    Returns
    -------
    (Session, dict)
        The session after the run and its row (label, method, minimizer,
        iterations, W, min_angle_deg, seconds).
    """
    s = Session.load(datafile(method), out=io.StringIO())
    rng = np.random.default_rng(seed)
    s.surface.X += jitter * rng.standard_normal(s.surface.X.shape)
    s.recalc()
    t0 = time.perf_counter()
    if minimizer == "g":
        s.g(steps, echo=False)
        n = steps
    else:
        n = s.bfgs(iters, echo=False).nit
    dt = time.perf_counter() - t0
    return s, {"label": label, "method": method, "minimizer": minimizer, "iterations": n,
               "W": s.total_energy, "min_angle_deg": min_angle(s.surface), "seconds": dt}


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=3000, help="g steps (HKS)")
    ap.add_argument("--iters", type=int, default=2000, help="bfgs iterations")
    ap.add_argument("--out", default=".")
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    rows, surfaces = [], []
    for label, method, mini in RUNS:
        s, row = run(label, method, mini, a.steps, a.iters)
        rows.append(row)
        surfaces.append(s.surface)
        print(f"{label:8s} {mini:5s} {row['iterations']:5d} its  W = {row['W']:.6f}  "
              f"min angle {row['min_angle_deg']:.3g} deg  {row['seconds']:.1f} s", flush=True)
    print(f"2 pi^2 = {2 * math.pi ** 2:.6f}, 4 pi = {4 * math.pi:.6f}")
    csv = os.path.join(a.out, "fig1_torus.csv")
    with atomic_write(csv, "w") as fh:
        keys = list(rows[0])
        fh.write(",".join(keys) + "\n")
        for r in rows:
            fh.write(",".join(str(r[k]) for k in keys) + "\n")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed: no PNG")
        return 0
    fig = plt.figure(figsize=(4 * len(rows), 4.4))
    for k, (r, S) in enumerate(zip(rows, surfaces)):
        ax = fig.add_subplot(1, len(rows), k + 1, projection="3d")
        ax.plot_trisurf(S.X[:, 0], S.X[:, 1], S.X[:, 2], triangles=S.F, color="0.8",
                        edgecolor="k", linewidth=0.3)
        ax.set_title(f"{r['label']}: W = {r['W']:.2f}", pad=12)
        ax.set_axis_off()
    fig.tight_layout()
    with atomic_write(os.path.join(a.out, "fig1_torus.png"), "wb") as fh:
        fig.savefig(fh, format="png", dpi=100)
    print("wrote", csv, "and fig1_torus.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
