"""mylarcube.fe's cube corners after ``g 5; r; u`` (docs/differences.md,
"`V` at cube corners after `u`"): with REF's coordinates loaded into
pyevolver, the ordered vertex normal of ``V`` (geometry.vertex_normals with
REF's facet order) lies along REF's ``vertex_normal`` at all eight corners,
although the third facet's flip there is decided by round-off."""
import io

import numpy as np
import pytest

from conftest import example
from reference import run_reference

from pyevolver.geometry import kernels as G
from pyevolver.model.records import vertex_facet_rank
from pyevolver.session.core import Session

CMDS = "g 5\nr\nu\n"


@pytest.mark.slow
def test_corner_normals_with_ref_coordinates(evolver, tmp_path):
    path = example("mylarcube.fe")
    script = CMDS + ('foreach vertex vv do printf "P %d %.17g %.17g %.17g %.17g %.17g %.17g\\n", '
                     'id, x, y, z, vv.vertex_normal[1], vv.vertex_normal[2], '
                     'vv.vertex_normal[3]\n')
    ref = run_reference(evolver, path, script, cwd=str(tmp_path), timeout=200)
    rows = np.array([[float(w) for w in ln.split()[1:]] for ln in ref if ln.startswith("P ")])
    s = Session.load(path, out=io.StringIO(), err=io.StringIO())
    s.run(CMDS.replace("\n", ";"))
    S = s.surface
    assert len(rows) == S.nv
    assert np.abs(S.X - rows[:, 1:4]).max() < 1e-12          # the same surface, up to round-off
    S.X[:] = rows[:, 1:4]
    t = S.evaluate()
    n = G.vertex_normals(S.F, t.facet_N2, S.nv, vertex_facet_rank(S))
    corners = np.abs(np.abs(np.einsum("ij,ij->i", n[:8], rows[:8, 4:7])) - 1.0)
    assert corners.max() < 1e-12
