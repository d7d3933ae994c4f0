"""The fast path of ``g`` (pyevolver/evolve/fastpath.py): the same step as
the general one, bit for bit, on the surfaces it takes; the others, and its
rare branches, left to the general step."""
import io

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.evolve import fastpath as FP
from pyevolver.methods import axis_major as AM
from pyevolver.studies.meshes import fe_text, icosphere

from conftest import example

BEND = "quantity bend energy modulus 1 method star_perp_sq_mean_curvature global\n"


def _sphere(tmp_path, header="", bodies=1, extra=""):
    """A prolate 80-facet icosphere with ``bodies`` fixed-volume bodies
    (two: the facets split between them, an open pair)."""
    X, F = icosphere(1)
    X = X * np.array([1.0, 1.0, 1.5])
    text = fe_text(X, F, header)
    nf = len(F)
    if bodies == 1:
        text += "\nbodies\n1 " + " ".join(str(k + 1) for k in range(nf)) + " volume 4.5\n"
    elif bodies == 2:
        text += ("\nbodies\n1 " + " ".join(str(k + 1) for k in range(nf // 2)) + " volume 2\n"
                 "2 " + " ".join(str(k + 1) for k in range(nf // 2, nf)) + " volume 2.2\n")
    path = tmp_path / "sphere.fe"
    path.write_text(text + extra)
    return str(path)


def _run(path, cmds, monkeypatch, fast):
    monkeypatch.setenv("PYEVOLVER_FASTPATH", "1" if fast else "0")
    out = io.StringIO()
    s = Session.load(path, out=out)
    s.run(cmds)
    b = s.surface.bodies
    return (s.total_energy, s.surface.X.copy(), b.lagrange.copy() if b.n else None,
            s.settings["scale"], out.getvalue())


def _same(path, cmds, monkeypatch):
    fast = _run(path, cmds, monkeypatch, True)
    slow = _run(path, cmds, monkeypatch, False)
    assert fast[0] == slow[0]
    assert np.array_equal(fast[1], slow[1])
    assert (fast[2] is None and slow[2] is None) or np.array_equal(fast[2], slow[2])
    assert fast[3] == slow[3]
    assert fast[4] == slow[4]              # the progress lines
    return fast


def _count(monkeypatch):
    """Counts of the steps the fast path took and gave back."""
    n = {"fast": 0, "general": 0}
    orig = FP.step

    def counted(*a):
        r = orig(*a)
        n["general" if r is None else "fast"] += 1
        return r
    monkeypatch.setattr(FP, "step", counted)
    return n


@pytest.mark.parametrize("cmds", ["g 12", "m 0.05; g 6", "fix vertex where id == 3; g 8",
                                  "set facet tension 2 where id < 9; g 8"])
def test_area_and_volume_bit_for_bit(tmp_path, monkeypatch, cmds):
    n = _count(monkeypatch)
    _same(_sphere(tmp_path), cmds, monkeypatch)
    assert n["fast"] >= 6


def test_bending_bit_for_bit(tmp_path, monkeypatch):
    n = _count(monkeypatch)
    _same(_sphere(tmp_path, BEND), "g 8", monkeypatch)
    assert n["fast"] == 8


@pytest.mark.parametrize("kw", [{"bodies": 2}, {"bodies": 0},
                                {"header": "symmetric_content"}])
def test_two_bodies_none_and_symmetric_content(tmp_path, monkeypatch, kw):
    n = _count(monkeypatch)
    _same(_sphere(tmp_path, **kw), "g 8", monkeypatch)
    assert n["fast"] == 8


@pytest.mark.parametrize("kw", [{}, {"bodies": 2}, {"header": "symmetric_content"}])
def test_scatter_axis_by_axis_as_on_large_surfaces(tmp_path, monkeypatch, kw):
    """Above LOW_MEMORY_FACETS the gradients are scattered axis by axis,
    without the concatenated indexes: the same numbers."""
    monkeypatch.setattr(AM, "LOW_MEMORY_FACETS", 0)
    n = _count(monkeypatch)
    _same(_sphere(tmp_path, **kw), "g 4; fix vertex where id == 3; g 4", monkeypatch)
    assert n["fast"] == 8


def test_cube_after_refining(monkeypatch):
    """cube.fe (example): refined between runs, so the plan is made again."""
    n = _count(monkeypatch)
    _same(example("cube.fe"), "g 5; r; g 5", monkeypatch)
    assert n["fast"] == 10


@pytest.mark.parametrize("cmds", ["U; g 4", "set body density 1; recalc; g 4",
                                  "area_normalization; g 4", "set body pressure 1; g 4"])
def test_other_motions_take_the_general_step(tmp_path, monkeypatch, cmds):
    n = _count(monkeypatch)
    _same(_sphere(tmp_path), cmds, monkeypatch)
    assert n["fast"] == 0


def test_a_rare_branch_gives_the_step_back_unchanged(tmp_path, monkeypatch):
    """A step the fast path abandons half-way (here: at its third trial
    move) is taken by the general step from where it started."""
    path = _sphere(tmp_path)
    want = _run(path, "g 3", monkeypatch, False)
    calls = {"n": 0}
    orig = FP._Plan.volumes

    def failing(self, P, symmetric):
        calls["n"] += 1
        if calls["n"] % 3 == 0:
            raise FP._Fallback
        return orig(self, P, symmetric)
    monkeypatch.setattr(FP._Plan, "volumes", failing)
    got = _run(path, "g 3", monkeypatch, True)
    assert got[0] == want[0] and np.array_equal(got[1], want[1]) and got[4] == want[4]


def test_an_unknown_energy_term_turns_it_off(tmp_path, monkeypatch):
    """The area mode checks its evaluation against the general one before a
    run: any difference (an energy it does not know) and the general step
    goes on."""
    path = _sphere(tmp_path)
    real = FP._totals

    def wrong(s, geom, e, vols):
        t = real(s, geom, e, vols)
        t.energy += 1.0
        return t
    monkeypatch.setattr(FP, "_totals", wrong)
    n = _count(monkeypatch)
    _run(path, "g 3", monkeypatch, True)
    assert n["fast"] == 0


def test_the_same_energies_as_the_evolver(tmp_path, evolver):
    """Against evolver-nox-d: the prolate sphere, area and bending."""
    import re
    import subprocess
    for header in ("", BEND):
        path = _sphere(tmp_path, header)
        ref = subprocess.run([evolver, "-p1", path],
                             input='g 10\nprintf "RESULT %.17g\\n", total_energy\nq\nq\n',
                             capture_output=True, text=True, timeout=60).stdout
        want = float(re.findall(r"RESULT (\S+)", ref)[-1])
        s = Session.load(path, out=io.StringIO())
        s.run("g 10")
        assert s.total_energy == pytest.approx(want, rel=1e-12)


def test_hessian_drops_the_plan_and_the_next_g_makes_it_again():
    # (the plan's index arrays need not stay beside the Hessian's factors;
    # the step moves the surface, so the next g could not use the plan)
    s = Session.load(example("cube.fe"), out=io.StringIO())
    s.run("r; r; g 3")
    it = s.iterator
    assert it.__dict__.get("_fast_plan") is not None
    s.hessian(echo=False)
    assert "_fast_plan" not in it.__dict__ and "_end" not in it.__dict__
    s.g(1)
    assert it.__dict__.get("_fast_plan") is not None
