"""pyevolver.methods.group_geometry: corners and edge vectors through the
group elements, and the energy gradients back through Aᵀ against central
differences (area, edge tension, a body's volume) in several groups."""
import os

from finite_differences import central_gradient
import numpy as np
import pytest

import pyevolver
from pyevolver.evolve.gradient import body_volume_gradients, energy_gradient
from pyevolver.methods import group_geometry as GG
from pyevolver.model.groups import group_of

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "symmetry_groups")


def _surface(name):
    return pyevolver.load(os.path.join(DATA, name + ".fe")).surface


def _fd(s, f, h=1e-6):
    return central_gradient(s, lambda s: f(s.evaluate()), h)


@pytest.mark.parametrize("name", ["rotate", "flip_rotate", "screw_symmetry", "cubelat", "xyz",
                                  "central_symmetry"])
def test_area_and_edge_length_gradients(name):
    from pyevolver.methods.basic import edge_length_grad
    s = _surface(name)
    ne, w = np.arange(s.ne), np.linspace(0.1, 0.5, s.ne)     # edge lengths through g too
    t = s.evaluate()

    def energy(t):
        return t.energy + w @ np.linalg.norm(t.edge_vec, axis=1)
    g = energy_gradient(t) + edge_length_grad(t, ne, w)
    assert np.allclose(g, _fd(s, energy), atol=1e-7)


def test_edge_tension_attribute_refused():
    """REF leaves the edges' TENSION out of the energy in these groups."""
    from pyevolver.errors import UnsupportedError
    s = _surface("flip_rotate")
    s.eattr["tension"] = np.full(s.ne, 0.3)
    with pytest.raises(UnsupportedError, match="edge TENSION"):
        s.evaluate()


def test_volume_gradient_and_corners():
    s = _surface("screw_symmetry")
    group = group_of(s)
    t = s.evaluate()
    # corners: the maps of REF's products of the oriented edges' codes
    codes = GG.corner_codes(s, group)
    A, b = group.affine(codes.ravel())
    P = np.einsum("nij,nj->ni", A, s.X[s.F].reshape(-1, 3)) + b
    assert np.allclose(P.reshape(-1, 3, 3)[:, 1] - P.reshape(-1, 3, 3)[:, 0], t.facet_S[:, 0])
    # every wrapped edge's head lifted by screw_height, turned a quarter
    w = s.eattr["wrap_code"] == 1
    assert w.sum() == 7                 # four sides, three diagonals
    head = s.X[s.E[w, 1]]
    assert np.allclose(t.edge_vec[w] + s.X[s.E[w, 0]],
                       np.stack([-head[:, 1], head[:, 0], head[:, 2] + 0.3], 1))
    # the facets' contents: their gradient, as a body's would be
    vol = t.facet_volume.sum()
    from pyevolver.methods.basic import facet_volume_grad
    from pyevolver.methods._common import corner_scatter
    g = corner_scatter(t, facet_volume_grad(t, False))
    assert np.allclose(g, _fd(s, lambda t: t.facet_volume.sum()), atol=1e-7)
    assert vol != 0 and callable(body_volume_gradients)


def _with_top(name, line, tmp_path):
    lines = open(os.path.join(DATA, name + ".fe")).read().split("\n")
    path = tmp_path / "q.fe"
    path.write_text("\n".join(lines[:4] + [line] + lines[4:]))
    return str(path)


def test_methods_through_the_maps_and_refusals(tmp_path):
    """facet_area quantities go through the maps; methods, integrals and
    metrics that read coordinates on their own are refused by name."""
    s = pyevolver.load(_with_top("cubocta", "quantity qq energy method facet_area global",
                                 tmp_path)).surface
    assert s.evaluate().energy == pytest.approx(2 * s.evaluate().total_area, rel=1e-14)
    for line in ("quantity qq energy method facet_scalar_integral scalar_integrand: x^2 global",
                 "constraint 1\nformula: z = 0\nenergy:\ne1: 0\ne2: z\ne3: 0",
                 "metric\n1 0 0\n0 1 0\n0 0 1"):
        with pytest.raises(pyevolver.errors.PyEvolverError, match='in SYMMETRY_GROUP "cubocta"'):
            pyevolver.load(_with_top("cubocta", line, tmp_path))


def test_wrapped_boundary_edge_refused():
    s = _surface("cubocta")
    s.eattr["boundary"] = (s.eattr["wrap_code"] != 0).astype(np.int64)
    with pytest.raises(pyevolver.errors.PyEvolverError, match="parametric boundary"):
        GG.check_supported(s)
    s.eattr["boundary"] = np.zeros(s.ne, np.int64)
    GG.check_supported(s)


@pytest.mark.parametrize("name", ["flip_rotate", "cubelat", "central_symmetry"])
def test_hessians_through_the_maps(name):
    """Area, edge-length and volume Hessians (methods._common.group_blocks:
    ``A_aᵀ H_ab A_b``) against central differences of the gradients."""
    from finite_differences import assert_hessian_columns
    from pyevolver.methods._common import corner_scatter
    from pyevolver.methods.basic import (edge_length_grad, edge_length_hessian,
                                         facet_area_hessian, facet_volume_grad,
                                         facet_volume_hessian)
    s = _surface(name)
    ne = np.arange(s.ne)
    we = np.linspace(0.1, 0.5, s.ne)
    wf = np.linspace(0.5, 1.5, s.nf)

    def grad(s):
        t = s.evaluate()
        return (energy_gradient(t) + edge_length_grad(t, ne, we)
                + corner_scatter(t, facet_volume_grad(t, False), wf))
    t = s.evaluate()
    H = (facet_area_hessian(t, s.facet_tension) + edge_length_hessian(t, ne, we)
         + facet_volume_hessian(t, wf, False)).toarray()
    assert np.abs(H).max() > 0.1
    assert_hessian_columns(s, H, grad, h=1e-5, tol=1e-6)


def test_quarter_turn_forces_leave_out_wrapped_corners():
    """REF's forces in quarter_turn (measured with v_force): a facet's corner
    whose code is not 0 adds nothing to its vertex; edge tension refused."""
    from pyevolver.errors import UnsupportedError
    s = _surface("quarter_turn")
    t = s.evaluate()
    codes = GG.corner_codes(s, group_of(s))
    assert (codes != 0).any()
    assert not t.corner_maps[codes != 0].any()
    assert np.allclose(t.corner_maps[codes == 0], np.eye(3))
    s.eattr["tension"] = np.full(s.ne, 0.5)
    with pytest.raises(UnsupportedError, match="edge TENSION"):
        s.evaluate()
