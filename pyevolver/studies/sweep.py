"""Parameter sweeps: one datafile over a grid of parameter values.

A sweep is described by a TOML file (``pyevolver sweep SPEC.toml``; every
key is documented in docs/guide.md, "The sweep file")::

    datafile = "vesicle.fe"          # relative to the spec's folder
    output = "vesicle_sweep"         # default: <spec name>_out beside the spec
    commands = "g 20; r; g 20"       # run at every point, after its values are set
    record = ["body[1].volume"]      # optional: more expressions for the table
    snapshot = "mean_curvature"      # the field of each point's picture; false: none

    [parameters]                     # the grid: every combination, in this order
    h_zero = [0.0, 0.5, 1.0, 1.5]
    "body[1].target" = {start = 3.0, stop = 4.0, num = 2}

    [continuation]                   # optional
    parameter = "h_zero"             # each point starts from its neighbour's surface

A parameter is anything the command language can assign (``name := value``):
a PARAMETER or variable of the datafile, ``body[1].target``,
``quantity.target``, ``quantity.modulus``...  Each point loads the datafile
(its ``read`` section runs), assigns its values, recalculates and runs
``commands``; with continuation, the points along the continuation
parameter form a chain and each starts from the final surface of the one
before it (``replace_load`` of its dump).

Every point has its own folder ``output/pNNNN`` holding ``final.fe`` (the
dump), ``energies.csv`` (energy and area of every ``g`` step), ``log.txt``
(what the commands printed), ``snapshot.png`` and, written last,
``result.json``.  All files are written atomically, so a sweep killed at any
moment and run again computes only the points without a ``result.json``
(or whose datafile, commands or values changed: the result records a key
of them).  The collected ``results.csv`` and ``phase.png`` (the snapshots
in a grid over two parameters, or a plot over one) are written at the end.

Points run through any :class:`concurrent.futures.Executor`: a local
process pool by default, Dask distributed through
``Client(address).get_executor()`` (``--scheduler tcp://HOST:PORT``; the
workers must import pyevolver and share the output folder's filesystem).
"""
from __future__ import annotations

import csv
import ctypes
import dataclasses
import hashlib
import io
import json
import math
import os
import signal
import threading
import time
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from typing import Any, Callable

import numpy as np

from ..atomic import atomic_path, atomic_write
from ..commands.interpreter import Quit
from ..datafile.writer import dump
from ..errors import PyEvolverError
from ..io import movie
from ..io.render import OBLIQUE, _matplotlib, _save, camera
from ..session.api import progress_bar
from ..session.core import Session

#: most points of one sweep (each has its own folder and process task); the
#: grid's size is checked from the parameters' lengths before anything runs
MAX_POINTS = 100_000

SPEC_KEYS = {"datafile", "output", "commands", "record", "snapshot", "parameters",
             "continuation", "plot"}


class SweepError(PyEvolverError):
    """A sweep specification that cannot be run (located in the spec file)."""


@dataclasses.dataclass
class SweepSpec:
    """A parsed sweep specification (see the module docstring); paths absolute."""

    datafile: str
    output: str
    parameters: dict                     # name -> list of float, in grid order
    commands: str = ""
    record: list = dataclasses.field(default_factory=list)
    snapshot: str | None = "mean_curvature"
    continuation: str | None = None
    plot_color: str = "total_energy"
    source: str = "<spec>"

    def points(self):
        """All grid points, as a list of ``{name: value}`` (the last
        parameter varying fastest)."""
        names = list(self.parameters)
        grids = np.meshgrid(*[self.parameters[n] for n in names], indexing="ij")
        flat = [g.ravel().tolist() for g in grids]
        return [dict(zip(names, vals)) for vals in zip(*flat)]

    def chains(self):
        """Lists of point indices: one per point, or, with continuation, one
        per line of the grid along the continuation parameter (in its
        order)."""
        pts = self.points()
        if self.continuation is None:
            return [[i] for i in range(len(pts))]
        others = [n for n in self.parameters if n != self.continuation]
        lines = {}
        for i, p in enumerate(pts):
            lines.setdefault(tuple(p[n] for n in others), []).append(i)
        return list(lines.values())


def _toml():
    try:
        import tomllib
        return tomllib
    except ImportError:                              # Python < 3.11
        try:
            import tomli
            return tomli
        except ImportError:
            raise SweepError("reading a sweep spec on Python < 3.11 needs tomli "
                             "(pip install tomli)") from None


def _values(where, name, v):
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        return [float(v)]
    if isinstance(v, list) and v and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                         for x in v):
        return [float(x) for x in v]
    if isinstance(v, dict) and set(v) == {"start", "stop", "num"}:
        try:
            num = int(v["num"])
            if not 1 <= num <= MAX_POINTS:
                raise SweepError(f"{where}: parameter '{name}': num = {v['num']} (from 1 to "
                                 f"{MAX_POINTS:,})")
            return np.linspace(float(v["start"]), float(v["stop"]), num).tolist()
        except (TypeError, ValueError):
            pass
    raise SweepError(f"{where}: parameter '{name}': expected a number, a list of numbers "
                     f"or {{start = a, stop = b, num = n}}")


def load_spec(path: str) -> SweepSpec:
    """Read a sweep specification from a TOML file (:class:`SweepError` with
    the file and the problem when it is wrong)."""
    toml = _toml()
    path = os.path.abspath(path)
    try:
        with open(path, "rb") as fh:
            raw = toml.load(fh)
    except OSError as exc:
        raise SweepError(f"{path}: cannot read the sweep spec: {exc.strerror}") from None
    except toml.TOMLDecodeError as exc:
        raise SweepError(f"{path}: {exc}") from None
    return spec_from_dict(raw, os.path.dirname(path), path)


def spec_from_dict(raw: dict, base: str = ".", where: str = "<spec>") -> SweepSpec:
    """A :class:`SweepSpec` from a dict shaped like the TOML file; relative
    paths are taken from ``base``."""
    unknown = set(raw) - SPEC_KEYS
    if unknown:
        raise SweepError(f"{where}: unknown key{'s' if len(unknown) > 1 else ''} "
                         f"{', '.join(sorted(unknown))} (known: {', '.join(sorted(SPEC_KEYS))})")
    if not isinstance(raw.get("datafile"), str):
        raise SweepError(f"{where}: 'datafile' (the datafile's path, a string) is required")
    datafile = os.path.join(base, raw["datafile"])
    if not os.path.isfile(datafile):
        raise SweepError(f"{where}: datafile '{raw['datafile']}' not found")
    params = raw.get("parameters")
    if not isinstance(params, dict) or not params:
        raise SweepError(f"{where}: a [parameters] table with at least one parameter is required")
    parameters = {str(k): _values(where, k, v) for k, v in params.items()}
    size = 1
    for vals in parameters.values():
        size *= len(vals)
    if size > MAX_POINTS:
        raise SweepError(f"{where}: the grid has {size:,} points ("
                         f"{' x '.join(str(len(v)) for v in parameters.values())}); at most "
                         f"{MAX_POINTS:,} (split the sweep)")
    stem = os.path.splitext(os.path.basename(where))[0] if where != "<spec>" else "sweep"
    output = os.path.join(base, raw.get("output", stem + "_out"))
    commands = raw.get("commands", "")
    if not isinstance(commands, str):
        raise SweepError(f"{where}: 'commands' must be a string of commands")
    record = raw.get("record", [])
    if not isinstance(record, list) or not all(isinstance(r, str) for r in record):
        raise SweepError(f"{where}: 'record' must be a list of expressions (strings)")
    snap = raw.get("snapshot", "mean_curvature")
    if snap is False:
        snap = None
    elif not isinstance(snap, str):
        raise SweepError(f"{where}: 'snapshot' must be a field name or false")
    cont = raw.get("continuation")
    cpar = None
    if cont is not None:
        if not isinstance(cont, dict) or set(cont) != {"parameter"}:
            raise SweepError(f"{where}: [continuation] takes one key, parameter = \"name\"")
        cpar = cont["parameter"]
        if cpar not in parameters:
            raise SweepError(f"{where}: the continuation parameter '{cpar}' is not in "
                             f"[parameters]")
    plot = raw.get("plot", {})
    if not isinstance(plot, dict) or set(plot) - {"color"}:
        raise SweepError(f"{where}: [plot] takes one key, color = \"column\"")
    return SweepSpec(datafile=os.path.abspath(datafile), output=os.path.abspath(output),
                     parameters=parameters, commands=commands, record=list(record),
                     snapshot=snap, continuation=cpar,
                     plot_color=plot.get("color", "total_energy"), source=where)


# -- keys: what a point's result depends on ----------------------------------------------

def point_keys(spec: SweepSpec) -> list[str]:
    """A key (hex digest) per point: the datafile's bytes, the commands, the
    recorded expressions, the snapshot field, the point's values and, with
    continuation, the key of the point it starts from."""
    with open(spec.datafile, "rb") as fh:
        base = hashlib.sha256(fh.read())
    base.update(json.dumps([spec.commands, spec.record, spec.snapshot]).encode())
    pts = spec.points()
    keys = [None] * len(pts)
    for chain in spec.chains():
        prev = ""
        for i in chain:
            h = base.copy()
            h.update(json.dumps([pts[i], prev], sort_keys=True).encode())
            keys[i] = prev = h.hexdigest()
    return keys


def point_dir(spec: SweepSpec, i: int) -> str:
    """The folder of point ``i``: ``<output>/pNNNN``."""
    return os.path.join(spec.output, f"p{i:04d}")


def finished(spec: SweepSpec, i: int, key: str) -> dict | None:
    """The stored result of point ``i`` if it was finished with ``key``, else None."""
    try:
        with open(os.path.join(point_dir(spec, i), "result.json")) as fh:
            res = json.load(fh)
    except (OSError, ValueError):
        return None
    return res if res.get("key") == key and res.get("status") == "ok" else None


# -- one point -----------------------------------------------------------------------------

def _assign(sess, name, value):
    """``name := value`` in the command language (a plain name must exist)."""
    plain = name.replace("_", "").isalnum()
    if plain and name.lower() not in sess.variables and name.lower() not in sess.settings:
        raise SweepError(f"sweep: '{name}' is not a parameter or variable of "
                         f"{os.path.basename(sess.filename)}")
    sess.run(f"{name} := {value:.17g}", where=f"<sweep parameter {name}>")


def run_point(spec: SweepSpec, i: int, key: str, start: str | None = None) -> dict:
    """Compute point ``i`` (its files in :func:`point_dir`); ``start``: the
    dump of the point it continues from.  Returns its result dict."""
    folder = point_dir(spec, i)
    os.makedirs(folder, exist_ok=True)
    for name in os.listdir(folder):            # temporary files of a killed run
        if name.startswith("."):
            os.remove(os.path.join(folder, name))
    params = spec.points()[i]
    out = io.StringIO()
    t0 = time.perf_counter()
    res = {"index": i, "parameters": params, "key": key, "status": "ok"}
    try:
        sess = Session.load(spec.datafile, out=out, err=out)
        if start is not None:
            sess.replace_load(start)
        for name, value in params.items():
            _assign(sess, name, value)
        sess.run("recalc")
        if spec.commands:
            try:
                sess.run(spec.commands, where="<sweep commands>")
            except Quit:                           # `q` ends the commands
                pass
        sess.recalc(keep_cg=True)
        s, t = sess.surface, sess.totals
        res.update({
            "total_energy": t.energy, "total_area": t.total_area,
            "vertex_count": s.nv, "edge_count": s.ne, "facet_count": s.nf,
            "body_volumes": [float(v) for v in np.atleast_1d(t.volumes)] if s.bodies.n else [],
            "quantities": {k: float(v) for k, v in sess.quantities.items()},
            "record": {e: sess.value(e) for e in spec.record},
            "iterations": len(sess.history)})
        with atomic_path(os.path.join(folder, "final.fe"), ".fe") as tmp:
            dump(sess, tmp)
        with atomic_write(os.path.join(folder, "energies.csv"), newline="") as fh:
            w = csv.writer(fh)
            w.writerow(["iteration", "energy", "area"])
            for it, e, a in sess.history:
                w.writerow([it, repr(float(e)), repr(float(a))])
        if spec.snapshot and s.nf:
            sess.snapshot(os.path.join(folder, "snapshot.png"), field=spec.snapshot,
                          title=", ".join(f"{k} = {v:.4g}" for k, v in params.items()))
    except PyEvolverError as exc:
        res["status"] = "error"
        res["error"] = str(exc)
    res["seconds"] = time.perf_counter() - t0
    with atomic_write(os.path.join(folder, "log.txt")) as fh:
        fh.write(out.getvalue())
    with atomic_write(os.path.join(folder, "result.json")) as fh:
        json.dump(res, fh, indent=1)
    return res


def run_chain(spec: SweepSpec, chain: list[int], keys: list[str]) -> list[dict]:
    """Run the points of ``chain`` in order, skipping finished ones (a
    finished point's dump is the start of the next).  Top level, so that
    process pools and Dask can pickle it."""
    results = []
    start = None
    for i in chain:
        res = finished(spec, i, keys[i])
        if res is None:
            res = run_point(spec, i, keys[i], start)
        else:
            res["reused"] = True                   # not stored: the file is as it was
        results.append(res)
        ok = res["status"] == "ok"
        start = os.path.join(point_dir(spec, i), "final.fe") if (ok and spec.continuation) \
            else None
        if spec.continuation and not ok:
            # the rest of the chain has no surface to start from
            for j in chain[len(results):]:
                results.append({"index": j, "parameters": spec.points()[j], "key": keys[j],
                                "status": "error",
                                "error": f"not run: point {i} before it failed"})
            break
    return results


# -- the sweep ------------------------------------------------------------------------------

@dataclasses.dataclass
class SweepResult:
    """The rows of a finished sweep (by point index) and its output files."""

    rows: list
    table: str
    plot: str | None
    computed: int
    reused: int

    @property
    def failed(self):
        return [r for r in self.rows if r["status"] != "ok"]


def local_executor(workers: int | None = None) -> ProcessPoolExecutor:
    """The default executor: a process pool (``workers`` processes, default
    the number of CPUs) whose workers end when the main process ends, even
    when it is killed (:func:`_end_with_parent`)."""
    return ProcessPoolExecutor(max_workers=workers, initializer=_end_with_parent,
                               initargs=(os.getpid(),))


def _end_with_parent(parent: int) -> None:
    """In a pool worker: end this process when ``parent`` ends.  On Linux
    the kernel sends SIGTERM (``prctl(PR_SET_PDEATHSIG)``); everywhere a
    daemon thread checks the parent every second and exits when it is gone
    (a point half done leaves no ``result.json``: it is run again on resume)."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGTERM, 0, 0, 0)          # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:                          # died before the call
        os._exit(1)

    def watch():
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)
    threading.Thread(target=watch, daemon=True, name="end-with-parent").start()


def dask_executor(address: str) -> tuple[Executor, Any]:
    """``(executor, client)`` for the Dask scheduler at ``address``
    (``tcp://HOST:PORT``); close the client when done."""
    try:
        from distributed import Client
    except ImportError:
        raise SweepError("--scheduler needs Dask distributed: pip install "
                         "'pyevolver[dask]'") from None
    try:
        client = Client(address, timeout=30)
    except (OSError, TimeoutError) as exc:
        raise SweepError(f"cannot reach the Dask scheduler at {address}: {exc}") from None
    return client.get_executor(), client


def run_sweep(spec: SweepSpec, executor: Executor | None = None, workers: int | None = None,
              progress: Any = None, log: Callable[[str], Any] | None = None) -> SweepResult:
    """Run every unfinished point of ``spec`` through ``executor`` (default:
    :func:`local_executor`), then write ``results.csv`` and ``phase.png``.

    ``log(text)`` receives a line about what is done and skipped (default:
    nothing); ``progress`` a tqdm bar over the points (as
    :func:`pyevolver.session.api.progress_bar`).  Returns a :class:`SweepResult`.
    """
    os.makedirs(spec.output, exist_ok=True)
    keys = point_keys(spec)
    pts = spec.points()
    rows = {}
    todo = []
    for chain in spec.chains():
        done = [finished(spec, i, keys[i]) for i in chain]
        if all(d is not None for d in done):
            rows.update({i: d for i, d in zip(chain, done)})
        else:
            todo.append(chain)
    reused = len(rows)
    before = set(rows)
    if log:
        log(f"{len(pts)} points, {reused} finished before, {len(pts) - reused} to run"
            f" in {len(todo)} task{'s' if len(todo) != 1 else ''}")
    own = executor is None and todo
    if own:
        executor = local_executor(workers)
    bar = progress_bar(len(pts), progress, "sweep")
    if bar is not None:
        bar.update(reused)
    try:
        futures = [executor.submit(run_chain, spec, chain, keys) for chain in todo]
        for fut in as_completed(futures):
            for res in fut.result():
                rows[res["index"]] = res
                if bar is not None:
                    bar.update(1)
    finally:
        if bar is not None:
            bar.close()
        if own:
            executor.shutdown()
    ordered = [rows[i] for i in range(len(pts))]
    reused = sum(1 for i, r in rows.items() if r.get("reused") or i in before)
    computed = len(pts) - reused
    table = write_table(spec, ordered)
    plot = None
    try:
        plot = plot_phase(spec, ordered)
    except PyEvolverError as exc:
        if log:
            log(f"no phase diagram: {exc}")
    if log:
        bad = [r for r in ordered if r["status"] != "ok"]
        log(f"wrote {table}" + (f" and {plot}" if plot else "") +
            (f"; {len(bad)} point{'s' if len(bad) != 1 else ''} failed (see their "
             f"result.json)" if bad else ""))
    return SweepResult(ordered, table, plot, computed, reused)


def table_columns(spec: SweepSpec, rows: list[dict]) -> list[str]:
    """Column names of ``results.csv``."""
    cols = ["index"] + list(spec.parameters) + ["status", "total_energy", "total_area",
                                                 "vertex_count", "facet_count"]
    nb = max((len(r.get("body_volumes", [])) for r in rows), default=0)
    cols += [f"body[{k + 1}].volume" for k in range(nb)]
    qn = []
    for r in rows:
        qn += [q for q in r.get("quantities", {}) if q not in qn]
    cols += [f"{q}.value" for q in qn] + list(spec.record)
    return cols


def _row_values(spec, r):
    v = {"index": r["index"], "status": r["status"]}
    v.update(r["parameters"])
    for k in ("total_energy", "total_area", "vertex_count", "facet_count"):
        if k in r:
            v[k] = r[k]
    for k, vol in enumerate(r.get("body_volumes", [])):
        v[f"body[{k + 1}].volume"] = vol
    for q, val in r.get("quantities", {}).items():
        v[f"{q}.value"] = val
    v.update(r.get("record", {}))
    return v


def write_table(spec: SweepSpec, rows: list[dict]) -> str:
    """``results.csv``: one row per point (numbers written so that they read back exactly)."""
    path = os.path.join(spec.output, "results.csv")
    cols = table_columns(spec, rows)
    with atomic_write(path, newline="") as fh:
        w = csv.writer(fh)
        w.writerow(cols)
        for r in rows:
            v = _row_values(spec, r)
            w.writerow([repr(v[c]) if isinstance(v.get(c), float) else v.get(c, "")
                        for c in cols])
    return path


def plot_phase(spec: SweepSpec, rows: list[dict]) -> str:
    """``phase.png``: over two parameters, the points' snapshots in a grid
    (titled with the colour column); over one, the colour column against
    it.  More parameters: the plot is skipped (:class:`SweepError`)."""
    _, Figure, FigureCanvasAgg = _matplotlib()
    names = list(spec.parameters)
    col = spec.plot_color
    vals = [_row_values(spec, r).get(col, math.nan) for r in rows]
    vals = [v if isinstance(v, (int, float)) else math.nan for v in vals]
    path = os.path.join(spec.output, "phase.png")
    if len(names) == 1:
        fig = Figure(figsize=(6.4, 4.0), dpi=100)
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 1, 1)
        ax.plot(spec.parameters[names[0]], vals, "o-")
        ax.set_xlabel(names[0])
        ax.set_ylabel(col)
        ax.grid(True, alpha=0.3)
        fig.tight_layout()
        _save(fig, path)
        return path
    if len(names) != 2:
        raise SweepError("the phase diagram plots one or two parameters")
    from matplotlib.image import imread
    xs, ys = spec.parameters[names[0]], spec.parameters[names[1]]
    pics, clim, label = _phase_pictures(spec, rows)
    bar = clim is not None
    fig = Figure(figsize=(2.2 * len(xs) + (1.8 if bar else 0.8), 2.2 * len(ys) + 0.8), dpi=100)
    FigureCanvasAgg(fig)
    axes = []
    for r, v in zip(rows, vals):
        ix, iy = np.unravel_index(r["index"], (len(xs), len(ys)))
        ax = fig.add_subplot(len(ys), len(xs), (len(ys) - 1 - iy) * len(xs) + ix + 1)
        axes.append(ax)
        png = pics.get(r["index"])
        if png is not None:
            ax.imshow(imread(png))
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f"{col} = {v:.6g}" if r["status"] == "ok" else "failed", fontsize=7)
        if iy == 0:
            ax.set_xlabel(f"{names[0]} = {xs[ix]:.4g}", fontsize=8)
        if ix == 0:
            ax.set_ylabel(f"{names[1]} = {ys[iy]:.4g}", fontsize=8)
    fig.tight_layout(rect=(0, 0, 0.86, 1) if bar else (0, 0, 1, 1))
    if bar:                                   # one colour bar for every panel
        import matplotlib as mpl
        cax = fig.add_axes([0.89, 0.12, 0.025, 0.76])
        cb = fig.colorbar(mpl.cm.ScalarMappable(norm=mpl.colors.Normalize(*clim),
                                                cmap="viridis"), cax=cax,
                          format=mpl.ticker.FormatStrFormatter("%.4g"))
        cb.set_label(label or str(spec.snapshot))
    _save(fig, path)
    for png in pics.values():
        os.remove(png)
    return path


def _phase_pictures(spec: SweepSpec, rows: list[dict]) -> tuple[dict, tuple | None, str]:
    """The phase diagram's panels: each finished point's final surface
    (``final.fe``) drawn without a colour bar, all over one colour range;
    ``({index: temporary png}, (lo, hi) or None, the colour bar's label)``."""
    data = {}
    for r in rows:
        final = os.path.join(point_dir(spec, r["index"]), "final.fe")
        if r["status"] != "ok" or not spec.snapshot or not os.path.isfile(final):
            continue
        try:
            sess = Session.load(final, out=io.StringIO())
            data[r["index"]] = movie.picture_data(sess.surface, spec.snapshot)
        except PyEvolverError:
            continue
    clim = movie.common_range(list(data.values()))
    pics = {}
    for k, pic in data.items():
        path = os.path.join(point_dir(spec, k), ".phase_panel.png")
        pics[k] = movie.draw(pic, path, camera(pic.X, *OBLIQUE), 300, clim, colorbar=False)
    label = next((p.label for p in data.values() if p.label), "")
    return pics, clim, label
