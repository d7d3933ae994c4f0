"""The Hessian in the quadratic model (`M 2`, `QUADRATIC`).

The unknowns are the coordinates of every node: the vertices and the edge
midpoints (the last ``ne`` vertices of the surface, :attr:`Surface.midv`).
The Hessian of the Lagrangian is taken by central differences of the
quadratic model's analytic gradient (:mod:`pyevolver.methods.quadratic`)
over a distance-2 colouring of the node graph, in which two nodes are
neighbours when they lie on one quadratic patch (its six nodes) or on one
edge curve (tail, midpoint, head).

With ``hessian_normal`` a node moves along one direction, found against
evolver-nox-d run without worker threads: the sum of the unit normals of the
quadratic patches through the node, each taken at the node (cube.fe
``M 2; g 5; hessian`` and ``r; M 2; g 5; hessian``: REF's energies to
1e-10).  The Evolver's manual says only "perpendicular is usually defined
as the volume gradient"; the patches' volume gradient, the flat triangles'
area vectors and the unweighted patch normals give other steps (1e-5 to
1e-7 off REF's on the refined cube).

Not done here (refused by name): nodes on level-set constraints or
parametric boundaries, junction lines (edges of three or more facets), and
the string model in the quadratic model.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..constraints import boundary_groups
from ..errors import UnsupportedError
from ..model.surface import Surface


def check(s: Surface) -> None:
    """Refuse what the quadratic model's Hessian does not cover."""
    if s.string:
        raise UnsupportedError("the Hessian in the quadratic string model",
                               "only the soapfilm model's quadratic Hessian is implemented")
    if any(np.any(on) for on in s.vcon.values()):
        raise UnsupportedError("the Hessian in the quadratic model with level-set constraints",
                               "REF's motion of constrained midpoints was not measured")
    idx = s.topology()[0]
    if np.any(np.bincount(idx.ravel(), minlength=s.ne) >= 3):
        raise UnsupportedError("the Hessian in the quadratic model with junction lines",
                               "REF's motion of midpoints on edges of three or more facets "
                               "was not measured")
    if boundary_groups(s):
        raise UnsupportedError("the Hessian in the quadratic model with parametric boundaries",
                               "REF's rule was not measured")


def node_adjacency(s: Surface) -> sp.csr_matrix:
    """(nv, nv) 0/1 matrix of nodes that share a patch or an edge curve
    (each node its own neighbour)."""
    idx, _, F = s.topology()
    nodes = np.concatenate([F, s.midv[idx]], axis=1)            # (nf, 6)
    r = np.repeat(nodes, 6, axis=1).ravel()
    c = np.tile(nodes, (1, 6)).ravel()
    curve = np.column_stack([s.E[:, 0], s.midv, s.E[:, 1]])     # (ne, 3)
    r = np.concatenate([r, np.repeat(curve, 3, axis=1).ravel(), np.arange(s.nv)])
    c = np.concatenate([c, np.tile(curve, (1, 3)).ravel(), np.arange(s.nv)])
    A = sp.csr_matrix((np.ones(len(r)), (r, c)), shape=(s.nv, s.nv))
    return ((A + A.T) != 0).astype(np.float64).tocsr()


#: the quadratic shape functions' derivatives (d/du, d/dv) at the six nodes
#: of a patch (corners (0,0), (1,0), (0,1); midpoints of sides 01, 12, 20):
#: rows the node where they are taken, columns the shape function
_UV = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 0.0], [0.5, 0.5], [0.0, 0.5]])


def _shape_derivatives():
    u, v = _UV[:, 0], _UV[:, 1]
    w = 1.0 - u - v
    z = np.zeros_like(u)
    du = np.column_stack([1.0 - 4.0 * w, 4.0 * u - 1.0, z, 4.0 * (w - u), 4.0 * v, -4.0 * v])
    dv = np.column_stack([1.0 - 4.0 * w, z, 4.0 * v - 1.0, -4.0 * u, 4.0 * u, 4.0 * (w - v)])
    return du, dv


_DU, _DV = _shape_derivatives()


def node_normals(s: Surface) -> np.ndarray:
    """(nv, 3) unit directions of the nodes' motion under ``hessian_normal``:
    at each node the sum of the unit normals ``x_u × x_v / |x_u × x_v|``
    of the quadratic patches through it, taken at the node (REF's
    ``vertex_normal`` attribute in the quadratic model, to 1e-15 on
    cube.fe ``r; M 2; g 5``); zero where the sum vanishes."""
    idx, _, F = s.topology()
    nodes = np.concatenate([F, s.midv[idx]], axis=1)             # (nf, 6)
    P = s.X[nodes]                                               # (nf, 6, 3)
    Xu = np.einsum("ac,ncj->naj", _DU, P)
    Xv = np.einsum("ac,ncj->naj", _DV, P)
    n = np.cross(Xu, Xv)
    L = np.linalg.norm(n, axis=2)
    n = np.where(L[..., None] > 0, n / np.where(L > 0, L, 1.0)[..., None], 0.0)
    N = np.zeros((s.nv, 3))
    np.add.at(N, nodes.ravel(), n.reshape(-1, 3))
    L = np.linalg.norm(N, axis=1)
    return np.where(L[:, None] > 0, N / np.where(L > 0, L, 1.0)[:, None], 0.0)


def lagrangian_hessian(s: Surface, grad_fn, basis=None, fd_hessian=None):
    """Sparse Hessian (3nv, 3nv) of the Lagrangian whose gradient is
    ``grad_fn(totals)``, or ``Tᵀ H T`` on a basis; ``fd_hessian`` the
    coloured central-difference routine (:func:`.hessian.fd_hessian`)."""
    check(s)
    A = node_adjacency(s)
    h = 1e-4 * max(float(np.max(np.ptp(s.X, axis=0))) if s.nv else 1.0, 1e-12)

    def fun(X):
        return grad_fn(s.evaluate())
    # Richardson's extrapolation of two central differences: error O(h⁴)
    # (an indefinite quadratic Hessian amplifies the O(h²) one)
    Hf = (4.0 * fd_hessian(fun, s, h / 2, A) - fd_hessian(fun, s, h, A)) / 3.0
    if basis is not None:
        T = basis.matrix()
        Hf = T.T @ Hf @ T
    return Hf
