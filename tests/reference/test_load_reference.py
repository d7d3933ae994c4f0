"""Load-time numbers agree with evolver-nox-d (run live).

For each shipped example the reference prints total_energy, total_area,
every body's volume and the element counts right after loading (after its
read section); pyevolver must print the same counts exactly and the same
values within 1e-12 relative.
"""
import pytest

from pyevolver import Session

from conftest import example
from reference import numbers
from tolerances import PRINTED

FILES = ["cube", "quad", "sphere", "octa", "mound", "qmound", "catbody", "cat", "catman",
         "column", "tankex", "twointor"]


def _close(a, b, rtol=PRINTED, atol=1e-14):
    return abs(a - b) <= rtol * max(abs(a), abs(b)) + atol


@pytest.mark.parametrize("name", FILES)
def test_load_matches_reference(evolver, name, tmp_path):
    path = example(name + ".fe")
    s = Session.load(path)
    nb = s.surface.bodies.n
    exprs = ["total_energy", "total_area", "vertex_count", "edge_count", "facet_count",
             "body_count"] + [f"body[{i + 1}].volume" for i in range(nb)]
    ref = numbers(evolver, path, exprs, cwd=str(tmp_path))
    counts = (s.surface.nv, s.surface.ne, s.surface.nf, nb)
    assert counts == tuple(int(v) for v in ref[2:6])
    assert _close(s.total_energy, ref[0]), (s.total_energy, ref[0])
    assert _close(s.total_area, ref[1]), (s.total_area, ref[1])
    for i in range(nb):
        assert _close(float(s.totals.volumes[i]), ref[6 + i]), (i, s.totals.volumes, ref[6:])
