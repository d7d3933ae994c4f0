"""The quadratic model's energies (pyevolver.methods.quadratic): analytic
gradients against central differences, the patch values against closed
forms, and the methods it refuses by name."""
import numpy as np
import pytest

import pyevolver
from pyevolver.errors import UnsupportedError
from pyevolver.evolve.gradient import body_volume_gradients, energy_gradient, quantity_gradient
from pyevolver.methods import quadratic as MQ
from tolerances import FD, ROUNDOFF

FE = """
SYMMETRIC_CONTENT_FLAG
gravity_constant 2
constraint 1
formula: z = -0.3
energy:
e1: -0.4*y
e2: 0.2*x*z
e3: 0
content:
c1: 0.1*z*y
c2: 0.3*x
c3: 0
quantity fvi energy method facet_vector_integral global
vector_integrand:
q1: x*y
q2: z^2
q3: x+y*z
quantity evi energy method edge_vector_integral global
vector_integrand:
q1: y
q2: x*z
q3: z
quantity el energy modulus 0.3 method edge_length global
quantity fa energy modulus 0.2 method facet_area global
quantity vol info_only method facet_volume global
quantity ft energy method facet_tension global
quantity et energy method edge_tension global
quantity fsi info_only method facet_scalar_integral global
scalar_integrand: x^2+z
quantity esi info_only method edge_scalar_integral global
scalar_integrand: y^2
vertices
1 1 0 -0.3 constraint 1
2 0 1 -0.3 constraint 1
3 -1 0 -0.3 constraint 1
4 0 -1 -0.3 constraint 1
5 0 0 1
edges
1 1 2 constraint 1
2 2 3 constraint 1
3 3 4 constraint 1
4 4 1 constraint 1
5 1 5
6 2 5
7 3 5
8 4 5
faces
1 1 6 -5
2 2 7 -6
3 3 8 -7
4 4 5 -8
bodies
1 1 2 3 4 volume 1 density 1.5
"""


def _surface(tmp_path, symmetric=False, seed=0):
    p = tmp_path / "q.fe"
    p.write_text(FE.replace("SYMMETRIC_CONTENT_FLAG", "SYMMETRIC_CONTENT" if symmetric else ""))
    sess = pyevolver.load(str(p))
    sess.run("M 2")
    s = sess.surface
    s.X = s.X + 0.05 * np.random.default_rng(seed).standard_normal(s.X.shape)
    return s


def _fd(s, fn, h=1e-6):
    X0 = s.X.copy()
    g = np.zeros(X0.shape + np.shape(fn(s.evaluate())))
    for i in range(s.nv):
        for k in range(3):
            s.X = X0.copy()
            s.X[i, k] += h
            up = fn(s.evaluate())
            s.X = X0.copy()
            s.X[i, k] -= h
            g[i, k] = (up - fn(s.evaluate())) / (2 * h)
    s.X = X0
    return g


@pytest.mark.parametrize("symmetric", [False, True])
def test_energy_and_volume_gradients(tmp_path, symmetric):
    s = _surface(tmp_path, symmetric)
    t = s.evaluate()
    assert isinstance(t, MQ.QuadTotals) and "gravity" in t.terms and t.con_energy
    g = energy_gradient(t)
    fd = _fd(s, lambda tt: tt.energy)
    assert np.abs(g - fd).max() < FD * max(1.0, np.abs(fd).max())
    vg = body_volume_gradients(t)[0]
    fdv = _fd(s, lambda tt: tt.volumes[0])
    assert np.abs(vg - fdv).max() < FD


def test_each_method_gradient(tmp_path):
    s = _surface(tmp_path, seed=1)
    t = s.evaluate()
    names = ("fvi", "evi", "el", "fa", "vol", "ft", "et")
    fds = _fd(s, lambda tt: np.array([tt.quantity_values[n] for n in names]))
    for k, name in enumerate(names):
        g = quantity_gradient(t, s.quantities[name])
        fd = fds[..., k]
        assert np.abs(g - fd).max() < FD * max(1.0, np.abs(fd).max()), name


def test_flat_patches_are_the_linear_values(tmp_path):
    # midpoints at the chord middles: the quadratic patch is the flat triangle
    p = tmp_path / "q.fe"
    p.write_text(FE.replace("SYMMETRIC_CONTENT_FLAG", ""))
    sess = pyevolver.load(str(p))
    lin = sess.surface.evaluate()
    sess.run("M 2")
    t = sess.surface.evaluate()
    assert np.allclose(t.facet_area, lin.facet_area, rtol=ROUNDOFF)
    assert np.allclose(t.facet_volume, lin.facet_volume, rtol=ROUNDOFF, atol=ROUNDOFF)
    assert np.allclose(t.edge_length, lin.edge_length, rtol=ROUNDOFF)
    # a scalar integral of a quadratic over a flat patch: the 7-point rule is exact
    assert abs(t.quantity_values["fsi"] - lin.quantity_values["fsi"]) < 1e-6


TET = """
quantity vv info_only method vertex_scalar_integral global
scalar_integrand: x^2+1
vertices
1 0 0 0
2 1 0 0
3 0 1 0
4 0.3 0.3 1
edges
1 1 2
2 2 3
3 3 1
4 1 4
5 2 4
6 3 4
faces
1 1 2 3
2 -1 4 -5
3 -2 5 -6
4 -3 6 -4
"""


def test_vertex_integral_counts_the_midpoints(tmp_path):
    # REF after M 2 prints 12.0575: corners 5.09 plus the six chord midpoints
    p = tmp_path / "t.fe"
    p.write_text(TET)
    sess = pyevolver.load(str(p))
    sess.run("M 2")
    assert abs(sess.surface.evaluate().quantity_values["vv"] - 12.0575) < ROUNDOFF


def test_refused_methods_by_name(tmp_path):
    # REF: "sq_mean_curvature method only for LINEAR model"
    p = tmp_path / "t.fe"
    p.write_text("quantity sq info_only method sq_mean_curvature global\n" + TET)
    from pyevolver.remesh.quadratic import to_quadratic
    s = to_quadratic(pyevolver.load(str(p)).surface)
    with pytest.raises(UnsupportedError, match="sq_mean_curvature in the quadratic model"):
        s.evaluate()
