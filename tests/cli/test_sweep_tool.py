"""Direct tests of pyevolver.cli.tools.sweep: the command line of a
parameter sweep; each point's energy is the reference Evolver's for the same
target and commands (run live); a failed point gives exit status 1."""
import argparse
import csv
import json
import os
import shutil

import pytest

from pyevolver.cli.tools import sweep

from reference import run_reference
from tolerances import STEPS

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def args(*argv):
    parser = argparse.ArgumentParser()
    sweep.add_args(parser)
    return parser.parse_args(list(argv))


def spec(tmp_path, commands, targets):
    shutil.copy(CUBE, tmp_path / "cube.fe")
    p = tmp_path / "spec.toml"
    p.write_text(f'datafile = "cube.fe"\ncommands = "{commands}"\nsnapshot = false\n\n'
                 f'[parameters]\n"body[1].target" = {targets}\n')
    return str(p)


def test_arguments():
    a = args("s.toml")
    assert (a.spec, a.scheduler, a.workers, a.progress) == ("s.toml", None, None, None)
    a = args("s.toml", "--workers", "2", "--no-progress", "--scheduler", "tcp://h:1")
    assert (a.workers, a.progress, a.scheduler) == (2, False, "tcp://h:1")


def test_sweep_points_match_reference(tmp_path, capsys, evolver):
    path = spec(tmp_path, "quietgo; g 2", "[1.0, 2.0]")
    assert sweep.run(args(path, "--workers", "1", "--no-progress")) == 0
    assert "results.csv" in capsys.readouterr().out
    with open(tmp_path / "spec_out" / "results.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["status"] for r in rows] == ["ok", "ok"]
    for r in rows:
        t = float(r["body[1].target"])
        lines = run_reference(evolver, CUBE, f"body[1].target := {t}\nrecalc\nQUIETGO\ng 2\n"
                              'printf "RESULT %.17g\\n", total_energy\n')
        e = [float(l.split()[1]) for l in lines if l.startswith("RESULT")][0]
        assert float(r["total_energy"]) == pytest.approx(e, rel=STEPS)
        res = json.loads((tmp_path / "spec_out" / f"p{int(r['index']):04d}" /
                          "result.json").read_text())
        assert res["vertex_count"] - res["edge_count"] + res["facet_count"] == 2


def test_failed_point_exit_status(tmp_path, capsys):
    path = spec(tmp_path, "print nosuchname", "[1.0]")
    assert sweep.run(args(path, "--workers", "1", "--no-progress")) == 1
    assert "point 0" in capsys.readouterr().err
