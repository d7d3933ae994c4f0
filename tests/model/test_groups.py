"""pyevolver.model.groups: the built-in symmetry groups' elements against
evolver-nox-d run live: ``wrap_compose`` / ``wrap_inverse`` over tables of
codes, and each code's map, read from REF's edge lengths (three tails at the
unit vectors and one at the origin, one head: |g(q) - e_i|^2 gives g(q))."""
import itertools
import re

import numpy as np
import pytest

from pyevolver.model.groups import NAMES, Group, function_value
from reference import run_reference

PARAMS = {
    "rotate": {"rotation_order": 6, "generator_power": 2},
    "flip_rotate": {"rotation_order": 6},
    "xyz": {}, "cubocta": {}, "cubelat": {}, "central_symmetry": {},
    "screw_symmetry": {"screw_height": 0.3, "screw_angle": 30},
    "quarter_turn": {"quarter_turn_period": 2},
}


def _torus(t):
    return sum((int(t[d]) & 31) << (6 * d) for d in range(3))


def _codes(name):
    rng = np.random.default_rng(7)
    if name in ("rotate", "flip_rotate", "xyz", "screw_symmetry"):
        return list(range(-7, 8))
    if name == "central_symmetry":
        return list(range(0, 6))
    if name == "cubocta":
        return list(range(64))
    if name == "cubelat":
        return [int(r) + 64 * _torus(rng.integers(-2, 3, 3)) for r in rng.integers(0, 64, 30)]
    return [_torus(t) for t in itertools.product(range(-1, 2), repeat=3)] + [_torus((2, -1, 3))]


def _header(name, tmp_path):
    lines = [f'symmetry_group "{name}"'] + [f"parameter {k} = {v}" for k, v in PARAMS[name].items()]
    return lines


@pytest.mark.parametrize("name", NAMES)
def test_products_and_inverses_as_the_evolver(evolver, name, tmp_path):
    codes = _codes(name)
    if name == "cubocta":
        codes = codes[::3]
    path = tmp_path / "g.fe"
    path.write_text("\n".join(_header(name, tmp_path) + ["vertices", "1 0 0 0"]) + "\n")
    cmds = []
    for a in codes:
        cmds.append(f'printf "I %.0f\\n", wrap_inverse({a})')
        cmds += [f'printf "C %.0f\\n", wrap_compose({a},{b})' for b in codes]
    out = run_reference(evolver, str(path), "\n".join(cmds))
    got = [int(ln.split()[1]) for ln in out if re.match(r"^[IC] -?\d+$", ln)]
    g = Group(name, PARAMS[name])
    want = []
    for a in codes:
        want.append(int(function_value(g, "wrap_inverse", a)))
        want += function_value(g, "wrap_compose", np.full(len(codes), a),
                               np.array(codes)).astype(np.int64).tolist()
    assert got == want


@pytest.mark.parametrize("name", NAMES)
def test_maps_as_the_evolver(evolver, name, tmp_path):
    codes = _codes(name)
    q = np.array([0.31, 0.57, 0.83])
    lines = _header(name, tmp_path) + ["vertices", "1 1 0 0", "2 0 1 0", "3 0 0 1", "4 0 0 0",
                                       f"5 {q[0]} {q[1]} {q[2]}", "edges"]
    k = 0
    for c in codes:
        for tail in (1, 2, 3, 4):
            k += 1
            lines.append(f"{k} {tail} 5 wrap {c}")
    path = tmp_path / "m.fe"
    path.write_text("\n".join(lines) + "\n")
    out = run_reference(evolver, str(path),
                        'foreach edge ee do printf "E %.17g\\n", ee.length')
    L = np.array([float(ln.split()[1]) for ln in out if ln.startswith("E ")]).reshape(-1, 4) ** 2
    ref = (L[:, 3:4] + 1 - L[:, :3]) / 2                  # g(q)
    A, b = Group(name, PARAMS[name]).affine(np.array(codes))
    ours = np.einsum("nij,j->ni", A, q) + b
    assert np.allclose(ours, ref, atol=1e-12)


def test_geometry_of_the_cube_group():
    """cubocta's maps are signed permutations; code 40 = swap after one cycle."""
    A, b = Group("cubocta", {}).affine(np.arange(64))
    assert np.allclose(np.abs(np.linalg.det(A)), 1) and not b.any()
    assert np.allclose(A[40] @ [1, 2, 3], [1, 3, 2])
    A, _ = Group("xyz", {}).affine(np.array([1, 2, 3]))
    assert np.allclose(A[0] @ [1, 2, 3], [3, 1, 2]) and np.allclose(A[2], np.eye(3))
