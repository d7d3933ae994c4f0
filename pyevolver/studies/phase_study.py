"""The discrete vesicle phase study (issue 27): branches, stability, transitions.

The reduced volume ``v`` is swept on three branches (prolate,
oblate/discocyte, stomatocyte), at spontaneous curvature ``c0`` (reduced,
``C0·R0``; default 0).  Each point minimises the discrete bending energy
``W = Σ_v (h_v − c0/2)² A_v/3`` with the Evolver's ``h_zero = c0/2``
(``normal_sq_mean_curvature`` at ``c0 = 0``, where a sphere gives 4π, and
``star_perp_sq_mean_curvature`` otherwise, :func:`method_for`; the smooth
energy is ``∫(H − c0/2)² dA``, SBL's ``F/(2κ)``) plus the paper's
harmonic regularization ``λ E`` (``E = (1/√3) Σ_edges |e|²``) over all vertex coordinates, at fixed area ``4π`` and
volume ``v·4π/3`` (damped Newton, :func:`~pyevolver.studies.vesicle_newton.newton_lm`).
λ(h) = ``LAMBDA_642 · 642/nv`` (∝ h²; 0.3 at 642 vertices).

Every point starts from the axisymmetric reference at its ``v`` — itself
followed along the branch by continuation from the neighbouring point
(:func:`~pyevolver.studies.phase_reference.follow`) — revolved into a mesh
of about ``nv`` vertices (:func:`~pyevolver.studies.phase_mesh.revolve`).
The branch is swept from its seed volume outwards.  A damped Newton
iteration that stops short of its tolerance on the branch is continued by
plain Newton from where it stopped.  A point whose iteration still does not
converge, whose mesh degenerates (smallest angle
below 10°) or whose shape leaves the branch (on the unstable part of a
branch every descent does) is solved by plain Newton on the critical-point
equations (:func:`~pyevolver.studies.phase_newton.newton_critical`, which
finds saddles), then both again with 2λ and with 4λ (the stomatocyte's
neck at 2,562 vertices needs 4λ, and so do the oblate saddles there: with
λ the critical-point Newton lets the triangles collapse), Newton once more
with 8λ (the 2,562-vertex oblate at v = 0.5: λ = 0.6, as 2λ at 642
vertices), and last minimised and solved by
Newton from the last converged neighbour's mesh.  (Starting every point from its neighbour's
mesh, the first design, lets the triangulation drift: on the prolate
branch at 300 vertices the error grew from +0.8% to +3.2% between
v = 0.8 and 0.6, against +0.8% from the revolved start.)  For each point
the row gives W, the reference ``W_ref`` (:mod:`~pyevolver.studies.phase_reference`),
``rel_err``, the mesh quality, and the lowest eigenvalues of the constrained
Hessian of W (normal vertex motions, mass-weighted, rigid motions removed;
:mod:`~pyevolver.studies.phase_stability`) with ``stable`` = the lowest
above −10⁻³.

    pyevolver study phase [--nv 642] [--vmin 0.5 --vmax 0.95 --step 0.025]
        [--c0 0] [--branches prolate,oblate,stomatocyte] [--out DIR] [--no-plot]

writes ``DIR/phase.csv`` (one row per branch and v), ``DIR/transitions.csv``
(the crossings of the discrete branches, linearly interpolated, with the
reference's and the published values), ``DIR/summary.md`` (both as
Markdown tables) and ``DIR/phase.png``/``.pdf``.  It is
resumable: converged rows already in ``phase.csv`` (same branch, c0, v, nv)
are kept (failed ones are solved again),
and their meshes (``DIR/meshes/``) are the neighbours' meshes of the fallback.
"""
from __future__ import annotations

import argparse
import csv
import io
import os
import tempfile
import time
from typing import Any, Callable

import numpy as np

from ..session.core import Session
from . import phase_plot, phase_reference as PR, phase_spread as SP
from .axisymmetric import BRANCHES, Helfrich
from .meshes import write_fe
from .phase_ade import HZERO_METHODS
from .phase_mesh import mesh_quality, revolve
from .phase_newton import newton_critical, restore
from .phase_stability import lowest_eigenvalues, stability
from .vesicle_newton import newton_lm
from .vesicle_shapes import mesh_descriptors

#: λ at 642 vertices; λ(h) = LAMBDA_642 · 642 / nv
LAMBDA_642 = 0.3
#: published transitions at c0 = 0 (Seifert, Berndl & Lipowsky 1991, Fig. 8)
PUBLISHED = {("prolate", "oblate"): 0.652, ("oblate", "stomatocyte"): 0.592}
#: the axis the reference is revolved about (phase_mesh.revolve), known to the classifier
AXIS = np.array([0.0, 0.0, 1.0])
#: shape types accepted on each branch
TYPES = {"prolate": {"prolate", "sphere"}, "oblate": {"oblate", "discocyte", "sphere"},
         "stomatocyte": {"stomatocyte"}}
COLUMNS = ["branch", "c0", "v", "nv", "W", "W_ref", "rel_err", "stable", "eig1", "eig2",
           "eig3", "lambda", "min_angle_deg", "aspect", "h", "type", "start", "converged",
           "newton_steps", "seconds", "method", "seed"] + SP.SEED_COLUMNS
#: the bending energy's method at c0 = 0 (the paper's) and at c0 != 0: with h_zero the
#: normal estimate h = 3F·F/(2F·N) is singular where F -> 0 (flat parts, the
#: discocyte's dimples: Hessian eigenvalues of -2e5 and failed points at c0 = -0.5),
#: star_perp's h = 3F·N/(2N·N) is not (the manual's "pretty good formula")
METHOD = "normal_sq_mean_curvature"
METHOD_C0 = "star_perp_sq_mean_curvature"


def method_for(c0: float, method: str | None = None) -> str:
    """The bending energy's method: ``method``, or by default
    :data:`METHOD` at ``c0 = 0`` and :data:`METHOD_C0` otherwise."""
    method = method or (METHOD if c0 == 0 else METHOD_C0)
    if method not in HZERO_METHODS:
        raise ValueError(f"{method}: the study's bending energy must take h_zero, one of "
                         f"{HZERO_METHODS}")
    return method
MIN_ANGLE = 10.0


def lam_for(nv: int) -> float:
    """λ(h) of the study: ``LAMBDA_642 · 642 / nv`` (∝ h²)."""
    return LAMBDA_642 * 642.0 / nv


def _session(X, F, v, lam, directory, c0=0.0, method=METHOD):
    path = os.path.join(directory, "point.fe")
    hdr = "\n".join([
        "// discrete phase study point (pyevolver.studies.phase_study)",
        f"parameter v0 = {v!r}"]
        # the Evolver's h_zero is a mean curvature: H0 = C0/2 (phase_ade)
        + ([f"parameter c0 = {c0!r}", "parameter h_zero = c0/2"] if c0 else []) + [
        f"quantity willmore energy method {method} global",
        "quantity surf fixed = 4*pi method facet_area global",
        f"quantity harm energy modulus {lam!r} method harmonic_energy global"])
    write_fe(path, X, F, header=hdr, face_attrs="tension 0")
    with open(path, "a") as fh:
        fh.write("\nbodies\n1 " + " ".join(str(i + 1) for i in range(len(F)))
                 + " volume v0*4*pi/3\n")
    return Session.load(path, out=io.StringIO(), err=io.StringIO())


def solve_point(branch: str, v: float, ref, nv: int, lam: float | None = None,
                start: tuple[np.ndarray, np.ndarray] | None = None, maxit: int = 60,
                eigen: bool = True, c0: float = 0.0, method: str | None = None,
                min_ring: int = 3, seed: int | None = None
                ) -> tuple[dict, np.ndarray, np.ndarray]:
    """One point of a branch: minimise W + λE from ``start`` (a mesh; default
    the reference ``ref`` revolved), falling back as the module docstring
    says; ``c0`` the spontaneous curvature (``ref`` must be the reference at
    the same ``c0``); ``method`` the bending energy (:func:`method_for`);
    ``min_ring`` the fewest vertices on a ring of the revolved start
    (:func:`~pyevolver.studies.phase_mesh.revolve`: above 3 the mesh is
    graded in a neck narrower than the mesh size; recorded in ``start``);
    ``seed``: start from a perturbed mesh instead (:mod:`phase_spread`:
    random ring rotations and vertex jitter from ``default_rng(seed)``;
    ``start`` jittered too).  Returns ``(row, X, F)``."""
    method = method_for(c0, method)
    lam = lam_for(nv) if lam is None else lam
    t0 = time.perf_counter()
    rng = None if seed is None else np.random.default_rng(seed)
    rev = revolve(ref.s, ref.r, ref.z, nv, area=4 * np.pi, min_ring=min_ring, rng=rng)
    if rng is not None:
        rev = (SP.jitter(*rev, rng), rev[1])
        if start is not None:
            start = (SP.jitter(*start, rng), start[1])
    revolved = "revolved" if min_ring <= 3 else f"revolved-ring{min_ring}"
    attempts = [(revolved, rev, lam, "min"), (revolved, rev, lam, "critical"),
                (revolved, rev, 2 * lam, "min"), (revolved, rev, 2 * lam, "critical"),
                (revolved, rev, 4 * lam, "min"), (revolved, rev, 4 * lam, "critical"),
                (revolved, rev, 8 * lam, "critical")]
    if start is not None:
        attempts += [("continued", start, lam, "min"), ("continued", start, lam, "critical")]
    steps = 0

    def on_branch(surf):
        """Stop a descent that leaves the branch (a saddle's: the oblate to
        the prolate) or folds the mesh up."""
        if mesh_quality(surf.X, surf.F)["min_angle_deg"] < MIN_ANGLE / 2:
            return False
        return (branch == "stomatocyte"
                or mesh_descriptors(surf.X, surf.F, AXIS)["type"] in TYPES[branch])
    with tempfile.TemporaryDirectory() as tmp:
        for kind, (X, F), lam_k, solver in attempts:
            s = _session(X, F, v, lam_k, tmp, c0, method)
            restore(s)
            if solver == "min":
                ok, n, _ = newton_lm(s, maxit=maxit, guard=on_branch)
                if not ok and on_branch(s.surface):     # restart the damping once
                    ok, n2, _ = newton_lm(s, maxit=maxit // 2, guard=on_branch)
                    n += n2
                if not ok and on_branch(s.surface):     # then plain Newton from there
                    ok, n2, _ = newton_critical(s)
                    n += n2
            else:       # (the 2,562-vertex saddles with 4λ: 32 steps at v = 0.8)
                ok, n, _ = newton_critical(s, maxit=maxit)
            steps += n
            X1, F1 = s.surface.X.copy(), s.surface.F.copy()
            q = mesh_quality(X1, F1)
            kind_shape = mesh_descriptors(X1, F1, AXIS)["type"]
            good = ok and q["min_angle_deg"] >= MIN_ANGLE and kind_shape in TYPES[branch]
            if good:
                break
        W = float(s.totals.quantity_values["willmore"])
        eig = lowest_eigenvalues(s, k=3) if (eigen and good) else np.full(3, np.nan)
    row = {"branch": branch, "c0": float(c0), "v": float(v), "nv": len(X1), "W": W,
           "W_ref": float(ref.W), "rel_err": W / ref.W - 1.0,
           "stable": (stability(eig) if good and eigen else ""),
           "eig1": eig[0], "eig2": eig[1], "eig3": eig[2], "lambda": lam_k,
           "min_angle_deg": q["min_angle_deg"], "aspect": q["aspect"], "h": q["h"],
           "type": kind_shape, "start": f"{kind}/{solver}", "converged": bool(good),
           "newton_steps": steps, "seconds": time.perf_counter() - t0, "method": method,
           "seed": "" if seed is None else int(seed)}
    return row, X1, F1


# -- the sweep ----------------------------------------------------------------------------------

def grid(vmin: float = 0.5, vmax: float = 0.95, step: float = 0.025) -> np.ndarray:
    return np.round(np.arange(vmin, vmax + 0.5 * step, step), 10)


def _key(branch, v, nv_target, c0=0.0):
    return f"{branch}_{v:.4f}_{nv_target}" + (f"_c0_{c0:+.4f}" if c0 else "")


def read_rows(path: str) -> list[dict]:
    """The rows of a ``phase.csv`` (numbers as floats, booleans as bool)."""
    if not os.path.exists(path):
        return []
    out = []
    with open(path, newline="") as fh:
        for r in csv.DictReader(fh):
            row: dict[str, Any] = {}
            for k, val in r.items():
                if val in ("True", "False"):
                    row[k] = val == "True"
                elif k in ("branch", "type", "start", "method", "from", "to", "seeds",
                           "W_seeds", "eig1_seeds", "stable_seeds", "v_seeds",
                           "start_seeds") or val == "":
                    row[k] = val
                else:
                    row[k] = float(val)
            out.append(row)
    return out


def write_rows(path: str, rows: list[dict]) -> None:
    rows = sorted(rows, key=lambda r: (float(r.get("c0") or 0.0), BRANCHES.index(r["branch"]),
                                       r["v"]))
    tmp = path + ".tmp"
    with open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS + ["nv_target"], extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{r[k]:.10g}" if isinstance(r.get(k), float) else r.get(k, ""))
                        for k in COLUMNS + ["nv_target"]})
    os.replace(tmp, path)


def run_branch(branch: str, volumes, nv: int, out: str, refs: dict, rows: list[dict],
               log: Callable[[str], Any] = print, eigen: bool = True, c0: float = 0.0,
               method: str | None = None, min_ring: int = 3, seeds: tuple[int, ...] = ()
               ) -> None:
    """Solve the branch's points of ``volumes`` (those with a reference in
    ``refs``, v -> BranchPoint) by continuation from its seed outwards,
    appending to ``rows`` and rewriting ``out/phase.csv`` after each point;
    converged points already in ``rows`` are skipped, failed ones solved
    again.  The fallback start of a point is the last converged point's
    mesh on its side of the seed.  ``c0``: the spontaneous curvature (rows
    of other ``c0`` are left alone); ``method`` the bending energy (one
    output folder per method: the rows do not key on it); ``seeds``: each
    point solved again from the perturbed starts of these seeds, their
    numbers and the spread in the point's row (:mod:`phase_spread`; a
    point done without them gets them on the next run)."""
    mesh_dir = os.path.join(out, "meshes")
    os.makedirs(mesh_dir, exist_ok=True)
    vs = np.array(sorted(v for v in volumes if float(v) in refs))
    if not len(vs):
        return
    seed = vs[np.argmin(np.abs(vs - PR.SEEDS[branch]))]

    def mine(r, v):
        return (r["branch"] == branch and round(r["v"], 6) == round(float(v), 6)
                and int(r.get("nv_target", 0)) == nv
                and round(float(r.get("c0") or 0.0), 9) == round(c0, 9))

    def with_seeds(row, v, start):
        """The seeds' solves of a point, into its row."""
        want = ";".join(str(k) for k in seeds)
        if not seeds or row.get("seeds", "") == want:
            return False
        seed_rows = [solve_point(branch, float(v), refs[float(v)].result, nv, start=start,
                                 eigen=eigen, c0=c0, method=method, min_ring=min_ring,
                                 seed=k)[0] for k in seeds]
        SP.add_seeds(row, list(seeds), seed_rows)
        log(f"{branch} v={v:.4f} seeds {want}: W {row['W_seeds']} "
            f"spread {row['W_spread']:.3g} stable {row['stable_seeds']}")
        return True
    for side in (vs[vs >= seed], vs[vs < seed][::-1]):
        start = None
        for v in side:
            key = os.path.join(mesh_dir, _key(branch, v, nv, c0) + ".npz")
            done = [r for r in rows if mine(r, v) and r["converged"] is True]
            if done and os.path.exists(key):
                if with_seeds(done[0], v, start):
                    write_rows(os.path.join(out, "phase.csv"), rows)
                with np.load(key) as z:
                    start = (z["X"], z["F"])
                continue
            rows[:] = [r for r in rows if not mine(r, v)]       # a failed point: again
            if start is None and side[0] != seed and v == side[0]:
                sk = os.path.join(mesh_dir, _key(branch, seed, nv, c0) + ".npz")
                if os.path.exists(sk):
                    with np.load(sk) as z:
                        start = (z["X"], z["F"])
            row, X, F = solve_point(branch, float(v), refs[float(v)].result, nv, start=start,
                                    eigen=eigen, c0=c0, method=method, min_ring=min_ring)
            row["nv_target"] = nv
            log(f"{branch} v={v:.4f} W={row['W']:.6f} rel_err={row['rel_err']:+.5f} "
                f"eig1={row['eig1']:.4g} stable={row['stable']} lambda={row['lambda']:g} "
                f"{row['start']} {row['type']} {row['seconds']:.1f}s")
            rows.append(row)
            write_rows(os.path.join(out, "phase.csv"), rows)
            if with_seeds(row, v, start):                       # from the same fallback
                write_rows(os.path.join(out, "phase.csv"), rows)
            if row["converged"]:
                np.savez(key, X=X, F=F)
                start = (X, F)          # else the last converged point stays the start


def crossing_linear(a: list[tuple[float, float]], b: list[tuple[float, float]]) -> float | None:
    """The first v (ascending) where the piecewise linear energies ``a`` and
    ``b`` (lists of (v, W)) cross on their common volumes; None if they do
    not."""
    wa, wb = dict(a), dict(b)
    common = sorted(set(wa) & set(wb))
    d = [wa[v] - wb[v] for v in common]
    for k in range(len(common) - 1):
        if d[k] == 0:
            return common[k]
        if d[k] * d[k + 1] < 0:
            return common[k] + (common[k + 1] - common[k]) * d[k] / (d[k] - d[k + 1])
    return None


def transitions(rows: list[dict], refs: dict | None = None, c0: float = 0.0,
                model: Helfrich | None = None) -> list[dict]:
    """Crossings prolate/oblate and oblate/stomatocyte of the discrete
    branches (converged points only), of the reference (exact, by
    :func:`phase_reference.crossing` with ``model``, when ``refs`` is
    given) and the published values (``c0 = 0`` only); with seeds
    (:mod:`phase_spread`) each seed's crossing (``v_seeds``) and the
    spread over the point's and the seeds' (``v_spread``)."""
    out = []
    for (fa, fb), pub in PUBLISHED.items():
        pub = pub if c0 == 0.0 else None
        pa = [(r["v"], r["W"]) for r in rows if r["branch"] == fa and r["converged"] is True]
        pb = [(r["v"], r["W"]) for r in rows if r["branch"] == fb and r["converged"] is True]
        v = crossing_linear(pa, pb)
        vref = None
        if refs is not None and refs.get(fa) and refs.get(fb):
            vref = PR.crossing(list(refs[fa].values()), list(refs[fb].values()), model)
        per_seed = SP.crossing_spread(rows, fa, fb, crossing_linear)
        found = [x for x in [v] + per_seed if x is not None]
        out.append({"c0": float(c0), "from": fa, "to": fb, "v": v, "v_ref": vref,
                    "v_published": pub,
                    "v_seeds": ";".join("" if x is None else f"{x:.10g}" for x in per_seed),
                    "v_spread": (max(found) - min(found)) if per_seed and len(found) > 1
                    else None})
    return out


def write_transitions(path: str, trans: list[dict]) -> None:
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["c0", "from", "to", "v", "v_ref", "v_published",
                                           "v_spread", "v_seeds"], extrasaction="ignore")
        w.writeheader()
        for t in trans:
            w.writerow({k: ("" if val is None else (f"{val:.10g}" if isinstance(val, float)
                                                     else val)) for k, val in t.items()})


def read_transitions(path: str) -> list[dict]:
    """The rows of a ``transitions.csv`` as :func:`transitions` gives them
    (numbers as floats, empty as None)."""
    out = []
    with open(path, newline="") as fh:
        for r in csv.DictReader(fh):
            t: dict[str, Any] = {"c0": float(r.get("c0") or 0.0), "from": r["from"],
                                 "to": r["to"], "v_seeds": r.get("v_seeds", "")}
            for k in ("v", "v_ref", "v_published", "v_spread"):
                t[k] = float(r[k]) if r.get(k) else None
            out.append(t)
    return out


def references(volumes, branches=BRANCHES, modes: int | None = None,
               model: Helfrich | None = None) -> dict:
    """branch -> {v: BranchPoint} of the axisymmetric reference on ``volumes``
    (``modes`` sine modes; default :data:`phase_reference.MODES`) for the
    energy ``model`` (default ``∫H² dA``)."""
    return {b: {p.v: p for p in PR.follow(b, volumes, model, n=modes)} for b in branches}


def run(nv: int = 642, volumes=None, branches=BRANCHES, out: str = "phase_out",
        c0: float = 0.0, plot: bool = True, eigen: bool = True,
        log: Callable[[str], Any] = print, modes: int | None = None,
        method: str | None = None, min_ring: int = 3,
        seeds: tuple[int, ...] = ()) -> tuple[list[dict], list[dict]]:
    """The study (see the module docstring); returns ``(rows, transitions)``.
    ``modes``: sine modes of the references (default per branch, see
    :data:`phase_reference.MODES`; fewer for quick runs); ``c0`` the
    reduced spontaneous curvature (the references are solved at the same
    ``c0``; published transitions exist for ``c0 = 0`` only); ``method``
    the bending energy (:func:`method_for`); ``min_ring`` the fewest
    vertices on a ring of the revolved starts (:func:`solve_point`);
    ``seeds`` the perturbed starts each point is solved from again, for
    the spread of its numbers and of the transitions (:mod:`phase_spread`)."""
    c0 = float(c0)
    method = method_for(c0, method)
    model = Helfrich(c0=c0) if c0 else None
    for b in branches:
        if b not in BRANCHES:
            raise ValueError(f"unknown branch {b!r}; expected one of {BRANCHES}")
    volumes = grid() if volumes is None else np.asarray(volumes, dtype=float)
    os.makedirs(out, exist_ok=True)
    refs = references(volumes, branches, modes, model)
    rows = read_rows(os.path.join(out, "phase.csv"))
    for b in branches:
        run_branch(b, volumes, nv, out, refs[b], rows, log=log, eigen=eigen, c0=c0,
                   method=method, min_ring=min_ring, seeds=tuple(seeds))
    # the tables as written (the summary is then exactly the CSV's)
    rows = [r for r in read_rows(os.path.join(out, "phase.csv"))
            if int(r.get("nv_target", 0)) == nv and r["branch"] in branches
            and round(float(r.get("c0") or 0.0), 9) == round(c0, 9)]
    trans = transitions(rows, refs, c0, model)
    write_transitions(os.path.join(out, "transitions.csv"), trans)
    with open(os.path.join(out, "summary.md"), "w") as fh:
        fh.write(phase_plot.summary_markdown(rows, trans))
    if plot:
        phase_plot.plot(os.path.join(out, "phase"), rows, refs, trans)
    return rows, trans


def merge(sources: list[str], out: str, plot: bool = False,
          modes: int | None = None) -> tuple[list[dict], list[dict]]:
    """Combine the ``phase.csv`` of several runs (e.g. one per branch, run
    at the same time, or one branch with another ``--method``) into ``out``:
    its ``phase.csv``, ``transitions.csv`` and ``summary.md``.  With
    ``plot`` the axisymmetric references of the rows' volumes are solved
    again (``modes`` as in :func:`run`), their crossings enter
    ``transitions.csv`` and the figure is drawn (one ``c0`` per folder)."""
    rows: list[dict] = []
    for src in sources:
        rows += read_rows(os.path.join(src, "phase.csv"))
    os.makedirs(out, exist_ok=True)
    write_rows(os.path.join(out, "phase.csv"), rows)
    rows = read_rows(os.path.join(out, "phase.csv"))
    c0s = sorted({float(r.get("c0") or 0.0) for r in rows}) or [0.0]
    if plot and len(c0s) > 1:
        raise ValueError(f"rows of several c0 ({c0s}): merge them into one folder each "
                         "to draw the figure")
    trans, refs = [], None
    for c0 in c0s:
        mine = [r for r in rows if float(r.get("c0") or 0.0) == c0]
        model = Helfrich(c0=c0) if c0 else None
        if plot:
            branches = [b for b in BRANCHES if any(r["branch"] == b for r in mine)]
            volumes = sorted({float(r["v"]) for r in mine})
            refs = references(volumes, branches, modes, model)
        trans += transitions(mine, refs, c0, model)
    write_transitions(os.path.join(out, "transitions.csv"), trans)
    with open(os.path.join(out, "summary.md"), "w") as fh:
        fh.write(phase_plot.summary_markdown(rows, trans))
    if plot:
        phase_plot.plot(os.path.join(out, "phase"), rows, refs, trans)
    return rows, trans


def main(argv: list[str] | None = None) -> int:
    """``pyevolver study phase`` (see the module docstring); returns the exit code."""
    p = argparse.ArgumentParser(prog="pyevolver study phase",
                                description=__doc__.split("\n")[0])
    add_args(p)
    return run_args(p.parse_args(argv))


def add_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--nv", type=int, default=642, help="vertices per mesh (about)")
    p.add_argument("--vmin", type=float, default=0.5)
    p.add_argument("--vmax", type=float, default=0.95)
    p.add_argument("--step", type=float, default=0.025)
    p.add_argument("--volumes", default=None,
                   help="comma-separated reduced volumes (instead of the grid)")
    p.add_argument("--c0", type=float, default=0.0,
                   help="reduced spontaneous curvature C0*R0 (default 0)")
    p.add_argument("--branches", default=",".join(BRANCHES))
    p.add_argument("--method", default=None, choices=list(HZERO_METHODS),
                   help=f"bending energy (default {METHOD} at c0 = 0, {METHOD_C0} otherwise)")
    p.add_argument("--min-ring", type=int, default=3,
                   help="fewest vertices on a ring of the revolved start (default 3; more "
                        "grades the mesh in a stomatocyte's narrow neck)")
    p.add_argument("--seeds", default="",
                   help="comma-separated seeds: each point solved again from perturbed "
                        "starts (random ring rotations and vertex jitter), the spread "
                        "of W, of the stability marks and of the transitions reported")
    p.add_argument("--out", default="phase_out", help="output folder")
    p.add_argument("--no-plot", dest="plot", action="store_false")
    p.add_argument("--no-eigen", dest="eigen", action="store_false",
                   help="skip the Hessian eigenvalues")
    p.add_argument("--merge", metavar="DIR1,DIR2,...", default=None,
                   help="only combine these runs' phase.csv into --out (no solving; "
                        "the references only for the figure and their crossings, "
                        "skipped with --no-plot)")


def run_args(args: argparse.Namespace) -> int:
    if args.merge:
        rows, trans = merge(args.merge.split(","), args.out, plot=args.plot)
        _print_transitions(trans)
        return 0
    volumes = (grid(args.vmin, args.vmax, args.step) if args.volumes is None
               else [float(x) for x in args.volumes.split(",")])
    rows, trans = run(nv=args.nv, volumes=volumes,
                      branches=tuple(args.branches.split(",")), out=args.out, c0=args.c0,
                      plot=args.plot, eigen=args.eigen, method=args.method,
                      min_ring=args.min_ring,
                      seeds=tuple(int(k) for k in args.seeds.split(",") if k.strip()),
                      log=lambda t: print(t, flush=True))
    _print_transitions(trans)
    return 0 if all(r["converged"] is True for r in rows) else 1


def _print_transitions(trans):
    for t in trans:
        v = "none" if t["v"] is None else f"{t['v']:.4f}"
        vr = "none" if t["v_ref"] is None else f"{t['v_ref']:.4f}"
        pub = "none" if t["v_published"] is None else t["v_published"]
        print(f"transition {t['from']}/{t['to']}: v = {v} (reference {vr}, published {pub})")


if __name__ == "__main__":
    raise SystemExit(main())
