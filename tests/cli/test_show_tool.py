"""Direct tests of pyevolver.cli.tools.show: a datafile rendered headless to
an image, after -c commands, with the requested width."""
import argparse
import os
import struct

import pytest

from pyevolver.cli.tools import show
from pyevolver.errors import CommandError, PyEvolverError

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def args(*argv):
    parser = argparse.ArgumentParser()
    show.add_args(parser)
    return parser.parse_args(list(argv))


def png_size(path):
    data = open(path, "rb").read(24)
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def test_defaults():
    a = args(CUBE, "-o", "x.png")
    assert (a.field, a.azimuth, a.elevation, a.size, a.commands) == \
        ("auto", 0.0, 0.0, 600, "")


def test_renders_png_of_the_requested_width(tmp_path, capsys):
    out = str(tmp_path / "cube.png")
    assert show.run(args(CUBE, "-o", out, "-c", "r", "--azimuth", "30",
                         "--elevation", "20", "--size", "240", "--field", "area")) == 0
    assert capsys.readouterr().out.strip() == f"wrote {out}"
    w, h = png_size(out)
    assert w == 240 and h > 0


def test_errors(tmp_path):
    with pytest.raises(PyEvolverError, match="cannot open datafile"):
        show.run(args(str(tmp_path / "none.fe"), "-o", str(tmp_path / "a.png")))
    with pytest.raises(CommandError, match="<-c>"):
        show.run(args(CUBE, "-o", str(tmp_path / "a.png"), "-c", "print nosuchname"))
    assert not (tmp_path / "a.png").exists()
