"""The figure of the discrete phase study (:mod:`pyevolver.studies.phase_study`):
``W/(4π)`` against the reduced volume per branch, the discrete points
(filled: stable, open: unstable, ×: not converged, drawn at the
reference's energy) over the axisymmetric
reference's curves, the transitions marked; below, the relative error of
each point against its reference."""
from __future__ import annotations

import numpy as np

COLORS = {"prolate": "tab:blue", "oblate": "tab:orange", "stomatocyte": "tab:green"}


def plot(stem: str, rows: list[dict], refs: dict, trans: list[dict]) -> list[str]:
    """Write ``stem.png`` and ``stem.pdf``; returns their paths."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7, 7), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 1.3]})
    for b, color in COLORS.items():
        pts = sorted(refs.get(b, {}).values(), key=lambda p: p.v)
        if pts:
            ax.plot([p.v for p in pts], [p.W / (4 * np.pi) for p in pts], "-", color=color,
                    lw=1, label=f"{b} (axisymmetric reference)")
        mine = sorted((r for r in rows if r["branch"] == b), key=lambda r: r["v"])
        for r in mine:
            y = r["W"] / (4 * np.pi)
            if r["converged"] is not True:          # marked at the reference's energy
                ax.plot(r["v"], r["W_ref"] / (4 * np.pi), "x", color=color, ms=8)
            elif r["stable"] is True:
                ax.plot(r["v"], y, "o", color=color, ms=5)
            else:
                ax.plot(r["v"], y, "o", mfc="white", color=color, ms=5)
        ok = [r for r in mine if r["converged"] is True]
        if ok:
            ax2.plot([r["v"] for r in ok], [100 * r["rel_err"] for r in ok], "o-",
                     color=color, ms=3, lw=0.8)
    for t in trans:
        if t["v"] is not None:
            ax.axvline(t["v"], color="k", ls="--", lw=0.8)
            ax.text(t["v"], ax.get_ylim()[1], f" {t['from'][:3]}/{t['to'][:3]}\n {t['v']:.3f}",
                    va="top", fontsize=8)
        if t["v_published"] is not None:
            ax.axvline(t["v_published"], color="0.6", ls=":", lw=0.8)
    ax.plot([], [], "ko", ms=5, label="discrete, stable")
    ax.plot([], [], "o", mfc="white", color="k", ms=5, label="discrete, unstable")
    ax.plot([], [], "kx", ms=8, label="not converged (at W_ref)")
    ax.plot([], [], "k--", lw=0.8, label="discrete transition")
    ax.plot([], [], ":", color="0.6", label="published (SBL 1991)")
    nv = sorted({int(r["nv"]) for r in rows})
    ax.set_ylabel("W / 4π")
    c0 = sorted({float(r.get("c0") or 0.0) for r in rows}) or [0.0]
    ax.set_title(f"discrete phase study, c0 = {', '.join(f'{c:g}' for c in c0)} "
                 f"(about {nv[len(nv) // 2] if nv else '?'} vertices)")
    ax.legend(fontsize=7, loc="upper right")
    ax2.axhline(0, color="0.7", lw=0.5)
    ax2.set_xlabel("reduced volume v")
    ax2.set_ylabel("rel. error (%)")
    fig.tight_layout()
    paths = [f"{stem}.png", f"{stem}.pdf"]
    for p in paths:
        fig.savefig(p, dpi=120)
    plt.close(fig)
    return paths


def _fmt(x, spec):
    return "—" if x is None or x == "" or (isinstance(x, float) and x != x) else format(x, spec)


def summary_markdown(rows: list[dict], trans: list[dict]) -> str:
    """The study's tables in Markdown (written as ``summary.md`` next to
    ``phase.csv``; docs/phase.md quotes it): the transitions, then one row
    per point; where the rows' bending energies differ (a branch solved
    with another ``--method``) the solver column names each one's; with
    seeds (:mod:`~pyevolver.studies.phase_spread`) a column of the spread
    over the perturbed starts (the transitions': max − min of the
    crossings; the points': max − min of W relative to W_ref, and how many
    of the converged seeds are stable)."""
    mixed = len({r["method"] for r in rows if r.get("method")}) > 1
    seeded = any(r.get("seeds") not in (None, "") for r in rows)
    out = ["| transition | discrete | axisymmetric reference | published (SBL 1991) |"
           + (" spread over seeds |" if seeded else ""),
           "|---|---|---|---|" + ("---|" if seeded else "")]
    for t in trans:
        out.append(f"| {t['from']}/{t['to']} | {_fmt(t['v'], '.4f')} | "
                   f"{_fmt(t['v_ref'], '.4f')} | {_fmt(t['v_published'], '')} |"
                   + (f" {_fmt(t.get('v_spread'), '.2g')} |" if seeded else ""))
    out += ["", "| branch | v | vertices | W/4π | W_ref/4π | rel. error | lowest eigenvalue "
            "| stable | λ | min angle | solver |" + (" spread of W (stable seeds) |" if seeded
                                                      else ""),
            "|---|---|---|---|---|---|---|---|---|---|---|" + ("---|" if seeded else "")]
    for r in sorted(rows, key=lambda r: (list(COLORS).index(r["branch"]), r["v"])):
        ok = r["converged"] is True
        line = (
            f"| {r['branch']} | {r['v']:.3f} | {int(r['nv'])} | "
            f"{r['W'] / (4 * np.pi):.5f} | {r['W_ref'] / (4 * np.pi):.5f} | "
            + (f"{100 * r['rel_err']:+.3f}%" if ok else "not converged") + " | "
            f"{_fmt(r['eig1'], '.4g')} | "
            + ("yes" if r["stable"] is True else ("no" if r["stable"] is False else "—"))
            + " | "
            f"{r['lambda']:g} | {r['min_angle_deg']:.1f}° | {r['start']}"
            + (f", {r.get('method', '')}" if mixed else "") + " |")
        if seeded:
            sp = r.get("W_spread")
            rel = None if sp in (None, "") else 100 * float(sp) / r["W_ref"]
            line += (f" {_fmt(rel, '.2g')}%" if rel is not None and rel == rel else " —") + (
                f" ({r['stable_seeds']})" if r.get("stable_seeds") else "") + " |"
        out.append(line)
    return "\n".join(out) + "\n"
