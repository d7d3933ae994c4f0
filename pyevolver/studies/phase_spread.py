"""The spread of the phase study's numbers over perturbed starting meshes.

A point of :mod:`~pyevolver.studies.phase_study` is solved once from the
reference revolved into a mesh (``phase_mesh.revolve``) and, with seeds,
again from perturbed starts: for seed ``k`` the rings of the revolved mesh
are rotated by random angles (``revolve(..., rng=...)``: another
triangulation of the same surface) and every vertex is moved by a
Gaussian of deviation :data:`JITTER` × the mean edge length, both from
``numpy.random.default_rng(k)``.  The row keeps its own numbers (the
unperturbed start's) and gains the seeds' (:data:`SEED_COLUMNS`):

``seeds``
    the seeds, ``;``-separated (the output records them);
``W_seeds``, ``eig1_seeds``
    each seed's W and lowest eigenvalue (empty where it did not converge);
``stable_seeds``
    ``"k/n"``: of the n converged seeds, k marked stable;
``W_spread``
    max − min of W over the point and its converged seeds;
``start_seeds``
    how each seed was solved: its attempt and λ (``revolved/min@0.3``;
    a seed may succeed with another λ or start than the point, and a
    larger λ moves W, so this explains the larger spreads).

:func:`crossing_spread` gives each transition per seed, so that the
crossings carry their spread too.
"""
from __future__ import annotations

from typing import Callable

import numpy as np

#: the vertex jitter of a perturbed start, in mean edge lengths
JITTER = 0.05
SEED_COLUMNS = ["seeds", "W_seeds", "eig1_seeds", "stable_seeds", "W_spread", "start_seeds"]


def jitter(X: np.ndarray, F: np.ndarray, rng: np.random.Generator,
           amount: float = JITTER) -> np.ndarray:
    """``X`` (n, 3) moved by Gaussians of deviation ``amount`` × the mean
    edge length of the mesh ``F`` (m, 3)."""
    P = X[F]
    h = float(np.mean(np.linalg.norm(P - np.roll(P, 1, axis=1), axis=2)))
    return X + rng.normal(scale=amount * h, size=X.shape)


def parse_seeds(text: str) -> list[int]:
    """``"1;2;3"`` -> ``[1, 2, 3]`` (``""`` -> ``[]``)."""
    return [int(t) for t in str(text).split(";") if t.strip() != ""]


def values(row: dict, key: str) -> list[float | None]:
    """A ``;``-separated column of ``row`` as numbers (None where empty)."""
    text = row.get(key, "")
    if text in ("", None):
        return []
    return [None if t == "" else float(t) for t in str(text).split(";")]


def add_seeds(row: dict, seeds: list[int], seed_rows: list[dict]) -> None:
    """Fill ``row``'s :data:`SEED_COLUMNS` from the rows solved from the
    perturbed starts of ``seeds`` (same order)."""
    def num(r, k):
        x = r.get(k)
        return "" if not r["converged"] or x is None or x != x else f"{float(x):.10g}"
    ok = [r for r in seed_rows if r["converged"] is True]
    row["seeds"] = ";".join(str(k) for k in seeds)
    row["W_seeds"] = ";".join(num(r, "W") for r in seed_rows)
    row["eig1_seeds"] = ";".join(num(r, "eig1") for r in seed_rows)
    row["stable_seeds"] = f"{sum(r['stable'] is True for r in ok)}/{len(ok)}"
    row["start_seeds"] = ";".join(f"{r['start']}@{r['lambda']:.4g}" if r["converged"] is True
                                  else "" for r in seed_rows)
    W = [r["W"] for r in ok] + ([row["W"]] if row["converged"] is True else [])
    row["W_spread"] = float(max(W) - min(W)) if len(W) > 1 else float("nan")


def crossing_spread(rows: list[dict], fa: str, fb: str,
                    crossing: Callable[[list, list], float | None]) -> list[float | None]:
    """The crossing of branches ``fa`` and ``fb`` per seed index (the k-th
    seed's W of every converged point where that seed converged)."""
    n = max((len(values(r, "W_seeds")) for r in rows), default=0)
    out = []
    for k in range(n):
        pts = {}
        for b in (fa, fb):
            pts[b] = []
            for r in rows:
                w = values(r, "W_seeds")
                if r["branch"] == b and r["converged"] is True and k < len(w) and w[k] is not None:
                    pts[b].append((r["v"], w[k]))
        out.append(crossing(pts[fa], pts[fb]))
    return out
