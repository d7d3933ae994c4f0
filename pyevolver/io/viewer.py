"""A self-contained HTML viewer of a surface: one file, no network, no
library (a small canvas renderer written for pyevolver), opened in any web
browser.  Drag to rotate, wheel (or +/−) to zoom, a menu to colour the
facets by a quantity (mean curvature, area, ... as in
:func:`pyevolver.io.fields.surface_fields`, clipped at the 2nd and 98th
percentiles, with a labelled colour bar) or by the datafile's facet colours
when it sets them.

``s`` and ``show`` in the command language write it (:func:`write_viewer`)
and say where.
"""
from __future__ import annotations

import html
import json
import os

import numpy as np

from ..atomic import atomic_path
from ..errors import CommandError, dimension_error
from ..model.surface import Surface
from .fields import clipped_range, facet_colors, surface_fields

def _facet_fields(s: Surface) -> dict:
    v, f = surface_fields(s)
    out = {}
    for name, vals in v.items():
        if name in ("id",) or not np.issubdtype(np.asarray(vals).dtype, np.number):
            continue
        vals = np.asarray(vals, float)
        vals = np.clip(vals, *clipped_range(vals, 0.0, 100.0))   # outliers first
        out[f"vertex {name}"] = vals[s.F].mean(axis=1)
    for name, vals in f.items():
        if name == "id":
            continue
        out[f"facet {name}"] = np.asarray(vals, float)
    # the interesting ones first
    order = sorted(out, key=lambda k: (k != "vertex mean_curvature", k != "facet area", k))
    return {k: out[k] for k in order if np.ptp(np.nan_to_num(out[k])) > 0 or
            k == "vertex mean_curvature"}


def viewer_data(surface: Surface) -> dict:
    """The JSON-able content of the viewer: coordinates centred and scaled
    into the unit ball, triangles, per-facet fields with clipped ranges, the
    facet colours when set."""
    s = surface
    if s.X.shape[1] > 3:
        raise dimension_error(s.sdim, "the viewer", "needs")
    if s.nf == 0:
        raise CommandError("show: the surface has no facets to draw")
    X = np.zeros((s.nv, 3))
    X[:, :s.X.shape[1]] = s.X
    lo, hi = X.min(axis=0), X.max(axis=0)
    X = X - (lo + hi) / 2
    r = float(np.max(np.linalg.norm(X, axis=1))) or 1.0
    X = X / r
    fields = {}
    for name, vals in _facet_fields(s).items():
        a, b = clipped_range(vals)
        fields[name] = {"values": [round(float(x), 6) for x in np.nan_to_num(vals)],
                        "lo": a, "hi": b}
    data = {"X": [round(float(x), 5) for x in X.ravel()],
            "F": [int(i) for i in np.asarray(s.F).ravel()],
            "fields": fields}
    col = facet_colors(s)
    if col is not None:
        data["colors"] = [round(float(x), 3) for x in col.ravel()]
    return data


def viewer_html(surface: Surface, title: str = "pyevolver") -> str:
    """The viewer page of ``surface`` (one self-contained HTML text)."""
    data = json.dumps(viewer_data(surface), separators=(",", ":")).replace("</", "<\\/")
    return _PAGE.replace("__TITLE__", html.escape(title)).replace("__DATA__", data)


def notebook_html(surface: Surface, title: str = "pyevolver", height: int = 520) -> str:
    """The viewer in an ``<iframe srcdoc>`` (a notebook cell's display)."""
    page = viewer_html(surface, title)
    return (f'<iframe srcdoc="{html.escape(page, quote=True)}" width="100%" '
            f'height="{int(height)}" style="border:0"></iframe>')


def write_viewer(surface: Surface, path: str, title: str = "pyevolver") -> str:
    """Write the HTML viewer of ``surface`` to ``path`` (atomically); returns
    ``path``."""
    page = viewer_html(surface, title)
    try:
        with atomic_path(path, ".html") as tmp:
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(page)
    except OSError as exc:
        raise CommandError(f"cannot write '{path}': {exc.strerror or exc}") from None
    return os.fspath(path)


_PAGE = r"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>__TITLE__</title>
<style>
body{margin:0;font:14px sans-serif;background:#fff;color:#222}
#bar{padding:6px 10px;border-bottom:1px solid #ddd}
#bar label{margin-right:14px}
canvas{display:block;cursor:grab}
</style></head><body>
<div id="bar"><b>__TITLE__</b> &nbsp;
<label>colour by <select id="field"></select></label>
<label><input type="checkbox" id="edges"> edges</label>
<button id="reset">reset view</button>
<span style="color:#777">drag: rotate &middot; wheel or +/&minus;: zoom</span></div>
<canvas id="view" width="800" height="600"></canvas>
<script>
"use strict";
const DATA = __DATA__;
const cv = document.getElementById("view"), ctx = cv.getContext("2d");
const X = DATA.X, F = DATA.F, nf = F.length / 3;
const sel = document.getElementById("field"), edges = document.getElementById("edges");
// viridis, five stops (lerped)
const RAMP = [[68,1,84],[59,82,139],[33,145,140],[94,201,98],[253,231,37]];
function ramp(t) {
  t = Math.min(1, Math.max(0, t)) * (RAMP.length - 1);
  const i = Math.min(RAMP.length - 2, Math.floor(t)), u = t - i;
  return RAMP[i].map((c, k) => c + u * (RAMP[i + 1][k] - c));
}
const names = Object.keys(DATA.fields);
if (DATA.colors) names.unshift("facet colours of the datafile");
names.push("none");
for (const n of names) { const o = document.createElement("option"); o.textContent = n; sel.appendChild(o); }
edges.checked = nf <= 3000;
let yaw = 0.6, pitch = 0.45, zoom = 1.0;
function rot(p) {               // turn about z (yaw), then tip towards the viewer (pitch)
  const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
  const x = cy * p[0] - sy * p[1], y = sy * p[0] + cy * p[1], z = p[2];
  // screen right = x, screen up = cp*z - sp*y, depth (towards viewer) = -(cp*y + sp*z)
  return [x, cp * z + sp * y, -(cp * y - sp * z)];
}
function facetRGB() {
  const name = sel.value, out = new Array(nf);
  if (name === "facet colours of the datafile") {
    for (let f = 0; f < nf; f++) out[f] = [0, 1, 2].map(k => 255 * DATA.colors[3 * f + k]);
    return [out, null];
  }
  if (name === "none" || !DATA.fields[name]) { out.fill([200, 205, 214]); return [out, null]; }
  const fd = DATA.fields[name], w = fd.hi - fd.lo;
  for (let f = 0; f < nf; f++) out[f] = ramp((fd.values[f] - fd.lo) / w);
  return [out, fd];
}
function fmt(v) { return Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(3) : v.toPrecision(4); }
function draw() {
  const W = cv.width, H = cv.height, barW = 90;
  ctx.fillStyle = "#ffffff"; ctx.fillRect(0, 0, W, H);
  const s = 0.45 * Math.min(W - barW, H) * zoom, cx = (W - barW) / 2, cy = H / 2;
  const nv = X.length / 3, P = new Array(nv);
  for (let i = 0; i < nv; i++) P[i] = rot([X[3 * i], X[3 * i + 1], X[3 * i + 2]]);
  const depth = new Float64Array(nf), order = new Array(nf);
  for (let f = 0; f < nf; f++) {
    depth[f] = P[F[3 * f]][2] + P[F[3 * f + 1]][2] + P[F[3 * f + 2]][2]; order[f] = f;
  }
  order.sort((a, b) => depth[a] - depth[b]);          // far first (painter's order)
  const [rgb, fd] = facetRGB();
  ctx.lineJoin = "round";
  for (const f of order) {
    const a = P[F[3 * f]], b = P[F[3 * f + 1]], c = P[F[3 * f + 2]];
    const ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
    const vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
    const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    const len = Math.hypot(nx, ny, nz) || 1;
    const lam = Math.abs(0.35 * nx - 0.45 * ny + 0.82 * nz) / len;   // light from the front, upper left
    const sh = 0.35 + 0.65 * lam, col = rgb[f];
    const fill = "rgb(" + col.map(v => Math.round(Math.min(255, v * sh))).join(",") + ")";
    ctx.beginPath();
    ctx.moveTo(cx + s * a[0], cy - s * a[1]);
    ctx.lineTo(cx + s * b[0], cy - s * b[1]);
    ctx.lineTo(cx + s * c[0], cy - s * c[1]);
    ctx.closePath();
    ctx.fillStyle = fill; ctx.fill();
    ctx.strokeStyle = edges.checked ? "rgba(20,20,20,0.55)" : fill;
    ctx.lineWidth = edges.checked ? 0.6 : 0.8; ctx.stroke();
  }
  if (fd) {                                          // the colour bar, labelled
    const x0 = W - barW + 20, y0 = 40, h = H - 80;
    for (let k = 0; k < h; k++) {
      const c = ramp(1 - k / (h - 1));
      ctx.fillStyle = "rgb(" + c.map(Math.round).join(",") + ")"; ctx.fillRect(x0, y0 + k, 18, 1);
    }
    ctx.fillStyle = "#222"; ctx.font = "12px sans-serif";
    ctx.fillText(fmt(fd.hi), x0 - 4, y0 - 6); ctx.fillText(fmt(fd.lo), x0 - 4, y0 + h + 16);
    ctx.save(); ctx.translate(x0 + 34, y0 + h / 2); ctx.rotate(Math.PI / 2);
    ctx.textAlign = "center"; ctx.fillText(sel.value + " (outliers clipped)", 0, 0); ctx.restore();
  }
  window.pyevolverDrawn = nf;
}
function resize() { cv.width = window.innerWidth; cv.height = Math.max(300, window.innerHeight - 40); draw(); }
let drag = null;
cv.addEventListener("mousedown", e => { drag = [e.clientX, e.clientY]; });
window.addEventListener("mouseup", () => { drag = null; });
window.addEventListener("mousemove", e => {
  if (!drag) return;
  yaw += 0.01 * (e.clientX - drag[0]); pitch += 0.01 * (e.clientY - drag[1]);
  drag = [e.clientX, e.clientY]; draw();
});
cv.addEventListener("wheel", e => { e.preventDefault(); zoom *= Math.exp(-0.001 * e.deltaY); draw(); }, {passive: false});
window.addEventListener("keydown", e => {
  if (e.key === "+" || e.key === "=") { zoom *= 1.1; draw(); }
  if (e.key === "-") { zoom /= 1.1; draw(); }
});
sel.addEventListener("change", draw); edges.addEventListener("change", draw);
document.getElementById("reset").addEventListener("click", () => { yaw = 0.6; pitch = 0.45; zoom = 1; draw(); });
window.addEventListener("resize", resize);
resize();
</script></body></html>
"""
