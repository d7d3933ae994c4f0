"""Accuracy against time: the chart the users asked for (issue 7).

Relative energy error against wall time, log-log, one curve per method
(discretization × smoothing or regularization), one point per mesh
resolution.  The points come from the studies' ``chart_records``:

* :func:`pyevolver.studies.fig3_torus.chart_records` — the genus-1 Willmore
  problem; the error is against 2π² (Marques–Neves);
* :func:`pyevolver.studies.fig4_vesicles.chart_records` — the genus-0
  Canham problem at reduced volumes 0.50 / 0.62 / 0.85; the error is
  against the axisymmetric reference
  (:func:`pyevolver.studies.axisymmetric.canham_reference`).

    python -m pyevolver.studies.accuracy_chart [--size tiny|small|full] [--out DIR]

writes ``accuracy_vs_time.csv`` (problem, method, resolution, seconds,
energy, reference, rel_error, min_angle_deg) and ``accuracy_vs_time.png``
(one panel per problem).  ``tiny`` is what CI regenerates (under a minute),
``small`` the studies' small sizes, ``full`` the studies' full sizes (tori
up to 40×64, vesicles up to 2,562 vertices; about an hour on two quiet
cores).
"""
from __future__ import annotations

import argparse
import csv
import importlib
import os

STUDIES = [("torus", "pyevolver.studies.fig3_torus"),
           ("vesicle", "pyevolver.studies.fig4_vesicles")]
# keyword arguments of each study's chart_records per chart size
SIZES = {"tiny": {"torus": {"sizes": [(5, 10)], "rounds": 10},
                  "vesicle": {"max_nv": 162, "shapes": ["prolate"], "methods": ["normal"]}},
         "small": {"torus": {}, "vesicle": {"max_nv": 642}},
         "full": {"torus": {"full": True}, "vesicle": {"max_nv": 2562}}}
COLUMNS = ["problem", "method", "resolution", "seconds", "energy", "reference",
           "rel_error", "min_angle_deg"]


def collect(size: str = "small", studies: list[str] | None = None) -> list[dict]:
    """All chart records, each a dict with the keys of :data:`COLUMNS`.

    ``size``: "tiny" (the 5×10 torus with 10 rounds of the recipe and the
    162-vertex prolate: what CI regenerates), "small" (the studies' small
    sizes) or "full".

    The vesicle records carry their reduced volume in ``problem``
    (``vesicle v0=0.85``) so that each shape gets its own panel.
    """
    rows = []
    for problem, module in (studies or STUDIES):
        mod = importlib.import_module(module)
        for r in mod.chart_records(**SIZES[size][problem]):
            row = dict(r)
            row["problem"] = problem if "v0" not in r else f"{problem} v0={r['v0']:.2f}"
            rows.append(row)
    return rows


def write_csv(rows: list[dict], path: str) -> None:
    """Write ``rows`` with :data:`COLUMNS` (numbers with 12 significant digits)."""
    def fmt(v):
        return f"{v:.12g}" if isinstance(v, float) else str(v)
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)                 # labels such as "recipe (g,V,u,n)" get quoted
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow([fmt(r[k]) for k in COLUMNS])


def plot(rows: list[dict], path: str) -> None:
    """Log-log panels, one per problem: rel_error against seconds, one line
    per method through its resolutions (labelled with the vertex count)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    problems = list(dict.fromkeys(r["problem"] for r in rows))
    fig, axes = plt.subplots(1, len(problems), figsize=(5.2 * len(problems), 4.4),
                             squeeze=False)
    for ax, prob in zip(axes[0], problems):
        sub = [r for r in rows if r["problem"] == prob]
        for method in dict.fromkeys(r["method"] for r in sub):
            pts = sorted((r for r in sub if r["method"] == method),
                         key=lambda r: r["resolution"])
            x = [max(r["seconds"], 1e-3) for r in pts]
            y = [max(abs(r["rel_error"]), 1e-8) for r in pts]
            ax.loglog(x, y, "o-", label=method)
            for xi, yi, r in zip(x, y, pts):
                ax.annotate(str(r["resolution"]), (xi, yi), fontsize=7,
                            textcoords="offset points", xytext=(3, 3))
        ax.set_title(prob)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("|W − W_ref| / W_ref")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", choices=sorted(SIZES), default="small")
    ap.add_argument("--out", default=".")
    a = ap.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    rows = collect(size=a.size)
    csv = os.path.join(a.out, "accuracy_vs_time.csv")
    png = os.path.join(a.out, "accuracy_vs_time.png")
    write_csv(rows, csv)
    for r in rows:
        print(f"{r['problem']:14s} {r['method']:32s} {r['resolution']:7d} vertices "
              f"{r['seconds']:9.2f} s  W = {r['energy']:.6f}  rel. error {r['rel_error']:.2e}  "
              f"min angle {r['min_angle_deg']:.1f}", flush=True)
    try:
        plot(rows, png)
    except ImportError:
        print("matplotlib not installed: no PNG")
        return 0
    print("wrote", csv, "and", png)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
