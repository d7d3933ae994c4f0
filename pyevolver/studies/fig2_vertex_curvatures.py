"""The paper's Figure 2: four discrete mean curvatures at a vertex raised
above a regular n-gon, as functions of its height.

The vertex ``v = (0, 0, h)`` is joined to the corners of a regular n-gon of
circumradius 1 in the plane z = 0 (a cone of n triangles, oriented with the
normals pointing up).  At v (``shared/papers/pl-methods-biomembranes.txt``,
section 2, with the estimates of spec §5):

* ``H_HKS = 3|F|/(2A)`` — Hsu–Kusner–Sullivan, local area A/3 of the star;
* ``H_MDSB = |S|/(4 A_mixed)`` — Meyer–Desbrun–Schröder–Barr, cotangent
  weights and the mixed (Voronoi / obtuse) area;
* ``H_EffArea = 3|F|/(2|N|)`` — the Evolver's effective-area curvature;
* ``H_NormalCur = 3 F·F/(2 F·N)`` — the Evolver's normal curvature,

with F the area gradient at v, N the sum of the facets' area vectors and A
the star's area.  The paper's point: H_HKS and H_MDSB increase with the
height only up to a threshold and then decrease although the cone gets
sharper; the effective-area and normal curvatures keep increasing.

    python -m pyevolver.studies.fig2_vertex_curvatures [--n 6] [--hmax 3] [--out fig2]

writes ``fig2.csv`` (columns h, H_HKS, H_MDSB, H_EffArea, H_NormalCur) and,
with matplotlib installed, ``fig2.png``.
"""
from __future__ import annotations

import argparse
import csv

import numpy as np

from ..atomic import atomic_write
from ..methods.curvature import _cot_and_grad, _mixed_areas


def cone(n: int, h: float) -> np.ndarray:
    """Corners (n, 3, 3) of the n triangles (apex, p_k, p_{k+1})."""
    t = 2 * np.pi * np.arange(n) / n
    ring = np.stack([np.cos(t), np.sin(t), np.zeros(n)], axis=1)
    apex = np.array([0.0, 0.0, h])
    return np.stack([np.broadcast_to(apex, (n, 3)), ring, np.roll(ring, -1, axis=0)], axis=1)


def curvatures(n: int, h: float) -> tuple[float, float, float, float]:
    """(H_HKS, H_MDSB, H_EffArea, H_NormalCur) at the apex of the cone."""
    P = cone(n, h)
    N2 = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    L = np.linalg.norm(N2, axis=1)
    nrm = N2 / L[:, None]
    F = 0.5 * np.cross(nrm, P[:, 2] - P[:, 1]).sum(axis=0)     # ∂A/∂apex
    A = 0.5 * L.sum()
    N = 0.5 * N2.sum(axis=0)
    h_hks = 1.5 * np.linalg.norm(F) / A
    h_eff = 1.5 * np.linalg.norm(F) / np.linalg.norm(N)
    h_norm = 1.5 * (F @ F) / (F @ N)
    # MDSB at the apex (corner 0 of every facet)
    cot, cg = _cot_and_grad(P)
    Af = 0.5 * L
    Am, _ = _mixed_areas(P, cot, cg, Af, np.zeros_like(P))
    S = (cot[:, 2, None] * (P[:, 0] - P[:, 1]) + cot[:, 1, None] * (P[:, 0] - P[:, 2])).sum(axis=0)
    h_mdsb = np.linalg.norm(S) / (4.0 * Am[:, 0].sum())
    return h_hks, h_mdsb, h_eff, h_norm


def table(n: int = 6, hmax: float = 3.0, steps: int = 301) -> np.ndarray:
    """Rows (h, H_HKS, H_MDSB, H_EffArea, H_NormalCur) for h in (0, hmax]."""
    hs = np.linspace(hmax / steps, hmax, steps)
    return np.array([(h,) + curvatures(n, h) for h in hs])


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=6, help="number of corners of the n-gon")
    ap.add_argument("--hmax", type=float, default=3.0, help="largest height")
    ap.add_argument("--steps", type=int, default=301)
    ap.add_argument("--out", default="fig2", help="output prefix (.csv and .png)")
    a = ap.parse_args(argv)
    rows = table(a.n, a.hmax, a.steps)
    names = ["h", "H_HKS", "H_MDSB", "H_EffArea", "H_NormalCur"]
    with atomic_write(a.out + ".csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(names)
        w.writerows(rows.tolist())
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"wrote {a.out}.csv (matplotlib not installed: no picture)")
        return 0
    fig, ax = plt.subplots(figsize=(6, 4))
    for k, name in enumerate(names[1:], start=1):
        ax.plot(rows[:, 0], rows[:, k], label=name.replace("H_", ""))
    ax.set_xlabel("height of the vertex over the regular %d-gon" % a.n)
    ax.set_ylabel("discrete mean curvature at the vertex")
    ax.legend()
    fig.tight_layout()
    with atomic_write(a.out + ".png", "wb") as fh:
        fig.savefig(fh, format="png", dpi=120)
    print(f"wrote {a.out}.csv and {a.out}.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
