"""The benchmark scripts still run against the package as it is laid out now:
each on a small input, checking its exit status (they exit 2 when a program
crashes or the two programs disagree on the numbers).  Timings are printed,
never asserted."""
import os
import re
import shutil
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.join(ROOT, "benchmarks")


def _run(args, tmp_path):
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    p = subprocess.run([sys.executable] + args, capture_output=True, text=True,
                       timeout=600, cwd=tmp_path, env=env)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    return p.stdout


def test_bench_load_runs(evolver, tmp_path):
    out = _run([os.path.join(BENCH, "bench_load.py"), os.path.join(ROOT, "datafiles", "cube.fe"),
                "--repeat", "1"], tmp_path)
    assert "energy agreement" in out and "OK" in out


@pytest.mark.parametrize("script,args", [
    ("bench_mesh.py", ["--level", "2", "--repeat", "1"]),
    ("bench_startup.py", ["--repeat", "1"]),
])
def test_bench_scripts_run(evolver, tmp_path, script, args):
    out = _run([os.path.join(BENCH, script)] + args, tmp_path)
    assert "ratio" in out.lower() or "| goal" in out


def test_bench_all_summarizes_and_plots(evolver, tmp_path):
    """benchmarks/bench_all.py runs bench_iterate (here level 1, one step)
    and bench_hessian (level 1), reads their tables back from the document and
    writes the goals' summary between its markers, and the log-log plot."""
    doc, png = tmp_path / "perf.md", tmp_path / "perf.png"
    doc.write_text("intro\n")
    out = _run([os.path.join(BENCH, "bench_all.py"), "--only", "iterate", "hessian",
                "--iterate-levels", "1", "--hessian-levels", "1", "--steps", "1",
                "--repeat", "1", "--label", "t", "--doc", str(doc), "--plot", str(png)], tmp_path)
    text = doc.read_text()
    for tag in ("bench_iterate t", "bench_hessian t", "bench_all t"):
        assert f"<!-- {tag} -->" in text and f"<!-- /{tag} -->" in text
    summary = text[text.index("<!-- bench_all t -->"):]
    assert "| `g`, area, 80 facets |" in summary and "| `g`, bending, 80 facets |" in summary
    assert "| `hessian`, bending, 80 facets | peak [MB] |" in summary
    assert summary.count("| `") == 2 + 2 * 2 * 4      # g: 2 cases; hessian: 2 × 2 commands × 4 rows
    assert out.rstrip().endswith(summary[summary.index("| goal"):summary.index("<!-- /")].rstrip())
    assert png.stat().st_size > 10000
    # --only chooses what runs again; the summary still reads every table
    out = _run([os.path.join(BENCH, "bench_all.py"), "--only", "hessian", "--summary-only",
                "--label", "t", "--doc", str(doc), "--plot", str(png)], tmp_path)
    again = doc.read_text()
    assert again[again.index("<!-- bench_all t -->"):] == summary


def test_bench_hessian_runs(evolver, tmp_path):
    """Both programs on the level-1 prolate icosphere (80 facets), the table
    written into a Markdown file between its markers; the solver table."""
    doc = tmp_path / "perf.md"
    doc.write_text("intro\n<!-- bench_hessian t -->\nold\n<!-- /bench_hessian t -->\nend\n")
    out = _run([os.path.join(BENCH, "bench_hessian.py"), "--levels", "1", "--repeat", "1",
                "--cases", "area", "--label", "t", "--doc", str(doc)], tmp_path)
    assert out.count("| area |") == 2
    text = doc.read_text()
    assert text.startswith("intro\n") and text.endswith("end\n") and "old" not in text
    assert "| area | 80 | `hessian_seek` |" in text
    out = _run([os.path.join(BENCH, "bench_hessian.py"), "--levels", "1", "--solvers"],
               tmp_path)
    assert "SuperLU, symmetric mode, ND order (pyevolver)" in out


def test_deep_fuzz_writes_its_counts(tmp_path):
    """benchmarks/deep_fuzz.py: a reduced deep run (50 inputs per target)
    and the table of counts it writes (docs/fuzzing.md is this table)."""
    doc, log = tmp_path / "fuzzing.md", tmp_path / "fuzz.log"
    out = _run([os.path.join(BENCH, "deep_fuzz.py"), "--inputs", "50", "--reduced",
                "--doc", str(doc), "--log", str(log)], tmp_path)
    text = doc.read_text()
    assert "3 passed" in log.read_text()
    assert "result: passed" in text and "wrote" in out
    for target in ("reader", "parser", "interpreter"):
        assert f"| hostile {target} (deep) | 50 | 0 | 0 |" in text
    # the doc written again from the log: the same rows, the run's commit
    rows = [ln for ln in text.splitlines() if ln.startswith("| hostile")]
    doc.unlink()
    _run([os.path.join(BENCH, "deep_fuzz.py"), "--from-log", str(log), "--doc", str(doc)],
         tmp_path)
    assert [ln for ln in doc.read_text().splitlines() if ln.startswith("| hostile")] == rows


def test_bench_hostile_writes_its_table(tmp_path):
    """benchmarks/bench_hostile.py: the first check (a 200,000-digit number
    run into a letter: a located error) run once, its row written between
    the markers of a Markdown file (docs/hostile.md is this table)."""
    doc = tmp_path / "hostile.md"
    doc.write_text("intro\n<!-- bench_hostile -->\nold\n<!-- /bench_hostile -->\nend\n")
    _run([os.path.join(BENCH, "bench_hostile.py"), "--only", "1", "--repeat", "1",
          "--doc", str(doc)], tmp_path)
    text = doc.read_text()
    assert text.startswith("intro\n") and text.endswith("end\n") and "old" not in text
    assert "| 200,000-digit number run into a letter (datafile) |" in text
    assert "| ≤ 5 | right: exit 1, located message |" in text
    row = next(ln for ln in text.splitlines() if ln.startswith("| 200,000"))
    ref = row.split("|")[-2].strip()           # the Evolver's wall time on the same file
    if shutil.which("evolver-nox-d") or os.environ.get("CI"):
        assert re.fullmatch(r"\d+\.\d\d( \(exit \d+\))?", ref), row
    else:
        assert ref == "—", row                 # (no Evolver installed here)


def test_bench_frontal_counts_the_fronts(tmp_path):
    """The multifrontal estimate (docs/performance.md, "What is left"): on a
    small sphere every unknown is a pivot of one front, so the factor has at
    least n entries, and the extend-add volume is printed."""
    out = _run([os.path.join(BENCH, "bench_frontal.py"), "--level", "3", "--leaf", "16"],
               tmp_path)
    n = int(re.search(r"unknowns ([\d,]+)", out).group(1).replace(",", ""))
    entries = int(re.search(r"factor entries ([\d,]+)", out).group(1).replace(",", ""))
    assert n == 642 and entries >= n
    assert "extend-add volume" in out and "np.add.at" in out
