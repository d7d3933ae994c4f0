"""Direct tests of pyevolver.studies.phase_newton: restoring the fixed values
after a change of the target volume, and Newton on the critical-point
equations, which finds the saddles of the unstable part of a branch.

Known stable and unstable points: near the sphere the oblate ellipsoid is a
saddle of the bending energy at fixed area and volume (on the degree-2
harmonics at fixed v the cubic term of W is largest at the oblate axis, so
two non-axisymmetric directions lower W towards the prolate), and the
prolate at v = 0.85 is the global minimum (Seifert, Berndl & Lipowsky 1991);
the axisymmetric references come from pyevolver.studies.axisymmetric."""
import math
import os

import numpy as np
import pytest

from pyevolver.studies import phase_study as PS
from pyevolver.studies.axisymmetric import canham_reference
from pyevolver.studies.phase_mesh import revolve
from pyevolver.studies.phase_newton import newton_critical, restore
from pyevolver.studies.phase_stability import lowest_eigenvalues
from pyevolver.studies.vesicle_newton import newton_lm
from pyevolver.studies.vesicle_shapes import mesh_descriptors

NV = 150


def _start(branch, v, tmp):
    os.makedirs(tmp, exist_ok=True)
    ref = canham_reference(v, branch, n=16)
    X, F = revolve(ref.s, ref.r, ref.z, NV, area=4 * math.pi)
    s = PS._session(X, F, v, PS.lam_for(NV), tmp)
    restore(s)
    return s, ref


def test_restore_meets_a_changed_volume(tmp_path):
    s, _ = _start("prolate", 0.85, str(tmp_path))
    s.run("body[1].target := 0.85*4*pi/3")
    restore(s)
    s.run("body[1].target := 0.8*4*pi/3")
    s.recalc()
    target = 0.8 * 4 * math.pi / 3
    assert abs(s.totals.volumes[0] - target) > 1e-2
    restore(s)
    assert abs(s.totals.volumes[0] - target) < 1e-8
    assert abs(s.totals.quantity_values["surf"] - 4 * math.pi) < 1e-8


def test_oblate_near_the_sphere_is_a_saddle_the_prolate_a_minimum(tmp_path):
    # the oblate at v = 0.9: damped descent leaves the branch ...
    s, _ = _start("oblate", 0.9, str(tmp_path / "a"))
    newton_lm(s, maxit=40)
    assert mesh_descriptors(s.surface.X, s.surface.F)["type"] == "prolate"
    # ... Newton on the critical-point equations stays: a saddle
    s, ref = _start("oblate", 0.9, str(tmp_path / "b"))
    ok, _, _ = newton_critical(s)
    assert ok
    assert mesh_descriptors(s.surface.X, s.surface.F)["type"] == "oblate"
    assert abs(s.totals.quantity_values["willmore"] / ref.W - 1) < 0.03
    assert lowest_eigenvalues(s, k=2)[0] < -0.5
    # the prolate at v = 0.85: a minimum, found by either solver
    s, ref = _start("prolate", 0.85, str(tmp_path / "c"))
    ok, _, _ = newton_critical(s)
    assert ok and lowest_eigenvalues(s, k=2)[0] > 1.0
