"""Direct tests of pyevolver.cli.tools.convert: .fe to meshio formats and
back; the mesh read back with meshio has the Evolver's vertex and facet
counts (reference run live) and the cube's area 6 and volume 1."""
import argparse
import os

import meshio
import numpy as np
import pytest

from pyevolver import Session
from pyevolver.cli.tools import convert
from pyevolver.errors import PyEvolverError

from reference import numbers
from tolerances import PRINTED

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def run(inp, out):
    parser = argparse.ArgumentParser()
    convert.add_args(parser)
    return convert.run(parser.parse_args([inp, out]))


def area_volume(points, tri):
    P = points[tri]
    cross = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    return 0.5 * np.linalg.norm(cross, axis=1).sum(), np.einsum("ij,ij->", P[:, 0], cross) / 6


def test_fe_to_vtu_read_back(tmp_path, capsys, evolver):
    nv, nf = numbers(evolver, CUBE, ["vertex_count", "facet_count"])
    out = str(tmp_path / "cube.vtu")
    assert run(CUBE, out) == 0
    assert capsys.readouterr().out.strip() == \
        f"{CUBE} -> {out} (vtu): {int(nv)} vertices, {int(nf)} cells"
    m = meshio.read(out)
    tri = np.concatenate([c.data for c in m.cells if c.type == "triangle"])
    assert len(m.points) == nv and len(tri) == nf
    edges = {tuple(sorted(e)) for t in tri for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    assert len(m.points) - len(edges) + len(tri) == 2          # a closed sphere
    area, vol = area_volume(m.points, tri)
    assert area == pytest.approx(6.0, rel=PRINTED)
    assert abs(vol) == pytest.approx(1.0, rel=PRINTED)
    assert m.point_data or m.cell_data                      # data arrays travel along


def test_vtu_back_to_fe(tmp_path, capsys):
    vtu = str(tmp_path / "cube.vtu")
    fe = str(tmp_path / "back.fe")
    assert run(CUBE, vtu) == 0
    assert run(vtu, fe) == 0
    s = Session.load(fe, out=open(os.devnull, "w"))
    m = meshio.read(vtu)
    assert s.surface.nv == len(m.points)
    assert s.total_area == pytest.approx(6.0, rel=PRINTED)


def test_missing_input(tmp_path):
    with pytest.raises(PyEvolverError, match="no such file"):
        run(str(tmp_path / "missing.fe"), str(tmp_path / "x.vtu"))
    assert not (tmp_path / "x.vtu").exists()


def test_unreadable_input(tmp_path):
    bad = tmp_path / "bad.vtu"
    bad.write_text("not a mesh")
    with pytest.raises(PyEvolverError, match="cannot read"):
        run(str(bad), str(tmp_path / "x.obj"))
