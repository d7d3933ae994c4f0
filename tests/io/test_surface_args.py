"""io and datafile writers on a bare Surface with explicit arguments
(pyevolver/io/render.py, pyevolver/io/meshio_plugin.py,
pyevolver/datafile/writer.py): no session needed."""
import io

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.datafile.writer import DumpSettings, dump
from pyevolver.io import meshio_plugin as MP
from pyevolver.io.render import camera, plot_history, snapshot
from pyevolver.model.arrays import surface_from_arrays

from conftest import example

X = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
              [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])


def test_dump_of_a_surface_with_and_without_settings(tmp_path):
    s = surface_from_arrays(X, F, body=True)
    bare, full = str(tmp_path / "bare.fe"), str(tmp_path / "full.fe")
    dump(s, bare)
    dump(s, full, settings=DumpSettings("octa.fe", {"scale": 0.25, "scale_limit": 1.0,
                                                    "constraint_tolerance": 1e-12},
                                        {"conj_grad": 1}))
    text_bare, text_full = open(bare).read(), open(full).read()
    assert "SCALE" not in text_bare and "read" not in text_bare.split()
    assert "(datafile octa.fe)" in text_full and "SCALE 0.25" in text_full
    assert "conj_grad on" in text_full
    back = Session.load(full, out=io.StringIO())
    assert back.surface.evaluate().total_area == pytest.approx(s.evaluate().total_area,
                                                               rel=1e-15)
    assert back.settings["scale"] == 0.25 and back.toggles.get("conj_grad")


def test_session_dump_equals_dump_with_its_settings(tmp_path):
    sess = Session.load(example("cube.fe"), out=io.StringIO())
    sess.run("g 3")
    a, b = str(tmp_path / "a.fe"), str(tmp_path / "b.fe")
    dump(sess, a)             # an object holding a surface: its settings are written
    dump(sess.surface, b, settings=DumpSettings.of(sess))
    assert open(a).read() == open(b).read()


def test_load_surface_and_surface_mesh():
    s = MP.load_surface(example("cube.fe"))
    mesh = MP.surface_mesh(s)
    assert mesh.points.shape == (s.nv, 3)
    assert mesh.cell_data["area"][0].sum() == pytest.approx(6.0, abs=1e-14)
    with pytest.raises(Exception, match="no surface"):
        MP.surface_mesh(None)


def test_mesh_surface_uses_the_arrays():
    meshio = pytest.importorskip("meshio")
    mesh = meshio.Mesh(X, [("triangle", F)], point_data={"fixed": np.arange(6) == 0},
                       cell_data={"tension": [np.full(8, 2.0)]})
    s = MP._mesh_surface(mesh, "m.fe")
    assert s.vattr["fixed"].tolist() == [True] + [False] * 5
    assert s.evaluate().energy == pytest.approx(2 * 8 * np.sqrt(3) / 2)


def test_snapshot_and_history_without_a_session(tmp_path):
    pytest.importorskip("matplotlib")
    s = surface_from_arrays(X, F)
    p = snapshot(s, str(tmp_path / "o.png"), field="area", size=120,
                 view=camera(s.X, azimuth=20, elevation=10))
    assert open(p, "rb").read(4) == b"\x89PNG"
    q = plot_history([(1, 3.0, 2.0), (2, 2.5, 2.0), (3, 2.4, 2.0)], str(tmp_path / "h.png"))
    assert open(q, "rb").read(4) == b"\x89PNG"
    with pytest.raises(Exception, match="no iterations"):
        plot_history([], str(tmp_path / "e.png"))
