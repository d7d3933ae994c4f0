"""Direct tests of pyevolver.commands.extensions: registering a command of
one's own, export / snapshot / plot_history with their argument checks."""
import io
import os

import meshio
import numpy as np
import pytest

from pyevolver import Session
from pyevolver.commands import registry
from pyevolver.commands.extensions import register_command, run_command
from pyevolver.errors import CommandError

from reference import numbers

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def session():
    return Session.load(CUBE, out=io.StringIO(), err=io.StringIO())


def test_register_command_bare_and_call_forms():
    got = []

    @register_command("zz_direct_ext", 'zz_direct_ext "a", "b"', max_args=2)
    def _ext(session, args):
        got.append(list(args))
        session.write(f"ext {len(args)}\n")

    try:
        s = session()
        s.run('zz_direct_ext "one"')
        s.run('zz_direct_ext("one", "two")')
        run_command(s, "zz_direct_ext", [])
        assert got == [["one"], ["one", "two"], []]
        assert s.out.getvalue() == "ext 1\next 2\next 0\n"
        with pytest.raises(CommandError, match="at most 2 arguments"):
            s.run('zz_direct_ext("a", "b", "c")')
        # a user's command of the same name wins
        s.run('zz_direct_ext := { print 5 }')
        s.run("zz_direct_ext")
        assert got == [["one"], ["one", "two"], []]
    finally:
        registry.COMMANDS.pop("zz_direct_ext", None)


def test_export_writes_the_surface(tmp_path, evolver):
    nv, nf = numbers(evolver, CUBE, ["vertex_count", "facet_count"])
    s = session()
    path = str(tmp_path / "cube.vtu")
    s.run(f'export "{path}"')
    assert s.out.getvalue() == f"Exported to {path} (vtu).\n"
    m = meshio.read(path)
    tri = np.concatenate([c.data for c in m.cells if c.type == "triangle"])
    assert len(m.points) == nv and len(tri) == nf
    # the triangles cover the unit cube: area 6
    P = m.points[tri]
    area = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1).sum()
    assert area == pytest.approx(6.0, rel=1e-12)


def test_extension_arguments_checked():
    s = session()
    with pytest.raises(CommandError, match="export needs a file name"):
        s.run("export")
    with pytest.raises(CommandError, match="export needs a file name"):
        s.run("export 3")
    with pytest.raises(CommandError, match="arguments are strings"):
        s.run('snapshot("a.png", 3)')


def test_snapshot_and_plot_history(tmp_path):
    s = session()
    s.run("quietgo; g 2")
    png = tmp_path / "shape.png"
    hist = tmp_path / "hist.png"
    s.run(f'snapshot("{png}", "area")')
    s.run(f'plot_history "{hist}"')
    for p in (png, hist):
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert f"Snapshot written to {png}." in s.out.getvalue()


def test_movie_command(tmp_path, monkeypatch):
    from pyevolver.io import render_vtk
    monkeypatch.setattr(render_vtk, "available", lambda: False)      # matplotlib: quick
    s = session()
    gif = tmp_path / "run.gif"
    s.run(f'movie("{gif}", 4, 2, "area")')
    assert gif.read_bytes()[:6] == b"GIF89a" and len(s.history) == 4
    assert f"Movie written to {gif} (3 frames)." in s.out.getvalue()
    X = s.surface.X.copy()
    for bad, msg in [(f'movie("{tmp_path / "r.avi"}", 4, 2)', "write .gif or .mp4"),
                     (f'movie("{gif}", 4)', "movie needs a file name"),
                     (f'movie("{gif}", 4, 0)', "every >= 1"),
                     (f'movie("{gif}", 2.5, 1)', "movie needs")]:
        with pytest.raises(CommandError, match=msg):
            s.run(bad)
    np.testing.assert_array_equal(s.surface.X, X)       # refused before any step ran
