#!/usr/bin/env python3
"""Seconds per energy + gradient of the Loop limit surface (issue 8).

For unit icospheres with 642, 2,562 and 10,242 control vertices (and the
5×9 / 10×16 tori for scale): the set-up of the patches (first call, per
topology) and one evaluation of W, area and volume together with the
gradient of W, best of ``--repeat`` runs; then the growth exponent
``log(t2/t1)/log(n2/n1)`` between consecutive sizes (1 = linear).

    python benchmarks/bench_loop.py [--repeat 5] [--order 6] [--max-level 5]
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from pyevolver.geometry.loop import LoopEvaluator  # noqa: E402
from pyevolver.studies.meshes import icosphere, torus_grid  # noqa: E402


def bench(X, F, repeat, order):
    t0 = time.perf_counter()
    ev = LoopEvaluator(F, len(X), order=order)
    setup = time.perf_counter() - t0
    best = None
    for r in range(repeat):
        Xr = X * (1 + 1e-9 * (r + 1))          # a new X each time (no cache hit)
        t0 = time.perf_counter()
        v = ev.values(Xr)
        g = ev.gradient(Xr, "W")
        dt = time.perf_counter() - t0
        best = dt if best is None else min(best, dt)
    assert np.isfinite(g).all()
    npts = sum(len(w) * len(ctrl) for _, w, ctrl, _ in ev.blocks)
    return setup, best, float(v["W"].sum()), npts


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--order", type=int, default=6)
    ap.add_argument("--max-level", type=int, default=5)
    args = ap.parse_args(argv)
    rows = []
    meshes = [(f"torus {m}x{n}", torus_grid(m, n)) for m, n in ((5, 9), (10, 16))]
    meshes += [(f"icosphere L{lev}", icosphere(lev)) for lev in range(3, args.max_level + 1)]
    print(f"{'mesh':16s} {'vertices':>9s} {'facets':>7s} {'quad pts':>9s} {'setup s':>8s} "
          f"{'E+grad s':>9s} {'us/facet':>9s} {'W':>12s}")
    for name, (X, F) in meshes:
        setup, t, W, npts = bench(X, F, args.repeat, args.order)
        rows.append((name, len(X), t))
        print(f"{name:16s} {len(X):9d} {len(F):7d} {npts:9d} {setup:8.3f} {t:9.4f} "
              f"{1e6 * t / len(F):9.2f} {W:12.6f}")
    ico = [r for r in rows if r[0].startswith("icosphere")]
    for (n1, v1, t1), (n2, v2, t2) in zip(ico, ico[1:]):
        print(f"growth {v1} -> {v2} vertices: t ∝ n^{np.log(t2 / t1) / np.log(v2 / v1):.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
