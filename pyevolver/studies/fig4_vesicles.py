"""The paper's Figure 4: genus-0 Canham vesicles at three reduced volumes.

Minimise the bending energy W = ∫H² dA (``H = (κ1 + κ2)/2``, a round sphere
has W = 4π) of a closed genus-0 surface at fixed area ``A = 4π`` and fixed
volume ``V = v0 · 4π/3`` (shared/papers/pl-methods-biomembranes, §3 and
Fig. 4): v0 = 0.50 (stomatocyte), 0.62 (discocyte), 0.85 (prolate).  The area
is a FIXED ``facet_area`` quantity, the volume the body's; facets carry no
tension.  Two discretisations of W, each with its cure for bad triangles:

``NormalCur+harmonic``
    ``normal_sq_mean_curvature`` (h = (3/2) F·F/F·N per vertex) plus the
    paper's harmonic energy ``λ E``, ``E = (1/√3) Σ_edges |e|²``
    (``harmonic_energy``), minimised over all vertex coordinates by damped
    Newton steps (:func:`newton_lm`), with λ lowered by a continuation
    (:func:`harmonic_continuation`) while the mesh stays healthy.
``NormalCur+harmonic+u``
    the same energy and continuation, but each λ stage alternates Newton
    solves with equiangulation ``u`` (edge flips) until a solve is followed
    by no flip (:func:`_solve_stage`): the simplicial complex, and with it
    the equilateral conformal structure the harmonic term measures against,
    follows the surface.  On the stomatocyte this lets vertices flow through
    the neck into the inner bulb; on the prolate and the discocyte no edge
    flips and the runs are those of ``NormalCur+harmonic``.
``StarPerp+Evolver recipe``
    ``star_perp_sq_mean_curvature`` (h = (3/2) F·N/N·N) with the Evolver's
    smoothing recipe: cycles of vertex averaging ``V``, equiangulation ``u``
    and a batch of ``g`` steps (``datafiles/paper/vesicle_recipe.cmd``,
    which runs unchanged in ``evolver-nox-d``).
``StarPerp+recipe+Newton``
    the same cycles with the ``g`` batch shortened to 5 steps and followed by
    two ``hessian_seek`` Newton steps (pyevolver; ``evolver-nox-d -p1``
    refuses ``hessian`` with a FIXED quantity, its ERROR 3362).

Both energies are Σ_v h_v² A_v/3 with ``A_v`` the star area, so a sphere
gives 4π (not the (2H)² convention, 16π): the same normalisation as the
axisymmetric reference :func:`pyevolver.studies.axisymmetric.canham_reference`,
against which every run is measured.

Every run starts from the shipped 162-vertex datafile
``datafiles/paper/vesicle_<shape>_<perp|normal>.fe`` (an ellipsoid, an
oblate ellipsoid, or a sphere whose top cap is pushed in; each exactly at
A = 4π and the shape's v0) and goes coarse to fine: converge, refine ``r``,
converge again, ... through 642, 2,562 (and 10,242) vertices.  A row per
resolution reports the cumulative time.

    python -m pyevolver.studies.fig4_vesicles [--size small|full] [--out DIR]
        [--max-nv N] [--methods normal,normal_u,perp,perp_newton]
        [--shapes stomatocyte,discocyte,prolate] [--no-evolver]

writes ``fig4_vesicles.csv`` (one row per method, shape and resolution,
and the references' descriptors) and ``fig4_vesicles.png`` (the final
meshes' profiles over the reference's, and the error against time).
``small`` stops at 642 vertices, ``full`` at 2,562 (``--max-nv 10242`` goes
further).  The recipe is also run in ``evolver-nox-d`` when it is
installed (``--no-evolver``: not).  Numbers and discussion: docs/paper.md.
"""
from __future__ import annotations

import argparse
import io
import os
import shutil
import subprocess
import tempfile
import time
from typing import Any, Callable

import numpy as np

from ..session.core import Session
from .axisymmetric import CanhamResult, canham_reference
from .vesicle_newton import _solve_stage, harmonic_continuation, newton_lm
from .vesicle_shapes import (LEVELS, METHODS, PAPER, RECIPE, REFERENCE_MODES, SHAPES, _profile,
                             area_volume, datafile, initial_shape, mesh_descriptors, min_angle,
                             reduced_volume, reference_descriptors, write_datafile)

__all__ = ["SHAPES", "METHODS", "LEVELS", "CHART_KEYS", "area_volume", "reduced_volume",
           "min_angle", "initial_shape", "write_datafile", "datafile", "newton_lm",
           "harmonic_continuation", "mesh_descriptors", "reference_descriptors", "reference",
           "record", "run", "run_evolver", "chart_records", "plot", "main", "_solve_stage"]


# -- runs ----------------------------------------------------------------------------------------

_REFERENCES = {}


def reference(shape: str) -> CanhamResult:
    """The axisymmetric reference (:func:`canham_reference`) of a shape, cached."""
    if shape not in _REFERENCES:
        v0, branch = SHAPES[shape]
        _REFERENCES[shape] = canham_reference(v0, branch, n=REFERENCE_MODES[shape])
    return _REFERENCES[shape]


def record(shape: str, label: str, X: np.ndarray, F: np.ndarray, W: float, area: float,
           volume: float, seconds: float, cpu_seconds: float | None, **extra: Any) -> dict:
    """One result row: energy, error against the reference, mesh health,
    descriptors (see :func:`mesh_descriptors`)."""
    v0 = SHAPES[shape][0]
    ref = reference(shape).W
    row = {"method": label, "shape": shape, "v0": v0, "resolution": len(X),
           "seconds": float(seconds),
           "cpu_seconds": None if cpu_seconds is None else float(cpu_seconds),
           "energy": float(W),
           "reference": float(ref), "rel_error": float((W - ref) / ref),
           "min_angle_deg": min_angle(X, F),
           "area_error": float(area - 4 * np.pi),
           "volume_error": float(volume - v0 * 4 * np.pi / 3)}
    row.update(mesh_descriptors(X, F))
    row.update(extra)
    return row


def _levels(max_nv, first_nv=162):
    """The resolutions of a run: ``(nv, solve)`` from 162 up to ``max_nv``,
    ``solve`` False below ``first_nv`` (those are only refined)."""
    for nv in (max_nv, first_nv):
        if nv not in LEVELS:
            raise ValueError(f"resolution {nv} is not one of {sorted(LEVELS)}")
    return [(nv, nv >= first_nv) for nv in sorted(LEVELS) if nv <= max_nv]


def _recipe_text(directory=PAPER):
    with open(os.path.join(directory, RECIPE)) as fh:
        return fh.read()


#: "normal_u": at most this many equiangulate-and-solve rounds per λ stage
FLIP_ROUNDS = 10

NEWTON_CYCLE = "cycle := { V; u; g 5; hessian_seek; hessian_seek }"


def run(shape: str, method: str, max_nv: int = 2562, first_nv: int = 162,
        directory: str = PAPER, lam_min: float = 1e-3, recipe_vars: dict | None = None,
        progress: Callable[[dict], Any] | None = None) -> tuple[Session, list[dict]]:
    """Run one method on one shape coarse to fine up to ``max_nv`` vertices.

    ``method`` is a key of :data:`METHODS`.  Returns ``(session, rows)`` with
    one :func:`record` per resolution (times cumulative from the 162-vertex
    start).  Resolutions below ``first_nv`` are only refined (the run
    starts solving at ``first_nv``).  ``recipe_vars`` overrides variables of
    the recipe (``recipe_g``, ``recipe_tol``, ``recipe_max``).  ``progress(row)``
    is called after each resolution.
    """
    if shape not in SHAPES:
        raise ValueError(f"unknown shape {shape!r}; expected one of {', '.join(SHAPES)}")
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; expected one of {', '.join(METHODS)}")
    label = METHODS[method][1]
    s = Session.load(datafile(shape, method, directory), out=io.StringIO(), err=io.StringIO())
    harmonic = method.startswith("normal")
    if not harmonic:
        s.run(_recipe_text(directory))
        for name, value in (recipe_vars or {}).items():
            s.run(f"{name} := {value!r}")
        if method == "perp_newton":
            s.run(NEWTON_CYCLE)
    rows = []
    w0, c0 = time.perf_counter(), time.process_time()
    for k, (nv, solve) in enumerate(_levels(max_nv, first_nv)):
        if k:
            s.refine(echo=False)
        if not solve:
            continue
        extra = {}
        if harmonic:
            log = []
            lam = harmonic_continuation(s, lam_min=lam_min, log=log,
                                        flips=FLIP_ROUNDS if method == "normal_u" else 0)
            kept = [r for r in log if r.get("kept", r["converged"])]
            extra = {"lambda": lam, "newton_steps": sum(r["steps"] for r in log),
                     "flips": sum(r["flips"] for r in log),
                     "converged": bool(kept),
                     "continuation": " ".join(
                         f"{r['lambda']:g}:{r['W']:.5f}/{r['min_angle_deg']:.1f}deg/"
                         f"{r['steps']}{'' if r.get('kept', r['converged']) else 'x'}"
                         + (f"/u{r['flips']}" if r["flips"] else "")
                         for r in log)}
        else:
            s.run("relax")
            extra = {"cycles": int(s.variables["recipe_cycles"])}
        t = s.totals
        row = record(shape, label, s.surface.X, s.surface.F, t.quantity_values["willmore"],
                     t.total_area, t.volumes[0], time.perf_counter() - w0,
                     time.process_time() - c0, **extra)
        rows.append(row)
        if progress is not None:
            progress(row)
    return s, rows


def run_evolver(shape: str, max_nv: int = 642, first_nv: int = 162, directory: str = PAPER,
                executable: str = "evolver-nox-d", recipe_vars: dict | None = None,
                timeout: float = 3600) -> list[dict] | None:
    """The recipe run in the Surface Evolver (``evolver-nox-d``) on the same
    shipped datafile, refined up to ``max_nv`` vertices.  Its mesh after
    each resolution is printed by the script and measured here exactly as
    pyevolver's.  Returns the rows (label "StarPerp+Evolver recipe (REF)"),
    or None when the executable is missing.
    """
    exe = shutil.which(executable)
    if exe is None:
        return None
    levels = _levels(max_nv, first_nv)
    lines = ["printf \"START %.6f\\n\", clock"]
    lines += [f"{name} := {value!r}" for name, value in (recipe_vars or {}).items()]
    for k, (nv, solve) in enumerate(levels):
        if k:
            lines.append("r")
        if not solve:
            continue
        lines += ["relax", "report",
                  ("foreach vertex vv do printf \"VX %d %.17g %.17g %.17g\\n\", "
                   "vv.id, vv.x, vv.y, vv.z"),
                  ("foreach facet ff do printf \"FC %d %d %d\\n\", ff.vertex[1].id, "
                   "ff.vertex[2].id, ff.vertex[3].id"),
                  "printf \"END\\n\""]
    script = "\n".join(lines) + "\nq\nq\n"
    with tempfile.TemporaryDirectory() as tmp:
        fe = shutil.copy(datafile(shape, "perp", directory), tmp)
        cmd = shutil.copy(os.path.join(directory, RECIPE), tmp)
        w0 = time.perf_counter()
        out = subprocess.run([exe, "-p1", "-f", os.path.basename(cmd), os.path.basename(fe)],
                             input=script, capture_output=True, text=True, cwd=tmp,
                             timeout=timeout, check=False).stdout
        wall = time.perf_counter() - w0
    rows = []
    start = None
    V, Fc, rep = {}, [], None
    for line in out.splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "START":
            start = float(parts[1])
        elif parts[0] == "FIG4" and len(parts) == 7 and parts[1].isdigit():
            rep = parts
            V, Fc = {}, []
        elif parts[0] == "VX":
            V[int(parts[1])] = [float(x) for x in parts[2:5]]
        elif parts[0] == "FC":
            Fc.append([int(x) for x in parts[1:4]])
        elif parts[0] == "END" and rep is not None:
            ids = sorted(V)
            index = {v: i for i, v in enumerate(ids)}
            X = np.array([V[v] for v in ids])
            F = np.array([[index[v] for v in f] for f in Fc])
            # the Evolver's clock: its elapsed execution time (no processor time)
            elapsed = float(rep[6]) - (start or 0.0)
            rows.append(record(shape, METHODS["perp"][1] + " (REF)", X, F, float(rep[2]),
                               float(rep[3]), float(rep[4]), elapsed, None,
                               cycles=int(rep[5])))
            rep = None
    if len(rows) != sum(solve for _, solve in levels):
        raise RuntimeError(f"{executable} did not complete the recipe on {shape} "
                           f"({len(rows)} of {len(levels)} resolutions)")
    rows[-1]["wall_seconds_total"] = wall
    return rows


# -- the study ------------------------------------------------------------------------------------

CHART_KEYS = ("method", "v0", "resolution", "seconds", "energy", "reference", "rel_error",
              "min_angle_deg")


def chart_records(full: bool = False, max_nv: int | None = None, methods=None,
                  shapes=None) -> list:
    """Rows for the accuracy-versus-time chart: one per method, shape and
    resolution (162, 642, 2,562 vertices; 10,242 too with ``full``; or up
    to ``max_nv``).

    Each dict has ``method`` (a label of :data:`METHODS`), ``v0``,
    ``resolution`` (vertex count), ``seconds`` (wall time, cumulative over
    the coarser resolutions of the run), ``energy`` (W), ``reference``
    (the axisymmetric W), ``rel_error`` ((W − W_ref)/W_ref, signed),
    ``min_angle_deg``, plus the shape and its descriptors.
    """
    if max_nv is None:
        max_nv = 10242 if full else 2562
    rows = []
    for method in (methods or list(METHODS)):
        for shape in (shapes or list(SHAPES)):
            _, r = run(shape, method, max_nv)
            rows.extend(r)
    return rows


def _write_csv(path, rows):
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with open(path, "w") as fh:
        fh.write(",".join(keys) + "\n")
        for r in rows:
            fh.write(",".join("" if r.get(k) is None else str(r.get(k)) for k in keys) + "\n")


def plot(path: str, results: dict) -> None:
    """The final meshes' profiles over the references' (one row per shape,
    one column per method) and W's relative error against time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    shapes = [s for s in SHAPES if any(k[0] == s for k in results)]
    labels, timed = [], []
    for (_, label), (mesh, _) in results.items():
        if mesh is not None and label not in labels:
            labels.append(label)
        if label not in timed:
            timed.append(label)
    fig, axes = plt.subplots(len(shapes), len(labels) + 1,
                             figsize=(3.2 * (len(labels) + 1), 3.2 * len(shapes)),
                             squeeze=False)
    for i, shape in enumerate(shapes):
        ref = reference(shape)
        zr = ref.z - 0.5 * (ref.z.max() + ref.z.min())
        lo, hi = sorted([zr[0], zr[-1]])
        if (zr.max() - hi) < (lo - zr.min()):          # deeper pole on top, as _profile
            zr = -zr
        for j, label in enumerate(labels):
            ax = axes[i, j]
            item = results.get((shape, label))
            ax.plot(ref.r, zr, "r-", lw=0.8)
            ax.plot(-ref.r, zr, "r-", lw=0.8)
            if item is not None:
                (X, F), rows = item
                r, z = _profile(X, F)
                ax.plot(np.concatenate([r, -r]), np.concatenate([z, z]), "k.", ms=1)
                last = rows[-1]
                ax.set_title(f"{label}\n{shape} {last['resolution']}: W = {last['energy']:.4f} "
                             f"({100 * last['rel_error']:+.2f}%)", fontsize=7)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_xlabel("r (distance from the axis)", fontsize=6)
            ax.set_ylabel("z (along the axis)", fontsize=6)
        ax = axes[i, -1]
        for k, label in enumerate(timed):
            item = results.get((shape, label))
            if item is None:
                continue
            rows = item[1]
            ax.loglog([r["seconds"] for r in rows], [abs(r["rel_error"]) for r in rows],
                      ["-", "--", "-.", ":"][k % 4], marker="os^Dv"[k % 5], color=f"C{k}",
                      label=label, ms=4, zorder=3 + k)
        ax.axhline(0.01, color="0.6", lw=0.5)
        ax.set_xlabel("seconds", fontsize=7)
        ax.set_ylabel("|W - W_ref| / W_ref", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.set_title(f"{shape}, v0 = {SHAPES[shape][0]}", fontsize=8)
        if i == 0:
            ax.legend(fontsize=5, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    ap = argparse.ArgumentParser(prog="python -m pyevolver.studies.fig4_vesicles",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", choices=["small", "full"], default="small",
                    help="small: up to 642 vertices; full: up to 2,562")
    ap.add_argument("--max-nv", type=int, choices=sorted(LEVELS),
                    help="finest resolution (overrides --size)")
    ap.add_argument("--methods", default=",".join(METHODS),
                    help="comma-separated keys of " + ", ".join(METHODS))
    ap.add_argument("--shapes", default=",".join(SHAPES))
    ap.add_argument("--no-evolver", action="store_true",
                    help="do not run the recipe in evolver-nox-d")
    ap.add_argument("--out", default=".")
    a = ap.parse_args(argv)
    max_nv = a.max_nv or (642 if a.size == "small" else 2562)
    methods = [m for m in a.methods.split(",") if m]
    shapes = [s for s in a.shapes.split(",") if s]
    for m in methods:
        if m not in METHODS:
            ap.error(f"unknown method {m!r}; choose from {', '.join(METHODS)}")
    for s in shapes:
        if s not in SHAPES:
            ap.error(f"unknown shape {s!r}; choose from {', '.join(SHAPES)}")
    os.makedirs(a.out, exist_ok=True)
    rows, results = [], {}

    def show(r):
        print(f"{r['method']:28s} {r['shape']:11s} {r['resolution']:6d}  W = {r['energy']:.6f}"
              f"  ({100 * r['rel_error']:+.3f}%)  {r['type']:11s} h/w {r['height_width']:.3f}"
              f"  poles {r['pole_depth_min']:.3f} {r['pole_depth_max']:.3f}"
              f"  min angle {r['min_angle_deg']:.1f}  {r['seconds']:.1f} s", flush=True)
    for shape in shapes:
        ref = reference(shape)
        d = reference_descriptors(ref)
        row = {"method": "axisymmetric reference", "shape": shape, "v0": SHAPES[shape][0],
               "resolution": ref.n, "energy": ref.W, "reference": ref.W, "rel_error": 0.0}
        row.update(d)
        rows.append(row)
        print(f"{'axisymmetric reference':28s} {shape:11s} n={ref.n:<4d} W = {ref.W:.6f}  "
              f"{d['type']:11s} h/w {d['height_width']:.3f}  poles {d['pole_depth_min']:.3f} "
              f"{d['pole_depth_max']:.3f}", flush=True)
        for m in methods:
            s, r = run(shape, m, max_nv, progress=show)
            rows.extend(r)
            results[(shape, METHODS[m][1])] = ((s.surface.X.copy(), s.surface.F.copy()), r)
        if not a.no_evolver and "perp" in methods:
            r = run_evolver(shape, max_nv)
            if r is None:
                print("evolver-nox-d not found: no reference Evolver run")
            else:
                for x in r:
                    show(x)
                rows.extend(r)
                results[(shape, r[0]["method"])] = (None, r)
    csv = os.path.join(a.out, "fig4_vesicles.csv")
    _write_csv(csv, rows)
    try:
        plot(os.path.join(a.out, "fig4_vesicles.png"), results)
    except ImportError:
        print("matplotlib not installed: no PNG")
        return 0
    print("wrote", csv, "and fig4_vesicles.png")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
