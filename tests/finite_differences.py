"""Central differences the method tests share: the gradient of an energy
and the columns of a Hessian, by moving one coordinate of one vertex at a
time (``s.X`` is restored afterwards).

Every energy's analytic gradient (and Hessian, where it has one) is checked
against these in tests/methods/; the tolerance is :data:`tolerances.FD`."""
import numpy as np

from tolerances import FD




def central_gradient(s, energy, h=1e-6, dims=3):
    """(nv, dims) central differences of ``energy(s)`` (a float) in the
    vertex coordinates ``s.X[:, :dims]``."""
    num = np.zeros((s.nv, dims))
    X0 = s.X.copy()
    try:
        for i in range(s.nv):
            for k in range(dims):
                e = []
                for sg in (1, -1):
                    s.X = X0.copy()
                    s.X[i, k] += sg * h
                    e.append(energy(s))
                num[i, k] = (e[0] - e[1]) / (2 * h)
    finally:
        s.X = X0
    return num


def method_energy(method, idx, w, mq=None):
    """``s -> Σ w · method.value`` on the elements ``idx`` (a quantity's
    weighted value), for :func:`central_gradient`."""
    return lambda s: float(w @ method.value(s.evaluate(), mq, idx))


def assert_gradient(grad, num, tol=FD):
    """The analytic gradient equals the differences within ``tol``
    relative to its largest entry (absolute below 1)."""
    grad = np.asarray(grad)
    assert np.abs(grad - num).max() <= tol * max(1.0, np.abs(grad).max())


def assert_hessian_columns(s, D, gradient, h=1e-6, dims=3, tol=FD):
    """Each column of the dense Hessian ``D`` ((nv·dims)²) equals the central
    difference of ``gradient(s)`` (raveled (nv, dims)) in that coordinate."""
    X0 = s.X.copy()
    try:
        for i in range(s.nv):
            for k in range(dims):
                g = []
                for sg in (1, -1):
                    s.X = X0.copy()
                    s.X[i, k] += sg * h
                    g.append(np.asarray(gradient(s)).ravel())
                col = (g[0] - g[1]) / (2 * h)
                assert np.abs(D[:, dims * i + k] - col).max() <= tol * max(1.0, np.abs(col).max())
    finally:
        s.X = X0
