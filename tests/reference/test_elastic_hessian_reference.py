"""REF's Hessian matrix of ``linear_elastic`` against the exact one
(docs/differences.md, "`hessian` with `linear_elastic` ..."): dumped live
with ``hessian_menu``'s ``D`` on one facet with three free vertices.

* With enough other vertices in the file, REF's matrix is twice the exact
  Hessian's 3×3 blocks of each vertex and has no entries between two vertices.
* Without them, entries inside the vertex blocks are missing as well: which
  ones depends on the number of vertices in the file (an isolated fixed
  vertex changes it), so it is not a rule of the energy; pyevolver keeps the
  exact Hessian.
"""
import io
import os

import numpy as np

from pyevolver.evolve.hessian import hessian_system
from pyevolver.session.core import Session

FACET = """define facet attribute poisson_ratio real
define facet attribute form_factors real[3]
quantity st energy method linear_elastic global
vertices
1 0 0 0
2 1 0 0
3 0.3 1.2 0.1
{extra}
edges
1 1 2
2 2 3
3 3 1
faces
1 1 2 3 tension 0 form_factors {{1, 0.2, 1.1}} poisson_ratio 0.3
read
"""


def _file(tmp_path, n_extra):
    extra = "\n".join(f"{4 + k} {5 + k} 5 5 fixed" for k in range(n_extra))
    path = os.path.join(str(tmp_path), f"facet{n_extra}.fe")
    with open(path, "w") as fh:
        fh.write(FACET.format(extra=extra))
    return path


def _ref_matrix(evolver, path, tmp_path):
    import subprocess
    base = os.path.join(str(tmp_path), "dump")
    cmd = f"hessian_normal off\nhessian_menu\n1\nD\n{base}\nq\nq\nq\n"
    subprocess.run([evolver, "-p1", path], input=cmd, capture_output=True, text=True,
                   timeout=60, cwd=str(tmp_path))
    rows = np.loadtxt(base + "_H.dat", ndmin=2)
    M = np.zeros((9, 9))
    for r, c, v in rows:
        M[int(r) - 1, int(c) - 1] = M[int(c) - 1, int(r) - 1] = v
    return M


def _exact(path):
    s = Session.load(path, out=io.StringIO(), err=io.StringIO())
    K = hessian_system(s.iterator, normal=False).K.toarray()
    assert K.shape == (9, 9)
    return K


def _blocks(K):
    B = np.zeros_like(K)
    for v in range(3):
        B[3 * v:3 * v + 3, 3 * v:3 * v + 3] = K[3 * v:3 * v + 3, 3 * v:3 * v + 3]
    return B


def test_ref_keeps_vertex_blocks_only(evolver, tmp_path):
    path = _file(tmp_path, 8)
    M, K = _ref_matrix(evolver, path, tmp_path), _exact(path)
    B = _blocks(K)
    assert np.abs(K - B).max() > 0.1                       # the exact one couples the vertices
    assert np.allclose(M, 2 * B, rtol=1e-12, atol=1e-13)


def test_ref_matrix_depends_on_vertex_count(evolver, tmp_path):
    path = _file(tmp_path, 0)
    M, K = _ref_matrix(evolver, path, tmp_path), _exact(path)
    assert np.allclose(np.diag(M), 2 * np.diag(K), rtol=1e-12)
    assert not np.allclose(M, 2 * _blocks(K), rtol=1e-6, atol=1e-6)
