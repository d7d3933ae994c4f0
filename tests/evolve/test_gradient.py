"""Every energy's analytic gradient against central finite differences.

The shipped examples cover facet and edge tension, gravity, constraint and
boundary energy and content integrals, gap energy of CONVEX constraints,
SYMMETRIC_CONTENT, named quantities and the torus model.  Vertices are
perturbed first so that no gradient vanishes by symmetry.
"""
import numpy as np
import pytest

from pyevolver import Session
from pyevolver.evolve import gradient as GR

from conftest import example

FILES = ["cube", "mound", "qmound", "sphere", "tankex", "column", "catbody", "twointor",
         "quad", "octa"]


def perturbed(name, seed=0):
    s = Session.load(example(name + ".fe"))
    surf = s.surface
    rng = np.random.default_rng(seed)
    scale = 0.03 * np.ptp(surf.X, axis=0).max()
    surf.X = surf.X + rng.normal(scale=scale, size=surf.X.shape)
    return surf


def fd_check(surf, value, grad, ncoords=40, h=1e-6, seed=1):
    rng = np.random.default_rng(seed)
    g = grad(surf.evaluate())
    X0 = surf.X.copy()
    picks = rng.choice(surf.nv * 3, size=min(ncoords, surf.nv * 3), replace=False)
    scale = max(1.0, np.abs(g).max())
    for p in picks:
        v, k = divmod(int(p), 3)
        surf.X = X0.copy()
        surf.X[v, k] += h
        ep = value(surf.evaluate())
        surf.X[v, k] -= 2 * h
        em = value(surf.evaluate())
        surf.X = X0
        fd = (ep - em) / (2 * h)
        assert abs(fd - g[v, k]) <= 1e-6 * scale, (v, k, fd, g[v, k])


@pytest.mark.parametrize("name", FILES)
def test_energy_gradient(name):
    surf = perturbed(name)
    fd_check(surf, lambda t: t.energy, GR.energy_gradient)


@pytest.mark.parametrize("name", ["cube", "sphere", "tankex", "column", "catbody", "twointor",
                                  "mound"])
def test_body_volume_gradient(name):
    surf = perturbed(name)
    for b in range(surf.bodies.n):
        fd_check(surf, lambda t: t.volumes[b], lambda t: GR.body_volume_gradients(t)[b])


@pytest.mark.parametrize("name", ["qmound", "tankex"])
def test_quantity_gradient(name):
    surf = perturbed(name)
    for q in surf.quantities.values():
        fd_check(surf, lambda t: t.quantity_values[q.name], lambda t: GR.quantity_gradient(t, q))

