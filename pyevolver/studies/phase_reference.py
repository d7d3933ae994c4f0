"""Branches and transitions of the axisymmetric vesicle phase diagram.

The smooth reference of the phase-diagram study (issue 27): the minimisers
of :func:`pyevolver.studies.axisymmetric.canham_reference` followed along
the reduced volume ``v`` on each branch (prolate, oblate/discocyte,
stomatocyte) by continuation — each point's Newton iteration starts from the
neighbouring point's shape —, and the transitions, the reduced volumes where
two branches' energies cross (Seifert, Berndl & Lipowsky 1991, Phys. Rev. A
44, 1182, Fig. 8 for ``c0 = 0``: prolate/oblate at v ≈ 0.652,
oblate/stomatocyte at v ≈ 0.592).

    python -m pyevolver.studies.phase_reference [--c0 0] [--alpha 0 --m0 1]
        [--vmin 0.5 --vmax 0.95 --step 0.025]

prints each branch's energies ``W/(4π)`` and the crossings.
"""
from __future__ import annotations

import argparse
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from .axisymmetric import BRANCHES, CanhamResult, Helfrich, canham_reference

#: where each branch's initial shape converges without continuation
#: (c0 = 0; the continuation carries the branch from there)
SEEDS = {"prolate": 0.85, "oblate": 0.70, "stomatocyte": 0.55}
#: sine modes per branch: the stomatocyte's neck needs many
MODES = {"prolate": 32, "oblate": 32, "stomatocyte": 64}
#: the shape types (:func:`~pyevolver.studies.axisymmetric.descriptors`) of each branch:
#: a continuation that reaches another type has left the branch (with ADE the
#: "stomatocyte" start can converge to the discocyte)
BRANCH_TYPES = {"prolate": {"prolate", "sphere"}, "oblate": {"oblate", "discocyte", "sphere"},
                "stomatocyte": {"stomatocyte"}}


@dataclass
class BranchPoint:
    """One converged point of a branch."""
    branch: str
    v: float
    W: float
    result: CanhamResult


def follow(branch: str, volumes, model: Helfrich | None = None, n: int | None = None,
           seed: float | None = None, max_halvings: int = 6) -> list[BranchPoint]:
    """The branch's minimisers at each reduced volume of ``volumes``.

    The first point solved is ``seed`` (default :data:`SEEDS`), from the
    branch's initial shape; the others by continuation outwards from it,
    halving the step in ``v`` when Newton's iteration does not converge.
    Points the continuation cannot reach (the branch ends, or its shape
    changes type: not in :data:`BRANCH_TYPES`) are left out, the seed too
    when it is not of its branch's type.

    Parameters
    ----------
    branch : {"prolate", "oblate", "stomatocyte"}
    volumes : sequence of float
        Reduced volumes in (0, 1].
    model : Helfrich, optional
        Spontaneous curvature / ADE parameters (default ``∫H² dA``).
    n : int, optional
        Sine modes (default :data:`MODES`).

    Returns
    -------
    list of BranchPoint, sorted by ``v``.
    """
    if branch not in BRANCHES:
        raise ValueError(f"unknown branch {branch!r}; expected one of {BRANCHES}")
    n = n or MODES[branch]
    seed = SEEDS[branch] if seed is None else seed
    start = canham_reference(seed, branch, n=n, model=model)
    vs = np.unique(np.asarray(volumes, dtype=float))
    out = {}
    if start.descriptors["type"] not in BRANCH_TYPES[branch]:
        return []
    for side in (vs[vs >= seed], vs[vs < seed][::-1]):
        prev, v_prev = start, seed
        for v in side:
            res = _step(branch, v_prev, v, prev, model, n, max_halvings)
            if res is None or res.descriptors["type"] not in BRANCH_TYPES[branch]:
                break
            out[float(v)] = BranchPoint(branch, float(v), res.W, res)
            prev, v_prev = res, float(v)
    return [out[v] for v in sorted(out)]


def _step(branch, v_from, v_to, prev, model, n, halvings):
    """Continuation from ``prev`` (at ``v_from``) to ``v_to``, halving the
    step on failure; None when even the smallest step fails."""
    if v_to == v_from:
        return prev
    try:
        with np.errstate(invalid="ignore", over="ignore"):   # a diverging Newton iterate
            return canham_reference(v_to, branch, n=n, coef0=prev.coef, model=model)
    except (RuntimeError, FloatingPointError, np.linalg.LinAlgError):
        if halvings <= 0:
            return None
    mid = 0.5 * (v_from + v_to)
    half = _step(branch, v_from, mid, prev, model, n, halvings - 1)
    if half is None:
        return None
    return _step(branch, mid, v_to, half, model, n, halvings - 1)


def crossing(a: list[BranchPoint], b: list[BranchPoint], model: Helfrich | None = None,
             xtol: float = 1e-6) -> float | None:
    """The reduced volume where branches ``a`` and ``b`` have equal energy.

    The bracket is the first pair of neighbouring volumes common to both
    branches where ``W_a - W_b`` changes sign; inside it both branches are
    solved by continuation from the bracket's end and the root found by
    Brent's method.  None when the branches do not cross on their common
    volumes.
    """
    wa = {p.v: p for p in a}
    wb = {p.v: p for p in b}
    common = sorted(set(wa) & set(wb))
    for lo, hi in zip(common[:-1], common[1:]):
        dlo = wa[lo].W - wb[lo].W
        dhi = wa[hi].W - wb[hi].W
        if dlo == 0:
            return lo
        if np.sign(dlo) == np.sign(dhi):
            continue
        pa, pb = wa[lo].result, wb[lo].result

        def diff(v):
            ra = _step(pa.branch, lo, v, pa, model, pa.n, 6)
            rb = _step(pb.branch, lo, v, pb, model, pb.n, 6)
            if ra is None or rb is None:
                raise RuntimeError(f"continuation failed inside [{lo}, {hi}]")
            return ra.W - rb.W

        return float(brentq(diff, lo, hi, xtol=xtol))
    return None


def transitions(model: Helfrich | None = None, vmin: float = 0.5, vmax: float = 0.95,
                step: float = 0.025) -> tuple[dict, dict]:
    """Every branch on the grid ``vmin..vmax`` and the crossings
    prolate/oblate and oblate/stomatocyte.

    Returns
    -------
    branches : dict branch -> list of BranchPoint
    crossings : dict (from, to) -> v or None
    """
    grid = np.round(np.arange(vmin, vmax + 0.5 * step, step), 10)
    branches = {b: follow(b, grid, model) for b in BRANCHES}
    cross = {("prolate", "oblate"): crossing(branches["prolate"], branches["oblate"], model),
             ("oblate", "stomatocyte"): crossing(branches["oblate"], branches["stomatocyte"],
                                                 model)}
    return branches, cross


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    p = argparse.ArgumentParser(prog="python -m pyevolver.studies.phase_reference",
                                description=__doc__.split("\n")[0])
    p.add_argument("--c0", type=float, default=0.0)
    p.add_argument("--alpha", type=float, default=0.0)
    p.add_argument("--m0", type=float, default=1.0)
    p.add_argument("--vmin", type=float, default=0.5)
    p.add_argument("--vmax", type=float, default=0.95)
    p.add_argument("--step", type=float, default=0.025)
    args = p.parse_args(argv)
    model = Helfrich(args.c0, args.alpha, args.m0)
    branches, cross = transitions(model, args.vmin, args.vmax, args.step)
    print("branch,v,W/(4pi),type")
    for b, pts in branches.items():
        for pt in pts:
            print(f"{b},{pt.v:.4f},{pt.W / (4 * np.pi):.10f},"
                  f"{pt.result.descriptors['type']}")
    for (fa, fb), v in cross.items():
        print(f"transition {fa}/{fb}: " + ("none" if v is None else f"v = {v:.5f}"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
