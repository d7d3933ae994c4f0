"""Direct tests of the pyevolver.cli.tools package: the subcommand table and
main(), which parses the arguments and turns library errors into exit code 1."""
import importlib
import os

import pytest

from pyevolver.cli import tools

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def test_every_subcommand_module_has_add_args_and_run():
    assert set(tools.SUBCOMMANDS) == {"convert", "show", "sweep", "study"}
    for name, (mod, help_) in tools.SUBCOMMANDS.items():
        m = importlib.import_module(f"pyevolver.cli.tools.{mod}")
        assert callable(m.add_args) and callable(m.run) and help_


def test_main_error_gives_status_1(tmp_path, capsys):
    missing = str(tmp_path / "nothere.fe")
    assert tools.main(["convert", missing, str(tmp_path / "out.vtu")]) == 1
    assert f"cannot open '{missing}'" in capsys.readouterr().err
    assert tools.main(["show", missing, "-o", str(tmp_path / "a.png")]) == 1
    assert "cannot open datafile" in capsys.readouterr().err


def test_main_bad_arguments_exit_2(capsys):
    with pytest.raises(SystemExit) as exc:
        tools.main(["convert", CUBE])              # OUT missing
    assert exc.value.code == 2
    assert "pyevolver convert" in capsys.readouterr().err


def test_main_runs_a_subcommand(tmp_path, capsys):
    out = tmp_path / "cube.obj"
    assert tools.main(["convert", CUBE, str(out)]) == 0
    assert out.exists() and "-> " + str(out) in capsys.readouterr().out
