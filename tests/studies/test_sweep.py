"""Parameter sweeps (pyevolver/sweep.py, ``pyevolver sweep``).

Eight points (body volume × density of a drop under gravity) run in the
default local process pool and on a Dask ``LocalCluster`` on 127.0.0.1 and
give byte-identical tables; a sweep killed halfway and run again reuses
its finished points untouched; one point is checked against evolver-nox-d
running the same commands.
"""
import io
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from pyevolver import Session
from pyevolver.cli.main import main as cli_main
from pyevolver.studies.sweep import SweepError, load_spec, run_sweep, spec_from_dict

from reference import run_reference

HERE = os.path.dirname(os.path.dirname(__file__))
DROP = os.path.join(HERE, "data", "sweep_drop.fe")
COMMANDS = "r; g 20; r; g 10"
GRID = {"body[1].target": [0.8, 1.0, 1.2, 1.4], "body[1].density": [0.0, 0.5]}


def _toml(tmp, output, snapshot=True, extra=""):
    path = os.path.join(tmp, output + ".toml")
    snap = '"mean_curvature"' if snapshot else "false"
    with open(path, "w") as fh:
        fh.write(f'datafile = "{DROP}"\noutput = "{output}"\ncommands = "{COMMANDS}"\n'
                 f'record = ["max(vertex, z)"]\nsnapshot = {snap}\n{extra}\n[parameters]\n'
                 '"body[1].target" = [0.8, 1.0, 1.2, 1.4]\n'
                 '"body[1].density" = {start = 0.0, stop = 0.5, num = 2}\n')
    return path


def _table(spec):
    with open(os.path.join(spec.output, "results.csv")) as fh:
        return fh.read()


@pytest.fixture(scope="module")
def local(tmp_path_factory):
    """The 8-point sweep in the default executor (a local pool of 2 processes)."""
    tmp = str(tmp_path_factory.mktemp("sweep"))
    spec = load_spec(_toml(tmp, "local"))
    res = run_sweep(spec, workers=2, progress=False)
    return tmp, spec, res


def test_local_sweep_writes_every_point(local):
    _, spec, res = local
    assert res.computed == 8 and res.reused == 0 and not res.failed
    assert [r["parameters"] for r in res.rows] == spec.points()
    assert spec.points()[3] == {"body[1].target": 1.0, "body[1].density": 0.5}
    for r in res.rows:
        d = os.path.join(spec.output, f"p{r['index']:04d}")
        assert sorted(os.listdir(d)) == ["energies.csv", "final.fe", "log.txt", "result.json",
                                         "snapshot.png"]
        s = Session.load(os.path.join(d, "final.fe"), out=io.StringIO())
        assert abs(s.total_energy - r["total_energy"]) <= 1e-12 * r["total_energy"]
        assert s.surface.nf == r["facet_count"] == 384
        assert abs(r["body_volumes"][0] - r["parameters"]["body[1].target"]) < 1e-4
        with open(os.path.join(d, "energies.csv")) as fh:
            last = fh.read().splitlines()[-1].split(",")
        assert last[0] == str(r["iterations"]) == "30"
    # the density pulls the drop down: lower top, higher energy, at each volume
    for a, b in zip(res.rows[0::2], res.rows[1::2]):
        assert b["record"]["max(vertex, z)"] < a["record"]["max(vertex, z)"]
        assert b["total_energy"] > a["total_energy"]
    assert os.path.getsize(res.plot) > 1000
    assert _table(spec).splitlines()[0] == ('index,body[1].target,body[1].density,status,'
                                            'total_energy,total_area,vertex_count,facet_count,'
                                            'body[1].volume,"max(vertex, z)"')


def test_phase_panels_share_one_colour_range_and_bar(local):
    """The phase diagram redraws each point without its own colour bar, all
    over one range (the lowest to the highest of the points' ranges), and
    draws one colour bar for the panels."""
    import numpy as np
    from matplotlib.image import imread
    from pyevolver.io import movie
    from pyevolver.studies.sweep import _phase_pictures
    _, spec, res = local
    rows = [res.rows[0], res.rows[-1]]          # two panels: the lightest and the heaviest
    pics, clim, label = _phase_pictures(spec, rows)
    assert sorted(pics) == [0, 7] and label.startswith("mean curvature")
    ranges = []
    for r in rows:
        s = Session.load(os.path.join(spec.output, f"p{r['index']:04d}", "final.fe"),
                         out=io.StringIO())
        ranges.append(movie.common_range([movie.picture_data(s.surface, "mean_curvature")]))
    assert clim == (min(a for a, _ in ranges), max(b for _, b in ranges))
    for png in pics.values():
        img = imread(png)[:, :, :3]
        cols = np.nonzero(np.any(img[: int(0.9 * img.shape[0])] < 0.9, axis=(0, 2)))[0]
        # no bar in the right fifth: the surface is framed on the whole width
        assert cols.max() - cols.min() > 0.85 * img.shape[1], "a panel kept room for a bar"
        os.remove(png)
    big = imread(res.plot)[:, :, :3]
    bar = big[:, int(0.88 * big.shape[1]):int(0.93 * big.shape[1])]
    assert len(np.unique((bar.reshape(-1, 3) * 255).round(), axis=0)) > 50   # the one bar


def test_point_agrees_with_reference(local, evolver):
    tmp, _, res = local
    r = res.rows[5]                                    # target 1.2, density 0.5
    cmds = "body[1].target := 1.2; body[1].density := 0.5; recalc; " + COMMANDS
    lines = run_reference(evolver, DROP, cmds + '\nprintf "RESULT %.17g\\n", total_energy\n',
                          cwd=tmp)
    ref = [float(ln.split()[1]) for ln in lines if ln.startswith("RESULT")]
    assert len(ref) == 1, lines
    assert abs(r["total_energy"] - ref[0]) <= 1e-9 * ref[0], (r["total_energy"], ref[0])


def test_dask_local_cluster_gives_identical_results(local):
    distributed = pytest.importorskip("distributed")
    tmp, spec, _ = local
    toml = _toml(tmp, "dask", snapshot=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  host="127.0.0.1", protocol="tcp", dashboard_address=None,
                                  silence_logs=40) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        rc = cli_main(["sweep", toml, "--scheduler", cluster.scheduler_address,
                       "--no-progress"])
    assert rc == 0
    assert _table(load_spec(toml)) == _table(spec)


def test_killed_sweep_resumes_without_recomputing(local):
    tmp, spec, _ = local
    toml = _toml(tmp, "killed")
    out = os.path.join(tmp, "killed")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    proc = subprocess.Popen([sys.executable, "-m", "pyevolver", "sweep", toml, "--workers", "1",
                             "--no-progress"], env=env, start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def done():
        return sorted(p for p in (os.listdir(out) if os.path.isdir(out) else [])
                      if os.path.isfile(os.path.join(out, p, "result.json")))
    try:
        t0 = time.time()
        while len(done()) < 3 and time.time() - t0 < 60 and proc.poll() is None:
            time.sleep(0.01)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)           # the CLI and its pool worker
        proc.wait()
    finished = done()
    assert 3 <= len(finished) < 8, finished
    stamps = {p: os.stat(os.path.join(out, p, "result.json")).st_mtime_ns for p in finished}
    logs = []
    res = run_sweep(load_spec(toml), workers=1, progress=False, log=logs.append)
    assert logs[0].startswith(f"8 points, {len(finished)} finished before")
    assert res.reused == len(finished) and res.computed == 8 - len(finished)
    for p in finished:
        assert os.stat(os.path.join(out, p, "result.json")).st_mtime_ns == stamps[p]
    assert not [n for p in os.listdir(out) if os.path.isdir(os.path.join(out, p))
                for n in os.listdir(os.path.join(out, p)) if n.startswith(".")]
    assert _table(load_spec(toml)) == _table(spec)


def test_continuation_chain_and_partial_resume(tmp_path):
    raw = {"datafile": DROP, "output": "chain", "commands": "r; g 2", "snapshot": False,
           "parameters": {"body[1].target": [1.0, 1.1, 1.2]},
           "continuation": {"parameter": "body[1].target"}}
    spec = spec_from_dict(raw, str(tmp_path))
    assert spec.chains() == [[0, 1, 2]]
    res = run_sweep(spec, workers=1, progress=False)
    # each point refines the surface it starts from: 24 -> 96 -> 384 -> 1536 facets
    assert [r["facet_count"] for r in res.rows] == [96, 384, 1536]
    os.remove(tmp_path / "chain" / "p0002" / "result.json")
    again = run_sweep(spec_from_dict(raw, str(tmp_path)), workers=1, progress=False)
    assert again.computed == 1 and again.reused == 2
    assert again.rows[2]["total_energy"] == res.rows[2]["total_energy"]
    assert os.path.getsize(again.plot) > 1000                      # one parameter: a line
    # another datafile text changes every key: nothing is reused
    raw2 = dict(raw, commands="r; g 3")
    assert run_sweep(spec_from_dict(raw2, str(tmp_path)), workers=1,
                     progress=False).computed == 3


def test_bad_specs_are_located(tmp_path, capsys):
    def bad(raw, match):
        with pytest.raises(SweepError, match=match):
            spec_from_dict(raw, str(tmp_path), "spec.toml")
    ok = {"datafile": DROP, "parameters": {"body[1].target": [1.0]}}
    bad(dict(ok, colour="x"), r"spec.toml: unknown key colour")
    bad(dict(ok, datafile="nope.fe"), r"spec.toml: datafile 'nope.fe' not found")
    bad(dict(ok, parameters={}), r"\[parameters\] table")
    bad(dict(ok, parameters={"a": "x"}), r"parameter 'a': expected a number")
    bad(dict(ok, continuation={"parameter": "zz"}), r"continuation parameter 'zz'")
    # the grid's size is checked before anything runs (no MemoryError)
    huge = {f"p{k}": {"start": 0, "stop": 1, "num": 1000} for k in range(4)}
    bad(dict(ok, parameters=huge), r"spec.toml: the grid has 1,000,000,000,000 points")
    bad(dict(ok, parameters={"a": {"start": 0, "stop": 1, "num": 10**12}}), r"num = ")
    p = tmp_path / "broken.toml"
    p.write_text('datafile = "x\n')
    assert cli_main(["sweep", str(p)]) == 1
    assert "broken.toml" in capsys.readouterr().err
    # a parameter the datafile does not have: the point fails, by name
    spec = spec_from_dict(dict(ok, parameters={"nosuch": [1.0]}, snapshot=False),
                          str(tmp_path))
    res = run_sweep(spec, workers=1, progress=False)
    assert res.failed and "'nosuch' is not a parameter or variable" in res.failed[0]["error"]
    with open(os.path.join(spec.output, "p0000", "result.json")) as fh:
        assert json.load(fh)["status"] == "error"


def test_workers_end_when_the_main_process_is_killed(tmp_path):
    """SIGKILL of the sweep's main process (no chance to clean up): its pool
    workers end too (PR_SET_PDEATHSIG / a watcher thread)."""
    from pyevolver.studies import sweep as SW
    if not os.path.isdir("/proc"):
        pytest.skip("needs /proc to list the workers")
    script = (
        "import os, sys, time\n"
        f"sys.path[:0] = {sys.path!r}\n"
        "from pyevolver.studies.sweep import local_executor\n"
        "ex = local_executor(2)\n"
        "futs = [ex.submit(time.sleep, 600) for _ in range(2)]\n"
        "time.sleep(1.0)\n"
        "print(' '.join(str(p) for p in ex._processes), flush=True)\n"
        "time.sleep(600)\n")
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    pids = [int(p) for p in proc.stdout.readline().split()]
    assert len(pids) == 2 and SW.MAX_POINTS > 0
    proc.kill()
    proc.wait()
    t0 = time.time()
    while time.time() - t0 < 30 and any(_alive(p) for p in pids):
        time.sleep(0.1)
    assert not any(_alive(p) for p in pids)


def _alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False
