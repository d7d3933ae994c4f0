"""The studies' numbers in the documentation, written from the studies' CSV files.

Every results table of ``docs/paper.md`` and ``docs/guide.md`` that a study
measured lies between two marker comments,

    <!-- doc_numbers NAME -->
    ...
    <!-- /doc_numbers NAME -->

and is written here from the CSV files the studies wrote (committed beside
the docs: ``docs/fig1_torus.csv``, ``docs/fig3_*.csv``,
``docs/fig4_vesicles.csv``), never by hand.  After a study is run again,
copy its CSV into ``docs/`` and run

    python -m pyevolver.studies.doc_numbers            # rewrite the blocks
    python -m pyevolver.studies.doc_numbers --check    # exit 1 if a block is stale
    python -m pyevolver.studies.doc_numbers --figures  # also redraw fig4_vesicles.png
    python -m pyevolver.studies.doc_numbers --merge results/  # merge a run's fig3 CSVs first

(``--merge`` replaces the rows of the meshes the run covered, so the 20×32
and 40×64 rows of ``python -m pyevolver.studies.fig3_torus --meshes
20x32,40x64`` join the committed 5×10 and 10×16 ones.)

``tests/docs/test_documented_numbers.py`` checks that every block is what
its CSV gives, that the numbers quoted in the prose are the CSV's, and
regenerates small cases of the studies live.
"""
from __future__ import annotations

import argparse
import csv
import math
import os
import re
from typing import Callable

HERE = os.path.dirname(os.path.abspath(__file__))
DOCS = os.path.normpath(os.path.join(HERE, "..", "..", "docs"))
CLIFFORD = 2 * math.pi ** 2

__all__ = ["DOCS", "BLOCKS", "MERGED", "read_csv", "merge_csv", "render", "blocks_in", "update", "main",
           "pct", "fig1_table", "fig3_table", "fig3_stages_table", "fig3_loop_stages_table",
           "prop1_table",
           "fig4_table", "fig4_figure", "fig4_continuation_table", "chart_table"]


def read_csv(name: str, docs: str = DOCS) -> list[dict]:
    """The rows of ``docs/<name>`` as dicts of strings."""
    with open(os.path.join(docs, name), newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def merge_csv(name: str, src: str, docs: str = DOCS, key: str = "mesh") -> int:
    """Merge the study's ``src`` CSV into ``docs/<name>``: the rows of
    ``docs/<name>`` whose ``key`` value (the mesh, the shape) occurs in
    ``src`` are replaced by ``src``'s rows, the others kept in their order;
    the columns are the union of both files'.  Returns the number of rows
    written from ``src``."""
    new = read_csv(os.path.basename(src), os.path.dirname(os.path.abspath(src)))
    path = os.path.join(docs, name)
    old = read_csv(name, docs) if os.path.exists(path) else []
    keys_new = {r.get(key) for r in new}
    rows = [r for r in old if r.get(key) not in keys_new] + new
    fields: list[str] = []
    for r in old + new:
        fields += [k for k in r if k not in fields]
    with open(path, "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, restval="")
        w.writeheader()
        w.writerows(rows)
    return len(new)


def pct(x: float, digits: int = 3) -> str:
    """A relative error as a signed percentage with ``digits`` significant digits
    (``0.00932`` → ``+0.932%``)."""
    return f"{100 * x:+.{digits}g}%".replace("-", "−")


def _f(x: str, fmt: str) -> str:
    return format(float(x), fmt) if x not in ("", None) else ""


def _depth(x: str) -> str:
    v = round(abs(float(x)), 3)
    return "0" if v == 0 else f"{v:.3f}".rstrip("0")


def _table(head: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


# -- Figure 1 ------------------------------------------------------------------------------------

def fig1_table(docs: str = DOCS) -> str:
    """guide §7 and paper.md: the four PL energies on the 5×9 torus (``fig1_torus.csv``)."""
    rows = []
    for r in read_csv("fig1_torus.csv", docs):
        rows.append([r["label"], f"`{r['method']}`", f"`{r['minimizer']}`", r["iterations"],
                     _f(r["W"], ".4f"), pct(float(r["W"]) / CLIFFORD - 1),
                     f"{float(r['min_angle_deg']):.2g}°", _f(r["seconds"], ".1f")])
    return _table(["energy", "method", "minimizer", "iterations", "W", "W − 2π²",
                   "smallest angle", "s"], rows)


# -- Figure 3 and Proposition 1 ------------------------------------------------------------------

def _rr(r: dict) -> str:
    """R/r (fit deviation); for a continued mesh that is a cyclide (the plain
    fit's deviation above 0.1, the Möbius-normalized one less than half of
    it) the Möbius-normalized ratio, marked."""
    if not r.get("R_over_r"):
        return ""
    dev = float(r["revolution_dev"])
    if ("(cont.)" in r["label"] and dev > 0.1 and r.get("moebius_dev")
            and float(r["moebius_dev"]) < dev / 2):
        return (f"{float(r['R_over_r_moebius']):.3f} ({float(r['moebius_dev']):.3f}) Möbius; "
                f"plain fit dev {dev:.2f}")
    return f"{float(r['R_over_r']):.3f} ({dev:.3f})"


def fig3_table(docs: str = DOCS, mesh: str = "10x16") -> str:
    """paper.md, Figure 3: every run on ``mesh`` (``fig3_torus.csv``)."""
    rows = []
    for r in read_csv("fig3_torus.csv", docs):
        if r["mesh"] != mesh:
            continue
        label = r["label"] + (" [evolver-nox-d]" if r.get("program") == "evolver-nox-d" else "")
        loop = pct(float(r["loop_rel_error"])) if r.get("loop_rel_error") else ""
        if r.get("min_angle_deg") and float(r["min_angle_deg"]) < 0.05:
            ang = "0°"
        else:
            ang = _f(r.get("min_angle_deg", ""), ".1f") + "°"
        lam = _f(r["lambda"], ".4g") if r.get("lambda") and float(r["lambda"]) else ""
        rows.append([label, lam, _f(r["W"], ".3f"), pct(float(r["rel_error"])), loop,
                     _rr(r), ang, r["iterations"], _f(r["seconds"], ".1f")])
    return _table(["run", "λ", "W", "W − 2π²", "W_Loop − 2π²", "R/r (dev)", "min angle",
                   "iterations", "s"], rows)


def fig3_stages_table(docs: str = DOCS, mesh: str = "10x16", rule: str = "consistency") -> str:
    """paper.md: the healthy stages of the consistency rule (``fig3_stages.csv``)."""
    rows = []
    for r in read_csv("fig3_stages.csv", docs):
        if r["mesh"] != mesh or r.get("rule") != rule or r.get("status") != "healthy":
            continue
        rows.append([r["energy"], f"{float(r['lambda']):.4g}",
                     pct(float(r["W"]) / CLIFFORD - 1), pct(float(r["loop_w"]) / CLIFFORD - 1),
                     f"{float(r['minangle']):.1f}°"])
    return _table(["energy", "λ", "W", "W_Loop", "min angle"], rows)


def fig3_loop_stages_table(docs: str = DOCS, mesh: str = "10x16") -> str:
    """paper.md: the Loop-guided continuation's stages on ``mesh`` (or on
    several meshes, comma-separated) (``fig3_stages.csv``): λ: W, W_Loop
    (errors to 2π², the kept stage's W_Loop in bold), smallest angle; runs
    of undone stages as one item."""
    rows = []
    meshes = mesh.split(",")
    allrows = [r for r in read_csv("fig3_stages.csv", docs) if r.get("rule", "loop") == "loop"]
    for m in meshes:
        rows += _loop_stage_rows([r for r in allrows if r["mesh"] == m], m)
    return _table(["mesh", "energy", "λ: W, W_Loop, min angle"], rows)


def _loop_stage_rows(data: list[dict], mesh: str) -> list[list[str]]:
    rows = []

    def p2(x: float) -> str:
        return f"{100 * x:+.2f}%".replace("-", "−")
    for energy in dict.fromkeys(r["energy"] for r in data):
        st = [r for r in data if r["energy"] == energy]
        healthy = [r for r in st if r["status"] == "healthy"]
        best = min(healthy, key=lambda r: float(r["loop_w"])) if healthy else None
        items: list[str] = []
        undone: list[str] = []
        for r in st + [None]:
            if r is not None and r["status"] != "healthy":
                undone.append(f"{float(r['lambda']):.4g}")
                continue
            if undone:
                items.append(" and ".join(undone) + ": collapse (undone)")
                undone = []
            if r is None:
                break
            loop = p2(float(r["loop_w"]) / CLIFFORD - 1)
            if r is best:
                loop = f"**{loop}**"
            items.append(f"{float(r['lambda']):.4g}: {p2(float(r['W']) / CLIFFORD - 1)}, "
                         f"{loop}, {float(r['minangle']):.1f}°")
        rows.append([mesh.replace("x", "×"), energy, " · ".join(items)])
    return rows


def prop1_table(docs: str = DOCS) -> str:
    """paper.md, Proposition 1: Bobenko's energy of the almost spherical tori
    (``fig3_prop1.csv``), one column per grid."""
    data = read_csv("fig3_prop1.csv", docs)
    grids = list(dict.fromkeys(f"{r['m']}×{r['n']}" for r in data))
    eps = list(dict.fromkeys(r["eps"] for r in data))
    val = {(f"{r['m']}×{r['n']}", r["eps"]): float(r["W_bobenko"]) for r in data}
    rows = [[f"{float(e):g}"] + [f"{val[(g, e)]:.9f}" for g in grids] for e in eps]
    return _table(["ε"] + grids, rows)


# -- Figure 4 ------------------------------------------------------------------------------------

SHAPE_ORDER = ("prolate", "discocyte", "stomatocyte")
REF_SUFFIX = " (REF)"


def _fig4_rows(docs: str) -> list[dict]:
    rows = read_csv("fig4_vesicles.csv", docs)
    out = []
    for shape in SHAPE_ORDER:
        sub = [r for r in rows if r["shape"] == shape]
        methods = list(dict.fromkeys(r["method"] for r in sub if not r["method"].endswith(REF_SUFFIX)))
        for m in methods:
            out += [r for r in sub if r["method"] == m]
            out += [r for r in sub if r["method"] == m + REF_SUFFIX]
    return out


def fig4_table(docs: str = DOCS) -> str:
    """paper.md, Figure 4: every row of ``fig4_vesicles.csv``."""
    rows, last = [], None
    data = _fig4_rows(docs)
    finest = {}
    for r in data:
        key = (r["method"], r["shape"])
        finest[key] = max(finest.get(key, 0), int(r["resolution"]))
    for r in data:
        key = (r["method"], r["shape"])
        ref = r["method"] == "axisymmetric reference"
        if r["method"].endswith(REF_SUFFIX):
            label = "— in evolver-nox-d"
        else:
            label = "reference" if ref else r["method"]
        first = key != last
        last = key
        typ = r["type"] if r["type"] == r["shape"] else f"*{r['type']}*"
        err = "" if ref else pct(float(r["rel_error"]))
        if err and int(r["resolution"]) == finest[key] and not r["method"].endswith(REF_SUFFIX):
            err = f"**{err}**"
        W = f"{float(r['energy']):.6f}" if ref or r["method"].endswith(REF_SUFFIX) \
            else f"{float(r['energy']):.3f}"
        res = f"(n = {r['resolution']})" if ref else f"{int(r['resolution']):,}"
        ang = "" if ref else f"{float(r['min_angle_deg']):.1f}°"
        secs = "" if ref else f"{float(r['seconds']):.3g}"
        rows.append([label if first else "", r["shape"] if first else "", res, W, err, typ,
                     f"{float(r['height_width']):.3f}",
                     f"{_depth(r['pole_depth_min'])}, {_depth(r['pole_depth_max'])}", ang, secs])
    return _table(["method", "shape", "vertices", "W", "error", "type", "height/width",
                   "pole depths", "min angle", "s"], rows)


def _lam(x: float) -> str:
    return f"{x:g}" if round(x, 4) == x else f"{x:.2g}"


def _stages(text: str) -> str:
    """``fig4_vesicles.csv``'s continuation column (``λ:W/angle deg/steps[/uFLIPS][x]``
    per stage) as ``λ: W/angle°`` items; ``x`` marks a stage undone."""
    out = []
    for item in text.split():
        lam, rest = item.split(":", 1)
        undone = rest.endswith("x")
        parts = rest.rstrip("x").split("/")
        W, ang, steps = float(parts[0]), parts[1].replace("deg", "°"), parts[2]
        flips = next((p[1:] for p in parts[3:] if p.startswith("u")), None)
        txt = f"{_lam(float(lam))}{'x' if undone else ''}: {W:.3f}/{ang}"
        if flips is not None:
            txt += f" ({steps} Newton steps, {flips} flips)"
        out.append(txt)
    return " · ".join(out)


def fig4_continuation_table(docs: str = DOCS) -> str:
    """paper.md: the λ continuation of NormalCur+harmonic (and +u) per shape
    and resolution, from ``fig4_vesicles.csv``'s continuation column."""
    rows = []
    data = _fig4_rows(docs)
    plain = {(r["shape"], r["resolution"]): r["continuation"] for r in data
             if r["method"] == "NormalCur+harmonic"}
    for method, tag in (("NormalCur+harmonic", ""), ("NormalCur+harmonic+u", ", +u")):
        for r in data:
            if r["method"] != method or not r.get("continuation"):
                continue
            same = tag and r["continuation"] == plain.get((r["shape"], r["resolution"]))
            rows.append([r["shape"] + tag, f"{int(r['resolution']):,}",
                         "as without `u` (no edge flips)" if same else _stages(r["continuation"])])
    return _table(["shape", "vertices", "continuation (λ: W / smallest angle)"], rows)


# -- the accuracy chart --------------------------------------------------------------------------

def chart_table(docs: str = DOCS, torus_mesh: str = "5x10", max_nv: int = 642) -> str:
    """paper.md, the chart: the torus points (``fig3_chart.csv`` at
    ``torus_mesh``) and the vesicles' (``fig4_vesicles.csv`` up to ``max_nv``
    vertices), the same records ``accuracy_chart`` plots."""
    rows = []
    m, n = (int(v) for v in torus_mesh.split("x"))
    for r in read_csv("fig3_chart.csv", docs):
        if int(r["resolution"]) == m * n:
            rows.append(["torus", r["method"], r["resolution"], f"{float(r['seconds']):.3g}",
                         f"{float(r['rel_error']):.2e}"])
    for shape in SHAPE_ORDER:
        sub = [r for r in _fig4_rows(docs) if r["shape"] == shape
               and r["method"] != "axisymmetric reference" and int(r["resolution"]) <= max_nv]
        for meth in dict.fromkeys(r["method"] for r in sub):
            pts = [r for r in sub if r["method"] == meth]
            rows.append([f"{shape} {float(pts[0]['v0']):.2f}", meth,
                         " / ".join(r["resolution"] for r in pts),
                         " / ".join(f"{float(r['seconds']):.3g}" for r in pts),
                         " / ".join(f"{abs(float(r['rel_error'])):.1e}" for r in pts)])
    return _table(["problem", "method", "vertices", "seconds", "rel. error of W"], rows)


def fig4_figure(png: str, docs: str = DOCS) -> str:
    """``docs/fig4_vesicles.png`` from ``fig4_vesicles.csv`` alone: per shape,
    |W − W_ref|/W_ref against seconds (one line per method through its
    resolutions) and height/width against the vertex count beside the
    reference's.  Returns ``png``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    data = _fig4_rows(docs)
    shapes = [s for s in SHAPE_ORDER if any(r["shape"] == s for r in data)]
    fig, axes = plt.subplots(2, len(shapes), figsize=(4.2 * len(shapes), 7.6), squeeze=False)
    styles = ["o-", "s--", "^-.", "D:", "v-", "x--"]
    methods = list(dict.fromkeys(r["method"] for r in data
                                 if r["method"] != "axisymmetric reference"))
    for j, shape in enumerate(shapes):
        sub = [r for r in data if r["shape"] == shape]
        ref = [r for r in sub if r["method"] == "axisymmetric reference"]
        top, bottom = axes[0, j], axes[1, j]
        for k, m in enumerate(methods):
            pts = sorted((r for r in sub if r["method"] == m), key=lambda r: int(r["resolution"]))
            if not pts:
                continue
            kw = dict(color=f"C{k}", ms=4, label=m, zorder=3 + k % 3)
            top.loglog([float(r["seconds"]) for r in pts],
                       [max(abs(float(r["rel_error"])), 1e-6) for r in pts], styles[k % 6], **kw)
            bottom.semilogx([int(r["resolution"]) for r in pts],
                            [float(r["height_width"]) for r in pts], styles[k % 6], **kw)
        top.axhline(0.01, color="0.5", lw=0.6, zorder=1)
        top.set_title(f"{shape}, v0 = {float(sub[0]['v0']):.2f}", fontsize=10)
        top.set_xlabel("wall time (s)")
        top.set_ylabel("|W − W_ref| / W_ref")
        top.grid(True, which="both", alpha=0.3)
        if ref:
            bottom.axhline(float(ref[0]["height_width"]), color="k", lw=0.8, zorder=1,
                           label="axisymmetric reference")
        res = sorted({int(r["resolution"]) for r in sub if r["method"] != "axisymmetric reference"})
        bottom.set_xticks(res)
        bottom.set_xticklabels([f"{v:,}" for v in res])
        bottom.minorticks_off()
        bottom.set_xlabel("vertices")
        bottom.set_ylabel("height / width")
        bottom.grid(True, which="both", alpha=0.3)
    seen: dict = {}
    for ax in axes[1]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(lab, h)
    handles, labels = list(seen.values()), list(seen)
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return png


# -- the blocks ----------------------------------------------------------------------------------

#: the study CSVs ``--merge`` takes → the column whose values key the rows it replaces
MERGED = {"fig3_torus.csv": "mesh", "fig3_stages.csv": "mesh", "fig3_chart.csv": "resolution"}

#: block name → the function writing it from the CSVs in a docs folder
BLOCKS: dict[str, Callable[[str], str]] = {
    "fig1": fig1_table,
    "fig3": fig3_table,
    "fig3_5x10": lambda docs: fig3_table(docs, "5x10"),
    "fig3_consistency": fig3_stages_table,
    "fig3_loop_stages": fig3_loop_stages_table,
    "fig3_20x32": lambda docs: fig3_table(docs, "20x32"),
    "fig3_40x64": lambda docs: fig3_table(docs, "40x64"),
    "fig3_loop_stages_full": lambda docs: fig3_loop_stages_table(docs, "20x32,40x64"),
    "prop1": prop1_table,
    "fig4": fig4_table,
    "fig4_continuation": fig4_continuation_table,
    "chart": chart_table,
}
_BLOCK = re.compile(r"(<!-- doc_numbers (\w+) -->\n)(.*?)(<!-- /doc_numbers \2 -->)", re.S)


def render(name: str, docs: str = DOCS) -> str:
    """The text of block ``name`` from the CSVs in ``docs``."""
    return BLOCKS[name](docs).rstrip("\n") + "\n"


def blocks_in(text: str) -> dict[str, str]:
    """The blocks of a Markdown text: name → its current content."""
    return {m.group(2): m.group(3) for m in _BLOCK.finditer(text)}


def update(docs: str = DOCS, check: bool = False) -> list[str]:
    """Rewrite every block of the ``*.md`` files in ``docs`` (or with ``check``
    only compare); returns ``file:block`` for each block that was (or would
    be) changed.  An unknown block name raises ``KeyError``."""
    stale = []
    for fn in sorted(os.listdir(docs)):
        if not fn.endswith(".md"):
            continue
        path = os.path.join(docs, fn)
        with open(path, encoding="utf-8") as fh:
            text = fh.read()

        def sub(m: re.Match) -> str:
            new = render(m.group(2), docs)
            if new != m.group(3):
                stale.append(f"{fn}:{m.group(2)}")
            return m.group(1) + new + m.group(4)
        new_text = _BLOCK.sub(sub, text)
        if not check and new_text != text:
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(new_text)
    return stale


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit code."""
    ap = argparse.ArgumentParser(prog="python -m pyevolver.studies.doc_numbers",
                                 description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="only report stale blocks (exit 1)")
    ap.add_argument("--docs", default=DOCS)
    ap.add_argument("--figures", action="store_true",
                    help="also redraw fig4_vesicles.png from its CSV")
    ap.add_argument("--merge", metavar="DIR",
                    help="first merge a study's output CSVs in DIR into docs/ (the rows of "
                         "the meshes it ran replace the old ones)")
    a = ap.parse_args(argv)
    if a.merge and not a.check:
        for name, key in MERGED.items():
            if os.path.exists(os.path.join(a.merge, name)):
                n = merge_csv(name, os.path.join(a.merge, name), a.docs, key)
                print(f"merged {n} rows into {name}")
    stale = update(a.docs, check=a.check)
    if a.figures and not a.check:
        print("wrote", fig4_figure(os.path.join(a.docs, "fig4_vesicles.png"), a.docs))
    for s in stale:
        print(("stale: " if a.check else "rewrote: ") + s)
    return 1 if a.check and stale else 0


if __name__ == "__main__":
    raise SystemExit(main())
