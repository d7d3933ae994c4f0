"""Run a datafile over a grid of parameter values: ``pyevolver sweep SPEC.toml``.

Each point gets its own folder (final dump, energies, snapshot, result);
finished points are not computed again when the sweep is run again.  The
points run in a local process pool, or on a Dask distributed cluster with
``--scheduler tcp://HOST:PORT``.  See :mod:`pyevolver.studies.sweep` for the spec.
"""
from __future__ import annotations

import sys

from ...studies.sweep import dask_executor, load_spec, run_sweep


def add_args(parser):
    parser.add_argument("spec", help="sweep specification (TOML)")
    parser.add_argument("--scheduler", metavar="tcp://HOST:PORT",
                        help="run the points on this Dask distributed scheduler")
    parser.add_argument("--workers", type=int, default=None,
                        help="local processes (default: the number of CPUs)")
    parser.add_argument("--no-progress", dest="progress", action="store_false",
                        default=None, help="no progress bar")


def run(args):
    """Returns the exit code: 1 when a point failed."""
    def log(text):
        print(text, flush=True)
    spec = load_spec(args.spec)
    client = executor = None
    if args.scheduler:
        executor, client = dask_executor(args.scheduler)
    try:
        res = run_sweep(spec, executor, workers=args.workers, progress=args.progress, log=log)
    finally:
        if client is not None:
            client.close()
    for r in res.failed:
        sys.stderr.write(f"point {r['index']} {r['parameters']}: {r.get('error')}\n")
    return 1 if res.failed else 0
