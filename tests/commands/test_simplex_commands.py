"""pyevolver.commands.simplex: the commands in the simplex model against REF
(evolver-nox-d, live): evolution, refinement, queries, REF's errors and
notes for the mesh commands, and the dump.

REF 2.70 run with ``-p1`` (as the reference helpers do) crashes at a ``g``
on a simplex surface that was not refined since loading; without ``-p1`` it
evolves, and those runs are compared here with ``-p1`` left out.
"""
import io
import os
import re
import subprocess

import pytest

from pyevolver import Session
from pyevolver.commands import simplex as CS
from pyevolver.errors import CommandError, PyEvolverError

from conftest import example
from reference import run_reference

DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")
EX = example("simplex3.fe")
G_LINE = re.compile(r"^\s*\d+\. area:\s*(\S+) energy:\s*(\S+)")


def _ours(path, cmds):
    out, err = io.StringIO(), io.StringIO()
    s = Session.load(path, out=out, err=err)
    s.out = out
    s.run(cmds)
    return out.getvalue().splitlines(), s


def _ref_threads(evolver, path, cmds, cwd, p1=False):
    """REF's stdout and stderr, without -p1 (its default threads) unless asked."""
    p = subprocess.run([evolver] + (["-p1"] if p1 else []) + [path],
                       input=cmds + "\nq\nq\n", stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True, timeout=120, cwd=cwd)
    return p.stdout.splitlines()


def _energies(lines):
    return [float(m.group(2)) for m in map(G_LINE.match, lines) if m]


def _numbers(lines):
    return [float(v) for ln in lines if not G_LINE.match(ln)
            for v in re.findall(r"-?\d+\.?\d*(?:e[-+]?\d+)?", ln)]


@pytest.mark.parametrize("path,cmds", [
    (EX, "r\ng 10"), (EX, "r\nr\ng 3"), (EX, "r\nU\ng 5"), (EX, "r\nm 0.05\ng 5"),
    (os.path.join(DATA, "simplex_pressure.fe"), "r\ng 6\nv"),
    (os.path.join(DATA, "simplex_tetra.fe"), "r\ng 8\nv"),
    (os.path.join(DATA, "simplex_4d.fe"), "r\ng 4"),
    (os.path.join(DATA, "simplex_constraint.fe"), "r\ng 6\nr\ng 2"),
    (os.path.join(DATA, "simplex_4d.fe"), "r\narea_normalization\ng 4"),
    (os.path.join(DATA, "simplex_pressure.fe"), "r\narea_normalization\ng 4"),
])
def test_evolution_as_reference(evolver, tmp_path, path, cmds):
    ref = run_reference(evolver, path, cmds, cwd=str(tmp_path))
    ours, _ = _ours(path, cmds)
    re_, oe = _energies(ref), _energies(ours)
    assert len(re_) == len(oe) > 0
    assert all(abs(a - b) <= 1e-9 * max(abs(a), 1e-3) for a, b in zip(re_, oe)), (re_, oe)


def test_unrefined_evolution_as_reference_without_p1(evolver, tmp_path):
    ref = _energies(_ref_threads(evolver, EX, "g 10\nv", str(tmp_path)))
    ours = _energies(_ours(EX, "g 10\nv")[0])
    assert len(ref) == len(ours) == 10
    assert all(abs(a - b) <= 1e-10 for a, b in zip(ref, ours)), (ref, ours)


QUERIES = ("v\nlist vertices where id < 5\nprint total_energy\nprint total_area\n"
           "print vertex_count\nprint edge_count\nprint facet_count\n"
           'printf "%.15g %.15g\\n", sum(vertex, x), sum(facet, area)\n'
           'printf "%.15g\\n", max(edge, length)\nlist facets\nlist bodies\n'
           "print vertex[6].valence\nprint facet[3].valence\n"
           "foreach facet[2].vertex vv do print vv.id\nforeach vertex[1].facet ff do print ff.id")


def test_queries_as_reference(evolver, tmp_path):
    cmds = "r\n" + QUERIES
    ref = [ln for ln in run_reference(evolver, EX, cmds, cwd=str(tmp_path))
           if ln.strip() and "memory" not in ln]
    ours = [ln for ln in _ours(EX, cmds)[0] if ln.strip()]
    assert [ln.split()[:1] for ln in ours] == [ln.split()[:1] for ln in ref]
    assert _numbers(ours) == pytest.approx(_numbers(ref), rel=1e-12)


@pytest.mark.parametrize("path,cmd", [(EX, c) for c in ("w 0.001", "n 0.5", "V", "hessian",
                                                       "g 1\nhessian")]
                         + [(os.path.join(DATA, "simplex_pressure.fe"), "hessian")])
def test_errors_as_reference(evolver, tmp_path, path, cmd):
    ref = _ref_threads(evolver, path, "r\n" + cmd, str(tmp_path), p1=True)
    msg = next(ln for ln in ref if ln.startswith("ERROR"))
    with pytest.raises(CommandError) as exc:
        _ours(path, "r\n" + cmd)
    assert str(exc.value).split(": ", 1)[-1] in msg, (str(exc.value), msg)


@pytest.mark.parametrize("cmd", ["o", "O", "t 0.1", "refine edges"])
def test_notes_as_reference(evolver, tmp_path, cmd):
    cmds = f"r\n{cmd}\nprint total_energy\nprint facet_count"
    def keep(ln):
        return ln.strip() and "memory" not in ln and not ln.startswith("Vertices:")
    ref = [ln for ln in run_reference(evolver, EX, cmds, cwd=str(tmp_path)) if keep(ln)]
    ours = [ln for ln in _ours(EX, cmds)[0] if keep(ln)]
    assert [ln.strip() for ln in ours[:-2]] == [ln.strip() for ln in ref[:-2]]
    assert _numbers(ours[-2:]) == pytest.approx(_numbers(ref[-2:]))


@pytest.mark.parametrize("cmd", ["u", "K 0.2", "l 0.5", "rawv", "j", "delete facet[1]",
                                 "refine facet[1]", "area_normalization\ng 1",
                                 "diffusion\ng 1", "newton", "bfgs 2"])
def test_refused_by_name(cmd):
    with pytest.raises(PyEvolverError, match="not supported in pyevolver: .* simplex model"):
        _ours(EX, "r\n" + cmd)


def test_hessian_without_volumes_refused(tmp_path):
    p = tmp_path / "open.fe"
    p.write_text(open(EX).read().split("bodies")[0])
    with pytest.raises(PyEvolverError, match="not supported in pyevolver: hessian in the simplex"):
        _ours(str(p), "hessian")


@pytest.mark.parametrize("path", [EX, os.path.join(DATA, "simplex_constraint.fe")])
def test_dump_loads_in_both(evolver, tmp_path, path):
    out = str(tmp_path / "ours.dmp")
    _ours(path, f'r\ng 2\ndump "{out}"')
    text = open(out).read()
    assert "SIMPLEX_REPRESENTATION" in text and "SURFACE_DIMENSION 3" in text
    cmds = "print total_energy\nv\ng 3"
    ref = _ref_threads(evolver, out, cmds, str(tmp_path))
    ours = _ours(out, cmds)[0]
    assert _energies(ref) == pytest.approx(_energies(ours), rel=1e-12)
    assert len(_energies(ours)) == 3


def test_answer_table():
    assert "delete" in CS.STATEMENTS and "refine" in CS.STATEMENTS


def test_reference_dump_goes_on_alike(evolver, tmp_path):
    out = str(tmp_path / "ref.dmp")
    run_reference(evolver, EX, f'r\ng 3\ndump "{out}"', cwd=str(tmp_path))
    cmds = "v\ng 3"
    ref = _ref_threads(evolver, out, cmds, str(tmp_path))
    ours = _ours(out, cmds)[0]
    assert len(_energies(ours)) == 3
    assert _energies(ref) == pytest.approx(_energies(ours), rel=1e-12)
