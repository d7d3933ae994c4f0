"""Direct tests of pyevolver.cli.tools.study: ``pyevolver study phase``
parses the study's options and refuses what the study does not support by
name (exit status 1, no traceback)."""
import argparse

from pyevolver.cli.main import main
from pyevolver.cli.tools import study


def test_arguments():
    parser = argparse.ArgumentParser()
    study.add_args(parser)
    a = parser.parse_args(["phase", "--nv", "300", "--volumes", "0.6,0.7", "--no-plot"])
    assert (a.study, a.nv, a.volumes, a.plot, a.c0) == ("phase", 300, "0.6,0.7", False, 0.0)
    assert a.branches == "prolate,oblate,stomatocyte"


def test_spontaneous_curvature_and_method_are_options():
    parser = argparse.ArgumentParser()
    study.add_args(parser)
    a = parser.parse_args(["phase", "--c0", "0.5", "--method", "star_perp_sq_mean_curvature"])
    assert (a.c0, a.method) == (0.5, "star_perp_sq_mean_curvature")


def test_unknown_branch_is_refused_by_name(tmp_path, capsys):
    code = main(["study", "phase", "--branches", "prolate,bogus", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 1
    assert "unknown branch 'bogus'" in err and err.startswith("pyevolver study: ")
    assert "Traceback" not in err
