#!/usr/bin/env python3
"""Would a multifrontal LDLᵀ written with numpy beat SuperLU on the
``hessian`` step's matrix?  (issue 24; the answer quoted in
docs/performance.md, "What is left")

On the area Hessian of ``bench_hessian.py`` (81,920-facet prolate icosphere
after ``g 2``, ``hessian_normal``: one unknown per vertex) the script

* times SuperLU's factorization in pyevolver's nested-dissection order (the
  ``hessian`` step's, :func:`pyevolver.evolve.superlu.factor`);
* builds the frontal tree of that order (the separators of each cut and the
  leaves as fronts; the update structure of each front by the symbolic
  union of its pivots' couplings and its children's structures) and counts
  the factor's entries, the dense flops (``Σ p³/3 + p²u + pu²``) and the
  extend-add volume ``Σ u²``: the entries a multifrontal method moves from
  the children's update matrices into their parents;
* times numpy's scatter-add (``np.add.at``, fancy-index ``+=``) of that many
  entries (the first ``--leaf``'s volume) to random places of an array three
  times as long: the extend-add's memory traffic without its index work.

    PYTHONPATH=. python benchmarks/bench_frontal.py [--level 6] [--leaf 16 32 64]
"""
import argparse
import time

import numpy as np
import scipy.sparse as sp

from _common import icosphere_file, shifted_hessian

PREFIX = "set vertex z z*1.5\nset body target body[1].volume\ng 2\n"


def fronts(A, perm, leaf_of):
    """(pivots p, update sizes u) of the fronts in the order ``perm``;
    ``leaf_of`` (n,) the front of each position of the permuted matrix (its
    runs of one value)."""
    n = A.shape[0]
    pos = np.empty(n, np.int64)
    pos[perm] = np.arange(n)
    starts = np.flatnonzero(np.r_[True, leaf_of[1:] != leaf_of[:-1]])
    ends = np.r_[starts[1:], n]
    nf = len(starts)
    front = np.repeat(np.arange(nf), ends - starts)
    C = A.tocoo()
    pi, pj = pos[C.row], pos[C.col]
    lo = np.minimum(pi, pj)
    hi = np.maximum(pi, pj)
    f = front[lo]
    keep = hi >= ends[f]
    pairs = {}
    for ff, hh in zip(f[keep].tolist(), hi[keep].tolist()):
        pairs.setdefault(ff, set()).add(hh)
    u = np.zeros(nf, np.int64)
    for k in range(nf):                 # children before parents in this order
        s = pairs.get(k, set())
        u[k] = len(s)
        if s:
            first = min(s)              # the parent: the front of the first update row
            parent = front[first]
            rest = {x for x in s if x >= ends[parent]}
            pairs.setdefault(parent, set()).update(rest)
    return ends - starts, u


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--level", type=int, default=6)
    ap.add_argument("--leaf", type=int, nargs="+", default=[16, 32, 64])
    a = ap.parse_args()
    from pyevolver.evolve import superlu
    from pyevolver.evolve.ordering import dissection
    hs, A, perm, Ap = shifted_hessian(icosphere_file(a.level), PREFIX)
    n = A.shape[0]
    t = []
    for _ in range(3):
        t0 = time.process_time()
        superlu.factor(Ap.copy(), natural=True)
        t.append(time.process_time() - t0)
    print(f"unknowns {n:,}; SuperLU factorization in the nested-dissection order: "
          f"{min(t):.3f} s CPU (best of 3)")
    volume = None
    for leaf in a.leaf:
        perm, front = dissection(hs.points, A, leaf=leaf)
        p, u = fronts(A, perm, front[perm])
        print(f"leaf {leaf}: {len(p):,} fronts, factor entries {(p * (p + 1) // 2 + p * u).sum():,},"
              f" dense flops {((p ** 3) / 3 + p * p * u + p * u * u).sum() / 1e6:.0f} M,"
              f" extend-add volume Σu² {(u * u).sum():,}")
        volume = int((u * u).sum()) if volume is None else volume
    m = volume
    rng = np.random.default_rng(0)
    target = np.zeros(3 * m)
    idx = rng.integers(0, len(target), m)
    vals = rng.random(m)
    t0 = time.process_time()
    np.add.at(target, idx, vals)
    t1 = time.process_time()
    uniq = np.unique(idx)
    t2 = time.process_time()
    target[uniq] += vals[:len(uniq)]
    t3 = time.process_time()
    print(f"numpy scatter-add of {m:,} entries: np.add.at {t1 - t0:.3f} s, "
          f"fancy-index += ({len(uniq):,} distinct) {t3 - t2:.3f} s CPU")


if __name__ == "__main__":
    main()
