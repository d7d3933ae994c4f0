"""The paper's Figure 3 and Proposition 1: the genus-1 Willmore problem with
harmonic-energy regularization, a continuation in λ, and the Evolver's recipe.

The Willmore problem on a regular torus (radii √2 and 1, area fixed at its
initial value: W is scale invariant, the area fixes the scale) is solved
with the paper's two energies (shared/papers/pl-methods-biomembranes, §2–3):

============  ====================================  ===========================
label         pyevolver / Evolver method            paper
============  ====================================  ===========================
EffArea       ``eff_area_sq_mean_curvature``        W_EffAreaCur, h = 3|F|/(2|N|)
NormalCur     ``normal_sq_mean_curvature``          W_NormalCur, h = 3F·F/(2F·N)
============  ====================================  ===========================

(F the area gradient, N the volume gradient at a vertex; E_v = h² A_v/3.)
The paper names them after the Evolver manual's "effective area" and "normal"
curvatures; on a closed surface without ``h_zero`` the ``star_`` variants are
the same numbers (checked against evolver-nox-d: 20.892197778481 for both
spellings of the normal energy on the 10×16 grid), and the plain spellings
also run in the Evolver, whose manual lists them with ``g`` only.

Runs (every one from the datafiles in ``datafiles/paper/`` and the command
scripts there, which a user can run by hand):

(a) unregularized: ``fig3_newton.cmd`` on ``torus*_offset_<energy>.fe``;
(b) W + λE at fixed λ, E = ``harmonic_energy`` = (1/√3) Σ_e |e|²:
    ``fig3_newton.cmd`` on ``*_harmonic.fe`` after ``harmonic.modulus := λ``;
(c) continuation in λ: ``fig3_continuation.cmd`` (λ lowered by 0.7 per stage
    while the smallest angle stays ≥ 10°, stopped by the Loop-energy guide);
(c') the consistency rule for λ, the procedure ``consistency`` of the same
    script: λ lowered while W > W_Loop, then the crossing W = W_Loop
    bisected in log λ; the healthy stage where they agree best is kept;
(d) the Evolver's recipe, ``fig3_evolver_recipe.cmd`` (``g 20; V; u; n 1.0;
    g 20`` per round), run in pyevolver and in evolver-nox-d.

Minimizer: ``newton`` (damped Newton with the exact Hessian on all three
coordinates of every vertex; :mod:`pyevolver.evolve.newton`).  Plain Newton
(``hessian``) cannot be used: the Hessian is singular along the rigid motions
(and along scaling without the area constraint) and nearly singular,
indefinite along tangential motions and the Möbius directions W is invariant
under; the damping δI makes these harmless and the ratio test keeps every
step a descent step.

Meshes: ``torus_offset`` (offset rows) for (a)–(d); the paper's one-diagonal
``torus_grid`` for (b) as well, where the regularized minimizers are not
tori of revolution (the equilateral conformal structure of that grid is a
sheared lattice, see :func:`~pyevolver.studies.meshes.torus_offset`).

Measured per run: W (the discrete energy minimized, without λE), its relative
error to 2π², W_Loop (the true Willmore energy of the Loop subdivision
surface of the final mesh, :mod:`pyevolver.geometry.loop`, ≥ 2π² for every torus),
the radius ratio R/r (:func:`radius_ratio`), the smallest facet angle, wall
seconds and iterations.

Proposition 1: :func:`almost_spherical_torus` and :func:`proposition1`.

    python -m pyevolver.studies.fig3_torus [--size small|full] [--out DIR]
        [--meshes 20x32,40x64] [--runs continuation,recipe] [--no-evolver]

(``--meshes`` runs the listed grids instead of a size's, ``--runs`` a subset
of unregularized, fixed, continuation, consistency, recipe; ``python -m
pyevolver.studies.doc_numbers --merge DIR`` then puts the rows into the
CSVs in ``docs/``) writes ``fig3_torus.csv`` (one row per run), ``fig3_stages.csv`` (the
continuation stages), ``fig3_recipe.csv`` (the recipe, both programs, per
round), ``fig3_prop1.csv``, ``fig3_chart.csv`` (the :func:`chart_records` of
these runs) and ``fig3_torus.png``.
"""
from __future__ import annotations

import argparse
import csv
import io
import math
import os
import re
import shutil
import subprocess
import tempfile
import time
from typing import Any
import warnings

import numpy as np
from scipy.optimize import minimize

from ..errors import UnsupportedError
from ..geometry.loop import LoopEvaluator
from ..session.core import Session
from .meshes import _outward, torus_grid, torus_offset, write_fe

HERE = os.path.dirname(os.path.abspath(__file__))
PAPER = os.path.join(HERE, "..", "..", "datafiles", "paper")
CLIFFORD = 2 * math.pi ** 2
ENERGIES = {"EffArea": "eff_area_sq_mean_curvature", "NormalCur": "normal_sq_mean_curvature"}
SHORT = {"EffArea": "eff_area", "NormalCur": "normal"}
LAMBDA_DEFAULT = 0.25
# mesh sizes (minor × major grid points); the offset grid needs an even major count
SIZES = {"small": [(5, 10), (10, 16)], "full": [(5, 10), (10, 16), (20, 32), (40, 64)]}
FIXED_LAMBDAS = [1.0, 0.5, 0.25, 0.12]
# the runs of the study, in order (the --runs choices)
RUNS = ("unregularized", "fixed", "continuation", "consistency", "recipe")


# -- meshes and datafiles -------------------------------------------------------------------

def _mesh(m, n, grid):
    if grid == "offset":
        return torus_offset(m, n, R=math.sqrt(2.0), r=1.0)
    if grid == "paper":
        return torus_grid(m, n, R=math.sqrt(2.0), r=1.0)
    raise ValueError(f"unknown grid {grid!r} (offset or paper)")


def datafile(m: int, n: int, energy: str, regularized: bool, grid: str = "offset",
             directory: str | None = None) -> str:
    """Path of the datafile for an ``m``×``n`` torus with ``energy`` (EffArea
    or NormalCur), with ``harmonic_energy`` (λ = 0.25, the quantity
    ``harmonic``) and the ``loop_w`` info quantity when ``regularized``.

    The shipped file in ``datafiles/paper/`` is used when it exists; other
    sizes are written to ``directory`` (default: ``datafiles/paper``).
    Names: ``torus{m}x{n}[_offset]_{eff_area|normal}[_harmonic].fe``.
    """
    tag = "_offset" if grid == "offset" else ""
    name = f"torus{m}x{n}{tag}_{SHORT[energy]}{'_harmonic' if regularized else ''}.fe"
    shipped = os.path.join(PAPER, name)
    if os.path.exists(shipped):
        return shipped
    path = os.path.join(directory or PAPER, name)
    if os.path.exists(path):
        return path
    os.makedirs(os.path.dirname(path), exist_ok=True)
    X, F = _mesh(m, n, grid)
    a, b = X[F[:, 1]] - X[F[:, 0]], X[F[:, 2]] - X[F[:, 0]]
    area = float(0.5 * np.linalg.norm(np.cross(a, b), axis=1).sum())
    kind = ("offset rows (torus_offset)" if grid == "offset"
            else "one diagonal direction (torus_grid, as Figure 1)")
    lines = [f"// The regular {m}x{n} torus of the paper's Figure 3 (radii sqrt 2 and 1),",
             f"// {kind}; every vertex of valence 6.",
             f"// Energy: {ENERGIES[energy]} (the paper's W_{energy}); facets carry no",
             "// tension; the area is fixed at its initial value (W is scale invariant).",
             "// Written by pyevolver.studies.fig3_torus."]
    if regularized:
        lines += ["// Regularized: + lambda * harmonic_energy, the paper's",
                  "// E = (1/sqrt 3) sum |e|^2;",
                  "// lambda is the modulus of the quantity harmonic (harmonic.modulus := 0.1).",
                  "// loop_w (info only) is the Willmore energy of the Loop subdivision surface.",
                  "// pyevolver only: Surface Evolver has neither method."]
    else:
        lines += ["// Runs in pyevolver and in Surface Evolver 2.70."]
    lines.append(f"quantity willmore energy method {ENERGIES[energy]} global")
    if regularized:
        lines.append(f"quantity harmonic energy modulus {LAMBDA_DEFAULT} "
                     "method harmonic_energy global")
    lines.append(f"quantity area_fix fixed = {area!r} method facet_area global")
    if regularized:
        lines.append("quantity loop_w info_only method loop_sq_mean_curvature global")
    write_fe(path, X, F, header="\n".join(lines), face_attrs="tension 0")
    return path


# -- measurements -----------------------------------------------------------------------------

def min_angle(X: np.ndarray, F: np.ndarray) -> float:
    """Smallest corner angle of the triangles ``F`` (nf, 3) of ``X`` (nv, 3), degrees."""
    P = X[F]
    e = [P[:, (k + 2) % 3] - P[:, (k + 1) % 3] for k in range(3)]      # side opposite k
    L = np.stack([np.linalg.norm(v, axis=1) for v in e], 1)
    ang = []
    for k in range(3):
        b, c = L[:, (k + 1) % 3], L[:, (k + 2) % 3]
        with np.errstate(all="ignore"):
            cosk = (b * b + c * c - L[:, k] ** 2) / (2 * b * c)
        ang.append(np.arccos(np.clip(np.nan_to_num(cosk, nan=1.0), -1.0, 1.0)))
    return float(np.degrees(np.min(ang)))


def radius_ratio(X: np.ndarray) -> tuple[float, float]:
    """Radius ratio ``R/r`` of a torus of revolution fitted to the vertices.

    The axis is the direction of least spread of the vertices about their
    centroid (smallest eigenvalue of Σ (x − c)(x − c)ᵀ); each vertex gives
    (ρ, z), its distance from the axis and its height along it, and a circle
    (ρ − R)² + (z − z0)² = r² is fitted to these points by linear least
    squares (Kåsa 1976).  Returns ``(R/r, dev)`` with ``dev`` the root mean
    square distance of the points from the circle divided by r: small for a
    torus of revolution, large for shapes that are not (e.g. cyclides, the
    Möbius images of tori, which have the same Willmore energy).
    """
    c = X.mean(axis=0)
    Y = X - c
    _, V = np.linalg.eigh(Y.T @ Y)
    axis = V[:, 0]
    z = Y @ axis
    rho = np.linalg.norm(Y - np.outer(z, axis), axis=1)
    M = np.column_stack([2 * rho, 2 * z, np.ones_like(rho)])
    R, z0, k = np.linalg.lstsq(M, rho ** 2 + z ** 2, rcond=None)[0]
    r = math.sqrt(k + R * R + z0 * z0)
    dev = np.sqrt(np.mean((np.hypot(rho - R, z - z0) - r) ** 2)) / r
    return float(R / r), float(dev)


def special_conformal(X: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The Möbius transformation x ↦ (x + b|x|²)/(1 + 2 b·x + |b|²|x|²)
    (inversion, translation by b, inversion; the identity at b = 0)."""
    b = np.asarray(b, float)
    x2 = np.einsum("ij,ij->i", X, X)
    den = 1.0 + 2.0 * (X @ b) + (b @ b) * x2
    return (X + np.outer(x2, b)) / den[:, None]


def moebius_radius_ratio(X: np.ndarray, starts: int = 16,
                         seed: int = 0) -> tuple[float, float, np.ndarray]:
    """:func:`radius_ratio` of the Möbius image of ``X`` that is closest to a
    torus of revolution.

    The Willmore energy is Möbius invariant, so its minimizers among tori
    are the Clifford torus (R/r = √2) and its Möbius images (cyclides, for
    which the plain fit fails; R/r is the same for every torus of
    revolution in one Möbius orbit, the inversive distance 2(R/r)² − 1 of
    two opposite meridian circles being invariant).  The vertices, centred
    and scaled to unit rms radius, are moved by :func:`special_conformal`
    with the ``b`` that minimizes the squared fit deviation among ring fits
    with R/r > 1.1 (near-horn fits of a nearly spherical image are spurious
    and, on coarse or noisy meshes, can fit as well as the true one: trust
    the result only when its deviation is far below the plain fit's), by BFGS
    from b = 0 and ``starts`` seeded random points
    (|b| ≈ 0.3); similarities do not change the fit, and with these
    transformations they give every orientation-preserving Möbius
    transformation.  Returns ``(R/r, dev, b)``; checked on inverted tori
    (tests/studies/test_fig3_torus.py).
    """

    Y = X - X.mean(axis=0)
    Y = Y / math.sqrt(np.mean(np.einsum("ij,ij->i", Y, Y)))

    def dev2(b):
        with np.errstate(all="ignore"):
            Z = special_conformal(Y, b)
        if not np.all(np.isfinite(Z)) or np.max(np.abs(Z)) > 1e6:
            return 1e6
        ratio, d = radius_ratio(Z)
        return d * d if ratio > 1.1 else 1e6
    rng = np.random.default_rng(seed)
    best = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for x0 in [np.zeros(3)] + [0.3 * rng.standard_normal(3) for _ in range(starts)]:
            r = minimize(dev2, x0, method="BFGS", options={"gtol": 1e-12})
            if best is None or r.fun < best.fun:
                best = r
            if best.fun < 1e-14:
                break
    if not best.fun < 1e6:
        return radius_ratio(Y) + (np.zeros(3),)
    ratio, d = radius_ratio(special_conformal(Y, best.x))
    return ratio, d, best.x


def loop_energy(X: np.ndarray, F: np.ndarray) -> float:
    """Willmore energy ∫H² dA of the Loop subdivision surface of ``(X, F)``;
    NaN when the Loop methods refuse the mesh (valence above 12, which edge
    flips can produce)."""
    try:
        return float(LoopEvaluator(F, len(X)).totals(X)["W"])
    except UnsupportedError:
        return math.nan


def measure(session: Session, moebius: bool = True) -> dict:
    """W (the quantity willmore), relative error, W_Loop, R/r of the fitted
    torus of revolution and the fit's deviation (``revolution_dev``: how far
    the mesh is from a torus of revolution, :func:`radius_ratio`), the same
    after Möbius normalization (``R_over_r_moebius``, ``moebius_dev``:
    :func:`moebius_radius_ratio`, meaningful when that deviation is much
    smaller than the plain one, i.e. for a cyclide), smallest angle and vertex
    count of the session's surface (without ``moebius`` the normalized fit
    is NaN)."""
    s = session.surface
    W = float(session.totals.quantity_values["willmore"])
    plain, plain_dev = radius_ratio(s.X)
    ratio, dev, _ = moebius_radius_ratio(s.X) if moebius else (math.nan, math.nan, None)
    WL = loop_energy(s.X, s.F)
    return {"vertices": int(s.nv), "W": W, "rel_error": W / CLIFFORD - 1.0, "W_loop": WL,
            "loop_rel_error": WL / CLIFFORD - 1.0, "R_over_r": plain,
            "revolution_dev": plain_dev, "R_over_r_moebius": ratio, "moebius_dev": dev,
            "min_angle_deg": min_angle(s.X, s.F)}


# -- running the shipped scripts ------------------------------------------------------------

def script(name: str, call: str | None = None) -> str:
    """Text of ``datafiles/paper/<name>`` with its default run (the line
    ending in ``// default run``) replaced by ``call`` when given."""
    with open(os.path.join(PAPER, name)) as fh:
        lines = fh.read().splitlines()
    if call is not None:
        lines = [call if ln.rstrip().endswith("// default run") else ln for ln in lines]
    return "\n".join(lines) + "\n"


_PROGRESS = re.compile(r"^\s*-?\d+\. area: .* (energy|delta): ")


def run_pyevolver(path: str, text: str, before: str = "",
                  where: str = "<script>") -> tuple[Session, list[str], float, int]:
    """Load ``path`` and run ``before`` and the script ``text`` (named
    ``where`` in messages) in pyevolver; returns (session, output lines,
    wall seconds, progress lines printed)."""
    out = io.StringIO()
    s = Session.load(path, out=out, err=io.StringIO())
    t0 = time.perf_counter()
    if before:
        s.run(before)
    s.run(text, where=where)
    dt = time.perf_counter() - t0
    lines = out.getvalue().splitlines()
    return s, lines, dt, sum(1 for ln in lines if _PROGRESS.match(ln))


def run_evolver(path: str, text: str,
                exe: str = "evolver-nox-d") -> tuple[list[str], float] | None:
    """Run the script ``text`` on ``path`` in the reference Evolver; returns
    (output lines, wall seconds), or None when it is not installed."""
    if shutil.which(exe) is None:
        return None
    with tempfile.TemporaryDirectory() as tmp:
        cmd = os.path.join(tmp, "run.cmd")
        with open(cmd, "w") as fh:
            fh.write(text + "q\nq\n")
        t0 = time.perf_counter()
        p = subprocess.run([exe, "-p1", "-f", cmd, path], stdin=subprocess.DEVNULL,
                           capture_output=True, text=True, timeout=3600, check=False)
        dt = time.perf_counter() - t0
    return p.stdout.splitlines(), dt


def _fields(line):
    """The ``key value`` pairs of a script's report line as a dict: ``stage 3
    lambda 0.1 W 20.1 ... healthy`` gives stage, lambda, W, ... and status
    (the trailing word); a leading ``result`` is dropped."""
    w = line.split()
    out = {}
    if w and w[0] == "result":
        w = w[1:]
    if len(w) % 2:                            # a trailing flag (healthy / undone)
        out["status"] = w.pop()
    for k, v in zip(w[0::2], w[1::2]):
        try:
            out[k] = float(v)
        except ValueError:
            out[k] = v
    return out


# -- the runs -----------------------------------------------------------------------------------

def newton_run(m: int, n: int, energy: str, lam: float | None = None, grid: str = "offset",
               steps: int = 300, directory: str | None = None, moebius: bool = True) -> dict:
    """(a) with ``lam`` None, else (b): ``fig3_newton.cmd``.  Returns a row dict
    (:func:`measure`)."""
    path = datafile(m, n, energy, lam is not None, grid, directory)
    before = "" if lam is None else f"harmonic.modulus := {lam!r}"
    s, _, dt, its = run_pyevolver(path, script("fig3_newton.cmd", f"minimize({steps})"),
                                  before, "fig3_newton.cmd")
    label = energy + ("" if lam is None else f"+harmonic(λ={lam:g})")
    if grid != "offset":
        label += f" [{grid} grid]"
    row = {"label": label, "energy": energy, "grid": grid, "mesh": f"{m}x{n}",
           "lambda": 0.0 if lam is None else lam, "minimizer": "newton", "iterations": its,
           "seconds": dt}
    row.update(measure(s, moebius))
    return row


def continuation_run(m: int, n: int, energy: str, grid: str = "offset", lam0: float = 0.25,
                     factor: float = 0.7, lammin: float = 1e-3, steps: int = 100,
                     maxrises: int = 2, directory: str | None = None, moebius: bool = True,
                     rule: str = "loop", nbis: int = 8) -> tuple[dict, list[dict]]:
    """(c): ``fig3_continuation.cmd``.  Returns (row, stages).

    ``rule``: ``"loop"`` keeps the stage with the lowest Loop energy (the
    procedure ``continuation``, ``maxrises`` stages without a new lowest
    stop it); ``"consistency"`` keeps the healthy stage where the discrete W
    and the Loop energy agree best (the procedure ``consistency``: λ lowered
    by ``factor`` while W > W_Loop, then ``nbis`` bisections in log λ of the
    bracket where W − W_Loop changes sign).
    """
    path = datafile(m, n, energy, True, grid, directory)
    if rule == "loop":
        call = f"continuation({lam0!r}, {factor!r}, {lammin!r}, {steps}, {maxrises})"
    elif rule == "consistency":
        call = f"consistency({lam0!r}, {factor!r}, {lammin!r}, {steps}, {nbis})"
    else:
        raise ValueError(f"unknown rule {rule!r} (loop or consistency)")
    s, lines, dt, its = run_pyevolver(path, script("fig3_continuation.cmd", call),
                                      where="fig3_continuation.cmd")
    stages = [dict(_fields(ln), mesh=f"{m}x{n}", energy=energy, grid=grid, rule=rule)
              for ln in lines if ln.startswith("stage ")]
    res = [_fields(ln) for ln in lines if ln.startswith("result ")]
    if not res:
        raise RuntimeError(f"{path}: the continuation printed no result:\n" + "\n".join(lines))
    label = energy + ("+harmonic(cont.)" if rule == "loop" else "+harmonic(W=W_Loop)")
    row = {"label": label, "energy": energy, "grid": grid,
           "mesh": f"{m}x{n}", "lambda": res[-1]["lambda"], "minimizer": "newton",
           "iterations": its, "seconds": dt}
    row.update(measure(s, moebius))
    return row, stages


def recipe_run(m: int, n: int, energy: str, rounds: int = 50, gsteps: int = 20,
               evolver: bool = True, directory: str | None = None,
               moebius: bool = True) -> tuple[list[dict], list[dict]]:
    """(d): ``fig3_evolver_recipe.cmd`` in pyevolver and (when installed and
    ``evolver``) in evolver-nox-d.  Returns (rows, per-round records)."""
    path = datafile(m, n, energy, False, "offset", directory)
    text = script("fig3_evolver_recipe.cmd", f"recipe({rounds}, {gsteps})")
    s, lines, dt, _ = run_pyevolver(path, text, where="fig3_evolver_recipe.cmd")
    rounds_py = [dict(_fields(ln), program="pyevolver") for ln in lines
                 if ln.startswith("round ")]
    row = {"label": energy + " Evolver recipe (g,V,u,n)", "energy": energy, "grid": "offset",
           "mesh": f"{m}x{n}", "lambda": 0.0, "minimizer": "g+V+u+n", "program": "pyevolver",
           "iterations": 2 * gsteps * rounds, "seconds": dt}
    row.update(measure(s, moebius))
    rows, recs = [row], rounds_py
    ref = run_evolver(path, text) if evolver else None
    if ref is not None:
        rlines, rdt = ref
        rr = [dict(_fields(ln), program="evolver") for ln in rlines if ln.startswith("round ")]
        if rr:
            last = rr[-1]
            rows.append({"label": row["label"], "energy": energy, "grid": "offset",
                         "mesh": f"{m}x{n}", "lambda": 0.0, "minimizer": "g+V+u+n",
                         "program": "evolver-nox-d", "iterations": 2 * gsteps * rounds,
                         "seconds": rdt, "vertices": int(last["vertices"]), "W": last["W"],
                         "rel_error": last["W"] / CLIFFORD - 1.0,
                         "min_angle_deg": last["minangle"]})
            recs = recs + rr
    for r in recs:
        r.update(mesh=f"{m}x{n}", energy=energy)
    return rows, recs


# -- Proposition 1 ------------------------------------------------------------------------------

def almost_spherical_torus(m: int, n: int, eps: float) -> tuple[np.ndarray, np.ndarray]:
    """A regular ``m``×``n`` torus (the connectivity of
    :func:`~pyevolver.studies.meshes.torus_grid`) with every vertex on the
    unit sphere and a hole of diameter 2ε along the z axis.

    Vertex ``(i, j)`` is at polar angle α_i = α0 + (π − 2α0) i/(m − 1),
    sin α0 = ε, and azimuth 2πj/n: the meridian circle of the torus is a
    half great circle from the ring of radius ε near the north pole to the
    one near the south pole, closed by a straight segment through the hole
    (a thin tube of facets of radius ε along the axis).  This is our
    construction of the paper's "almost spherical tori" T_{m,n,ε}
    (Proposition 1; the paper's proof is in its journal version).

    Returns ``X (m n, 3)``, ``F (2 m n, 3)`` oriented outward.
    """
    if not 0 < eps < 1:
        raise ValueError("eps must lie in (0, 1)")
    _, F = torus_grid(m, n)
    k = np.arange(m * n)
    i, j = k % m, k // m
    a0 = math.asin(eps)
    al = a0 + (math.pi - 2 * a0) * i / (m - 1)
    th = 2 * np.pi * j / n
    X = np.stack([np.sin(al) * np.cos(th), np.sin(al) * np.sin(th), np.cos(al)], 1)
    return X, _outward(X, F)


def bobenko_energy(X: np.ndarray, F: np.ndarray) -> float:
    """``circle_willmore`` (Bobenko's W = Σ_e β_e − π #V) of a closed mesh,
    evaluated by pyevolver's quantity method."""
    with tempfile.TemporaryDirectory() as tmp:
        path = write_fe(os.path.join(tmp, "t.fe"), X, F, face_attrs="tension 0",
                        header="quantity wb energy method circle_willmore global")
        return float(Session.load(path, out=io.StringIO()).total_energy)


def proposition1(grids: tuple = ((5, 10), (10, 20), (20, 40)),
                 eps: tuple = (0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 1e-3, 1e-4)) -> list[dict]:
    """Bobenko energies of :func:`almost_spherical_torus` for each grid size
    and hole size: a list of dicts (m, n, eps, W_bobenko, excess over 4π)."""
    rows = []
    for m, n in grids:
        for e in eps:
            W = bobenko_energy(*almost_spherical_torus(m, n, e))
            rows.append({"m": m, "n": n, "eps": e, "W_bobenko": W, "minus_4pi": W - 4 * math.pi})
    return rows


# -- the chart ----------------------------------------------------------------------------------

def chart_records(full: bool = False, directory: str | None = None, evolver: bool = False,
                  sizes: list | None = None, rounds: int | None = None) -> list[dict]:
    """Points for the accuracy-versus-time chart: one per method and mesh
    resolution (5×10, 10×16 with ``full`` False; also 20×32 and 40×64).

    Each record: ``method`` (label), ``resolution`` (vertex count of the
    starting mesh; the recipe's notching adds vertices),
    ``seconds`` (wall time of the run), ``energy`` (the discrete W at the
    end), ``reference`` (2π²), ``rel_error`` (|W − 2π²|/2π²),
    ``min_angle_deg``.  Methods: the continuation (c) for both energies
    (label ``<energy>+harmonic(cont.)``, plus ``... Loop W`` with the Loop
    surface's energy of the same mesh), the Evolver's recipe (d) in pyevolver
    and, with ``evolver``, in evolver-nox-d.  ``sizes``: the (m, n) grids
    instead (e.g. ``[(5, 10)]`` for the chart CI regenerates); ``rounds``
    the recipe's rounds (default 50, 30 from 20×32 up).
    """
    directory = directory or tempfile.mkdtemp(prefix="fig3_")
    out = []
    for m, n in sizes or SIZES["full" if full else "small"]:
        for energy in ENERGIES:
            row, _ = continuation_run(m, n, energy, directory=directory, moebius=False)
            out.append(_record(row["label"], row))
            out.append(_record(row["label"] + " Loop W", dict(row, W=row["W_loop"])))
            rows, _ = recipe_run(m, n, energy, rounds=rounds or _recipe_rounds(m), evolver=evolver,
                                 directory=directory, moebius=False)
            for r in rows:
                lab = r["label"] + (" [evolver-nox-d]" if r["program"] != "pyevolver" else "")
                out.append(_record(lab, r))
    return out


def _recipe_rounds(m):
    return 50 if m <= 20 else 30


def _record(method, row):
    m, n = (int(v) for v in row["mesh"].split("x"))
    return {"method": method, "resolution": m * n, "seconds": float(row["seconds"]),
            "energy": float(row["W"]), "reference": CLIFFORD,
            "rel_error": abs(float(row["W"]) / CLIFFORD - 1.0),
            "min_angle_deg": float(row["min_angle_deg"])}


# -- the study ----------------------------------------------------------------------------------

def _write_csv(path, rows):
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)


def _line(r):
    parts = [f"{r['label']:36s} {r['mesh']:6s} {r.get('program', 'pyevolver'):13s}",
             f"W {r['W']:.6f} ({100 * r['rel_error']:+.3f}%)"]
    if "W_loop" in r:
        parts.append(f"Loop {r['W_loop']:.5f} ({100 * r['loop_rel_error']:+.3f}%)")
    if "R_over_r" in r:
        parts.append(f"R/r {r['R_over_r']:.4f} (dev {r['revolution_dev']:.1e}; "
                     f"Möbius-normalized {r['R_over_r_moebius']:.4f}, "
                     f"dev {r['moebius_dev']:.1e})")
    parts.append(f"min angle {r['min_angle_deg']:.3g}°  {r['iterations']} its  "
                 f"{r['seconds']:.1f} s")
    return "  ".join(parts)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", choices=("small", "full"), default="small")
    ap.add_argument("--out", default=".")
    ap.add_argument("--no-evolver", action="store_true",
                    help="do not run the recipe in evolver-nox-d")
    ap.add_argument("--meshes", default=None,
                    help="comma-separated grids instead of --size's, e.g. 20x32,40x64")
    ap.add_argument("--runs", default=",".join(RUNS),
                    help=f"comma-separated subset of {','.join(RUNS)} (default: all)")
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    full = a.size == "full"
    sizes = SIZES[a.size]
    if a.meshes:
        sizes = [tuple(int(v) for v in g.split("x")) for g in a.meshes.split(",")]
        full = True
    runs = set(a.runs.split(","))
    if runs - set(RUNS):
        ap.error(f"unknown runs {sorted(runs - set(RUNS))} (choose from {', '.join(RUNS)})")
    rows, stages, recs = [], [], []

    def show(r, key=None, s=None):
        rows.append(r)
        print(_line(r), flush=True)

    for m, n in sizes:
        for energy in ENERGIES:
            if m <= 20 and "unregularized" in runs:                          # (a)
                show(newton_run(m, n, energy, None, directory=a.out))
            if ((m, n) == (10, 16) or (full and (m, n) == (20, 32))) and "fixed" in runs:
                for lam in FIXED_LAMBDAS:                                    # (b)
                    show(newton_run(m, n, energy, lam, directory=a.out))
                    if (m, n) == (10, 16):
                        show(newton_run(m, n, energy, lam, grid="paper", directory=a.out))
            if "continuation" in runs:                                       # (c)
                row, st = continuation_run(m, n, energy, directory=a.out)
                show(row)
                stages += st
            if "consistency" in runs:                                        # (c')
                row, st = continuation_run(m, n, energy, directory=a.out, rule="consistency")
                show(row)
                stages += st
            if "recipe" in runs:                                             # (d)
                rr, rc = recipe_run(m, n, energy, rounds=_recipe_rounds(m),
                                    evolver=not a.no_evolver, directory=a.out)
                for r in rr:
                    show(r)
                recs += rc
    prop = proposition1()
    print(f"2 pi^2 = {CLIFFORD:.6f}, 4 pi = {4 * math.pi:.6f}")
    for p in prop:
        if p["eps"] in (0.5, 0.1, 0.01, 1e-4):
            print(f"Proposition 1: {p['m']}x{p['n']} eps {p['eps']:g}: W_Bobenko = "
                  f"{p['W_bobenko']:.9f} (4 pi + {p['minus_4pi']:.3e})")
    _write_csv(os.path.join(a.out, "fig3_torus.csv"), rows)
    _write_csv(os.path.join(a.out, "fig3_stages.csv"), stages)
    _write_csv(os.path.join(a.out, "fig3_recipe.csv"), recs)
    _write_csv(os.path.join(a.out, "fig3_prop1.csv"), prop)
    chart = [_record(r["label"] + ("" if r.get("program", "pyevolver") == "pyevolver"
                                   else " [evolver-nox-d]"), r)
             for r in rows if r["label"].endswith(("(cont.)", "(W=W_Loop)", "(g,V,u,n)"))]
    chart += [_record(r["label"] + " Loop W", dict(r, W=r["W_loop"]))
              for r in rows if r["label"].endswith("(cont.)")]
    _write_csv(os.path.join(a.out, "fig3_chart.csv"), chart)
    _plot(os.path.join(a.out, "fig3_torus.png"), rows, stages, prop)
    print("wrote", os.path.join(a.out, "fig3_torus.csv"), "and the others")
    return 0


def _plot(path, rows, stages, prop):
    try:
        fig = figure(stages, prop)
    except ImportError:
        print("matplotlib not installed: no PNG")
        return
    import matplotlib.pyplot as plt
    fig.savefig(path, dpi=100)
    plt.close(fig)


def figure(stages: list, prop: list) -> Any:
    """The study's figure (a matplotlib Figure): W and W_Loop, and the
    smallest angle, against λ along the Loop-guided continuations
    (``stages``), and Proposition 1 (``prop``)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter
    fig, ax = plt.subplots(1, 3, figsize=(16, 5.2))
    marks = "os^Dv"
    lams, errs = set(), []
    for k, ((mesh, energy), grp) in enumerate(_groups(stages).items()):
        grp = sorted(grp, key=lambda s: s["lambda"])
        lam = [s["lambda"] for s in grp]
        lams.update(lam)
        c, mk = f"C{k % 10}", marks[k % len(marks)]
        w = [100 * (s["W"] / CLIFFORD - 1) for s in grp]
        wl = [100 * (s["loop_w"] / CLIFFORD - 1) for s in grp]
        errs += w + wl
        ax[0].semilogx(lam, w, "-", marker=mk, color=c, label=f"{energy} {mesh}: W",
                       zorder=3 + k)
        ax[0].semilogx(lam, wl, "--", marker=mk, mfc="none", color=c,
                       label=f"{energy} {mesh}: W_Loop", zorder=3 + k)
        ax[1].semilogx(lam, [s["minangle"] for s in grp], "-", marker=mk, color=c,
                       label=f"{energy} {mesh}", zorder=3 + k)
    for a in ax[:2]:                          # the stages' λ as plain tick labels
        ticks = sorted(lams)
        a.set_xticks(ticks)
        a.set_xticklabels([f"{t:.3g}" for t in ticks], rotation=45, fontsize=7)
        a.xaxis.set_minor_formatter(NullFormatter())
        a.grid(True, alpha=0.3)
    ax[0].axhline(0, color="k", lw=0.5, zorder=1)
    ax[0].set_xlabel("λ")
    ax[0].set_ylabel("error to 2π² (%)")
    if errs:
        lo, hi = min(errs), max(errs)
        pad = 0.05 * (hi - lo or 1.0)
        ax[0].set_ylim(lo - pad, hi + pad)
    ax[0].set_title("W (solid) and W_Loop (dashed) along the continuation", fontsize=10)
    ax[0].legend(fontsize=6, ncol=2)
    ax[1].axhline(10, color="r", lw=0.6, zorder=1, label="10°: a stage below is undone")
    ax[1].set_xlabel("λ")
    ax[1].set_ylabel("smallest angle (°)")
    ax[1].set_title("smallest facet angle of the healthy stages", fontsize=10)
    ax[1].legend(fontsize=6)
    grids = sorted({(p["m"], p["n"]) for p in prop})
    for k, (m, n) in enumerate(grids):        # the grids' curves nearly coincide: all visible
        pp = [p for p in prop if (p["m"], p["n"]) == (m, n)]
        ax[2].loglog([p["eps"] for p in pp], [p["minus_4pi"] for p in pp],
                     ["-", "--", ":"][k % 3], marker=marks[k % len(marks)],
                     ms=9 - 2.5 * k, mfc="none" if k == 0 else None, lw=2.5 - 0.7 * k,
                     label=f"{m}x{n}", zorder=3 + k)
    ax[2].set_xlabel("hole size ε")
    ax[2].set_ylabel("W_Bobenko − 4π")
    ax[2].set_title("Proposition 1: almost spherical tori", fontsize=10)
    ax[2].grid(True, which="both", alpha=0.3)
    ax[2].legend(fontsize=7)
    fig.tight_layout()
    return fig


def _groups(stages):
    g = {}
    for s in stages:
        if s.get("status") == "healthy" and s.get("rule", "loop") == "loop":
            g.setdefault((s["mesh"], s["energy"]), []).append(s)
    return g


if __name__ == "__main__":
    raise SystemExit(main())
