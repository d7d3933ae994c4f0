"""REF's Hessian of the elastic methods against pyevolver's exact one
(docs/differences.md, "`hessian` with method quantities and REF's worker
threads"), dumped live with ``hessian_menu``'s ``D``.

Run without worker threads, REF's matrix is the exact Hessian and its
``hessian`` steps are pyevolver's (mylarcube.fe, whose ``relaxed_elastic_A``
has an analytic Hessian now).  With worker threads (``-p1``, as the sweep and
``reference.run_reference`` run it) REF's matrix of a method quantity loses
terms: on one facet it is twice the exact Hessian's 3×3 blocks of each
vertex with nothing between two vertices, and which entries are lost changes
with the thread count and the number of vertices in the file.
"""
import io
import os
import re
import subprocess

import numpy as np

from conftest import EXAMPLES, example

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


def _ref(evolver, path, script, tmp_path, threads):
    """REF's stdout for ``script``, with one worker thread (``-p1``) or none."""
    args = [evolver, "-p1", path] if threads else [evolver, path]
    return subprocess.run(args, input=script + "q\nq\nq\n", capture_output=True, text=True,
                          timeout=120, cwd=str(tmp_path)).stdout


def _ref_matrix(evolver, path, pre, n, tmp_path, threads):
    base = os.path.join(str(tmp_path), "dump")
    _ref(evolver, path, f"{pre}hessian_normal off\nhessian_menu\n1\nD\n{base}\nq\n",
         tmp_path, threads)
    M = np.zeros((n, n))
    for r, c, v in np.loadtxt(base + "_H.dat", ndmin=2):
        M[int(r) - 1, int(c) - 1] = M[int(c) - 1, int(r) - 1] = v
    return M


def _exact(path, pre=""):
    s = Session.load(path, out=io.StringIO(), err=io.StringIO())
    if pre:
        s.run(pre.strip().replace("\n", "; "))
    return hessian_system(s.iterator, normal=False).K.toarray()


def _blocks(K):
    B = np.zeros_like(K)
    for v in range(K.shape[0] // 3):
        B[3 * v:3 * v + 3, 3 * v:3 * v + 3] = K[3 * v:3 * v + 3, 3 * v:3 * v + 3]
    return B


def test_without_threads_ref_matrix_is_the_exact_hessian(evolver, tmp_path):
    path = _file(tmp_path, 0)
    K = _exact(path)
    M = _ref_matrix(evolver, path, "", 9, tmp_path, threads=False)
    assert np.abs(K - _blocks(K)).max() > 0.1                # the vertices are coupled
    assert np.allclose(M, K, rtol=1e-12, atol=1e-13)


def test_mylarcube_matrix_without_threads(evolver, tmp_path):
    path = example("mylarcube.fe")
    K = _exact(path, "g 5\n")
    M = _ref_matrix(evolver, path, "g 5\n", K.shape[0], tmp_path, threads=False)
    assert np.abs(M - K).max() <= 1e-10 * np.abs(K).max()


def _energies(text):
    return [float(x) for x in re.findall(r"^E (\S+)$", text, flags=re.M)]


def test_mylarcube_hessian_steps_without_threads(evolver, tmp_path):
    """The sweep's g5_hessian, then a second step and g (REF without worker
    threads; with -p1 REF's first step gives another energy)."""
    pr = 'printf "E %.15g\\n", total_energy\n'
    script = f"g 5\nhessian\n{pr}hessian\n{pr}g 3\n{pr}"
    path = example("mylarcube.fe")
    ref = _energies(_ref(evolver, path, script, tmp_path, threads=False))
    ref_p1 = _energies(_ref(evolver, path, script, tmp_path, threads=True))
    out = io.StringIO()
    s = Session.load(path, out=out, err=io.StringIO())
    s.run(script.strip().replace("\n", "; "))
    ours = _energies(out.getvalue())
    assert len(ref) == len(ours) == 3
    assert np.allclose(ours, ref, rtol=0, atol=1e-9), (ours, ref)
    assert abs(ref_p1[0] - ref[0]) > 1e-4                    # REF's threaded Hessian


def test_with_threads_ref_keeps_vertex_blocks_only(evolver, tmp_path):
    path = _file(tmp_path, 8)
    K = _exact(path)
    M = _ref_matrix(evolver, path, "", 9, tmp_path, threads=True)
    assert np.allclose(M, 2 * _blocks(K), rtol=1e-12, atol=1e-13)


def test_with_threads_ref_matrix_depends_on_vertex_count(evolver, tmp_path):
    path = _file(tmp_path, 0)
    K = _exact(path)
    M = _ref_matrix(evolver, path, "", 9, tmp_path, threads=True)
    assert np.allclose(np.diag(M), 2 * np.diag(K), rtol=1e-12)
    assert not np.allclose(M, 2 * _blocks(K), rtol=1e-6, atol=1e-6)


def test_area_method_hessian_with_threads(evolver, tmp_path):
    """The same with the area as a ``facet_area`` method quantity on cube.fe:
    REF's step with -p1 is not its step with facet tension (nor with -p2);
    without worker threads it is, and pyevolver's is that one."""
    with open(example("cube.fe")) as fh:
        text = fh.read()
    text = text.replace("vertices\n", "quantity st energy method facet_area global\nvertices\n", 1)
    text = re.sub(r"^(\d+( +-?\d+){4})\s*$", r"\1 tension 0", text, flags=re.M)
    path = os.path.join(str(tmp_path), "cube_area_method.fe")
    with open(path, "w") as fh:
        fh.write(text)
    script = 'g 5\nr\ng 5\nhessian\nprintf "E %.15g\\n", total_energy\n'
    tension = _energies(_ref(evolver, os.path.join(EXAMPLES, "cube.fe"), script, tmp_path,
                             threads=False))[0]
    method = _energies(_ref(evolver, path, script, tmp_path, threads=False))[0]
    method_p1 = _energies(_ref(evolver, path, script, tmp_path, threads=True))[0]
    assert abs(method - tension) < 1e-8
    assert abs(method_p1 - tension) > 1e-5
    out = io.StringIO()
    s = Session.load(path, out=out, err=io.StringIO())
    s.run(script.strip().replace("\n", "; "))
    assert abs(_energies(out.getvalue())[0] - method) < 1e-8
