"""Free vertices on parametric boundaries (spec §6.3): motion in parameter space.

The Evolver moves such vertices by a rule the spec says not to copy, so the
reference numbers come from the same geometry written with level-set
constraints instead of a boundary, run through evolver-nox-d:

* ``mound_boundary.fe`` is mound.fe with its table top (constraint z = 0,
  contact angle 90°) written as the parametric plane ``(p1, p2, 0)``; the
  motion is then exactly the constrained one, so every printed line of
  ``g 10; r; g 5; hessian; hessian`` equals REF's on mound.fe.
* ``catfree_b.fe`` is catbody.fe with its ring vertices unfixed; on a curved
  ring parameter motion and constraint projection agree to second order in
  the step, checked on the first step against ``catfree_c.fe`` (the rings as
  two constraints each) in REF.
"""
import io
import os

import numpy as np

from conftest import example
from reference import run_reference
from pyevolver import Session
from pyevolver.constraints import boundary_eval

DATA = os.path.join(os.path.dirname(os.path.dirname(__file__)), "data")


def _energies(lines):
    return [float(l.split("energy:")[1].split()[0]) for l in lines if "energy:" in l]


def test_plane_boundary_moves_like_the_constraint(evolver, tmp_path):
    cmds = "g 10\nr\ng 5\nhessian\nhessian\n"
    ref = _energies(run_reference(evolver, example("mound.fe"), cmds, cwd=str(tmp_path)))
    out = io.StringIO()
    s = Session.load(os.path.join(DATA, "mound_boundary.fe"), out=out)
    s.run(cmds)
    ours = _energies(out.getvalue().splitlines())
    assert len(ours) == len(ref) == 17
    for a, b in zip(ours, ref):
        assert abs(a - b) <= 1e-12 * abs(b)


def test_ring_vertices_slide_on_their_rings(evolver, tmp_path):
    cmds = "u\nr\ng 1\n"
    ref = _energies(run_reference(evolver, os.path.join(DATA, "catfree_c.fe"), cmds,
                                  cwd=str(tmp_path)))
    s = Session.load(os.path.join(DATA, "catfree_b.fe"), out=io.StringIO())
    s.run("u\nr")
    S = s.surface
    bnd = S.vattr["boundary"]
    P0 = S.vattr["params"][:, 0].copy()
    e = [s.g(1)[0].energy]
    assert abs(e[0] - ref[0]) <= 1e-9 * ref[0]
    for _ in range(5):
        e.append(s.g(1)[0].energy)
    assert all(b <= a for a, b in zip(e, e[1:]))
    moved = bnd != 0
    assert np.abs(S.vattr["params"][moved, 0] - P0[moved]).max() > 1e-6   # they did slide
    for bid in (1, 2):
        rows = np.nonzero(bnd == bid)[0]
        X, _ = boundary_eval(S, bid, S.vattr["params"][rows])
        assert np.abs(S.X[rows] - X).max() <= 1e-15
