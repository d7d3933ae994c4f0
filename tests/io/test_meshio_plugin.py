"""The datafile as a meshio format and ``export`` (pyevolver/io/meshio_plugin.py).

Round trips: a datafile read through ``meshio.read`` and written back by
``meshio.write`` loads in pyevolver and in evolver-nox-d with the same
coordinates, counts and area; ``export`` to each listed format reads back
through meshio with the same counts, coordinates and data arrays (the
formats that hold data: vtu and xdmf point and cell data, ply point data).
"""
import io
import os

import meshio
import numpy as np
import pytest

import pyevolver
from pyevolver import Session
from pyevolver.cli.main import main as cli_main
from pyevolver.errors import PyEvolverError
from pyevolver.io.fields import surface_fields
from pyevolver.io import EXPORT_FORMATS

from conftest import example
from reference import numbers

DATA = {"vtu": ("point", "cell"), "xdmf": ("point", "cell"), "ply": ("point",),
        "obj": (), "stl": (), "off": ()}


def _session(path, cmds=""):
    s = Session.load(path, out=io.StringIO(), err=io.StringIO())
    if cmds:
        s.run(cmds)
    return s


def test_meshio_reads_a_datafile():
    m = meshio.read(example("cube.fe"))
    assert len(m.points) == 14 and m.cells[0].type == "triangle" and len(m.cells[0].data) == 24
    assert m.point_data["area"].sum() == pytest.approx(6.0, abs=1e-14)
    assert m.cell_data["area"][0].sum() == pytest.approx(6.0, abs=1e-14)
    pyevolver.io.register()                       # registering again changes nothing
    assert meshio.extension_to_filetypes[".fe"].count("evolver") == 1


def test_meshio_write_datafile_round_trip(evolver, tmp_path):
    """mound after r; g 5 -> meshio mesh -> .fe: the same triangles, fixed
    vertices and area, in pyevolver and in the Evolver."""
    s = _session(example("mound.fe"), "r; g 5")
    mesh = pyevolver.io.surface_mesh(s)
    out = str(tmp_path / "mesh.fe")
    meshio.write(out, mesh)
    s2 = _session(out)
    np.testing.assert_array_equal(s2.surface.X, s.surface.X)
    np.testing.assert_array_equal(s2.surface.F, s.surface.F)
    np.testing.assert_array_equal(s2.surface.vattr["fixed"], s.surface.vattr["fixed"])
    area = s.surface.evaluate().total_area
    assert abs(s2.total_area - area) <= 1e-12 * area
    ref = numbers(evolver, out, ["total_area", "vertex_count", "facet_count"], cwd=str(tmp_path))
    assert abs(ref[0] - area) <= 1e-12 * area
    assert ref[1:] == [s.surface.nv, s.surface.nf]
    again = meshio.read(out)                      # and meshio reads what it wrote
    np.testing.assert_array_equal(again.cells[0].data, s.surface.F)


@pytest.mark.parametrize("ext", sorted(EXPORT_FORMATS))
def test_export_round_trip(tmp_path, ext):
    """The mound (with a constraint) after r; g 5, exported by the command."""
    s = _session(example("mound.fe"), "r; g 5")
    path = str(tmp_path / f"mound{ext}")
    s.out = io.StringIO()
    s.run(f'export "{path}"')
    assert s.out.getvalue() == f"Exported to {path} ({EXPORT_FORMATS[ext]}).\n"
    m = meshio.read(path)
    S = s.surface
    assert len(m.points) == S.nv
    assert [(c.type, len(c.data)) for c in m.cells] == [("triangle", S.nf)]
    if ext == ".stl":          # binary STL: float32, points merged and reordered
        a = np.sort(m.points[m.cells[0].data].reshape(-1, 9), axis=0)
        b = np.sort(S.X[S.F].reshape(-1, 9), axis=0)
        np.testing.assert_allclose(a, b, atol=1e-6)
    else:
        np.testing.assert_array_equal(m.points, S.X)
        np.testing.assert_array_equal(m.cells[0].data, S.F)
    v, f = surface_fields(S)
    assert "on_constraint_1" in v and "mean_curvature" in v
    kinds = DATA[EXPORT_FORMATS[ext]]
    if "point" in kinds:
        assert set(m.point_data) == set(v)
        for k in v:
            np.testing.assert_array_equal(m.point_data[k], v[k], err_msg=k)
    if "cell" in kinds:
        from pyevolver.io.meshio_plugin import body_arrays
        bodies = body_arrays(S)                 # the mound's drop: kept through .fe
        assert set(m.cell_data) == set(f) | set(bodies)
        for k in bodies:
            np.testing.assert_array_equal(m.cell_data[k][0], bodies[k], err_msg=k)
        for k in f:
            np.testing.assert_array_equal(m.cell_data[k][0], f[k], err_msg=k)


def test_export_fe_is_dump(tmp_path):
    s = _session(example("cube.fe"), "r; g 3")
    s.export(str(tmp_path / "c.fe"))
    assert _session(str(tmp_path / "c.fe")).total_energy == pytest.approx(s.total_energy,
                                                                          rel=1e-12)


def test_export_errors_leave_nothing(tmp_path):
    s = _session(example("cube.fe"))
    X = s.surface.X.copy()
    with pytest.raises(PyEvolverError, match=r"<command>:1: export: cannot tell the format"):
        s.run(f'export "{tmp_path}/out.unknownext"')
    with pytest.raises(PyEvolverError, match="export needs a file name in quotes"):
        s.run("export 3")
    with pytest.raises(PyEvolverError, match="cannot write"):
        s.run(f'export "{tmp_path}/no/such/dir/out.vtu"')
    assert os.listdir(tmp_path) == []
    np.testing.assert_array_equal(s.surface.X, X)
    t = _session(example("twointor.fe"))
    with pytest.raises(PyEvolverError, match="not supported in pyevolver: export of a torus"):
        t.run(f'export "{tmp_path}/t.vtu"')


def test_user_procedure_named_export_wins():
    s = _session(example("cube.fe"))
    s.run('export := { printf "mine\\n" }')
    s.out = io.StringIO()
    s.run("export")
    assert s.out.getvalue() == "mine\n"


def test_convert_cli(tmp_path, capsys):
    vtu = str(tmp_path / "cube.vtu")
    assert cli_main(["convert", example("cube.fe"), vtu]) == 0
    assert "14 vertices, 24 cells" in capsys.readouterr().out
    assert cli_main(["convert", vtu, str(tmp_path / "cube.ply")]) == 0
    assert cli_main(["convert", str(tmp_path / "cube.ply"), str(tmp_path / "back.fe")]) == 0
    s = _session(str(tmp_path / "back.fe"))
    assert s.surface.nf == 24 and s.total_area == pytest.approx(6.0, abs=1e-14)
    assert cli_main(["convert", str(tmp_path / "missing.fe"), vtu]) == 1
    assert "no such file" in capsys.readouterr().err


def _two_cells(tmp_path):
    """Two unit cubes stacked along z sharing the square z = 1 (its facets
    bound body 1 with their front and body 2 with their back), written as a
    datafile: body 1 volume 1 density 2, body 2 pressure 3."""
    from pyevolver.datafile.writer import write_fe
    from pyevolver.model.arrays import surface_from_arrays
    X = np.array([(x, y, z) for z in (0, 1, 2) for y in (0, 1) for x in (0, 1)], float)
    v = {tuple(p): k for k, p in enumerate(X.astype(int).tolist())}

    F, owner = [], []

    def add(quad, centre):
        for tri in ([quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]):
            n = np.cross(X[tri[1]] - X[tri[0]], X[tri[2]] - X[tri[0]])
            if n @ (X[tri].mean(0) - centre) < 0:
                tri = tri[::-1]
            F.append(tri)
    for body, z0 in ((1, 0), (2, 1)):
        centre = np.array([0.5, 0.5, z0 + 0.5])
        for axis in (0, 1):
            for c in (0, 1):
                quad = [v[(c, a, z0 + b)] if axis == 0 else v[(b, c, z0 + a)]
                        for a, b in ((0, 0), (1, 0), (1, 1), (0, 1))]
                add(quad, centre)
                owner += [body, body]
        if body == 1:
            add([v[(0, 0, 0)], v[(1, 0, 0)], v[(1, 1, 0)], v[(0, 1, 0)]], centre)
            owner += [1, 1]
            add([v[(0, 0, 1)], v[(1, 0, 1)], v[(1, 1, 1)], v[(0, 1, 1)]], centre)
            owner += [12, 12]                       # the shared square
        else:
            add([v[(0, 0, 2)], v[(1, 0, 2)], v[(1, 1, 2)], v[(0, 1, 2)]], centre)
            owner += [2, 2]
    ids = np.arange(1, len(F) + 1)
    owner = np.array(owner)
    b1 = [int(i) for i in ids[(owner == 1) | (owner == 12)]]
    b2 = [int(i) for i in ids[owner == 2]] + [-int(i) for i in ids[owner == 12]]
    s = surface_from_arrays(X, np.array(F), bodies=[
        (b1, [("volume", [1.0]), ("density", [2.0])]), (b2, [("pressure", [3.0])])])
    path = str(tmp_path / "two.fe")
    write_fe(s, path)
    return path


def test_convert_keeps_the_bodies(tmp_path, evolver):
    """.fe -> .vtu -> .fe: the bodies, their facets (and sides), prescribed
    volume, density and pressure survive, in pyevolver and in the Evolver."""
    src = _two_cells(tmp_path)
    vtu, back = str(tmp_path / "two.vtu"), str(tmp_path / "back.fe")
    assert cli_main(["convert", src, vtu]) == 0
    m = meshio.read(vtu)
    assert sorted(set(m.cell_data["frontbody"][0].tolist())) == [1, 2]
    assert sorted(set(m.cell_data["backbody"][0].tolist())) == [0, 2]
    assert cli_main(["convert", vtu, back]) == 0
    a, b = _session(src), _session(back)
    ba, bb = a.surface.bodies, b.surface.bodies
    assert bb.n == ba.n == 2
    assert (bb.facet_matrix != ba.facet_matrix).nnz == 0
    np.testing.assert_array_equal(bb.target, ba.target)          # [1, nan]
    np.testing.assert_array_equal(bb.density, [2.0, 0.0])
    np.testing.assert_array_equal(bb.pressure, ba.pressure)      # [nan, 3]
    vols = [b.value("body[1].volume"), b.value("body[2].volume")]
    assert vols == pytest.approx([1.0, 1.0], abs=1e-14)
    assert b.total_energy == pytest.approx(a.total_energy, rel=1e-14)
    ref = numbers(evolver, back, ["body[1].volume", "body[2].volume", "body[1].target",
                                  "body[2].pressure", "total_energy"], cwd=str(tmp_path))
    assert ref == pytest.approx([1.0, 1.0, 1.0, 3.0, b.total_energy], rel=1e-12)
