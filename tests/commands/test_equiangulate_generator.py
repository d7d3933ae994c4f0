"""``equiangulate edge_generator`` and ``flush_counts`` (REF manual:
EQUIANGULATE, FLUSH_COUNTS): the given edges are tested and flipped,
``equi_count`` adds up within a command and starts again after the report,
"Edges equiangulated: N" is printed when the command ends or at
``flush_counts``.  Compared with the Evolver run live on a sheared cube."""
import os

from comparison import _run_both, _same
from conftest import EXAMPLES

SCRIPT = """r
r
set vertex x x+0.9*y+0.5*z
{equiangulate edge where id < 100; print equi_count; equiangulate edge where id < 200; print equi_count; flush_counts; print equi_count; equiangulate edge where id < 300; print equi_count; }
{ equiangulate edge; print equi_count}
print total_area
equiangulate edge[3]
print equi_count
"""


def test_equiangulate_edges_and_flush_counts(evolver, tmp_path):
    _, ref, out, err = _run_both(evolver, os.path.join(EXAMPLES, "cube.fe"), SCRIPT, tmp_path)
    ref = [ln for ln in ref if not ln.startswith(("Vertices:", "Element memory", "Total data"))]
    out = [ln for ln in out if not ln.startswith("Vertices:")]
    assert _same(out, ref), (out, ref, err)
