"""Direct tests of pyevolver.commands.output: print, printf, errprintf,
histogram, loghistogram, v, q; printed text against the reference run live."""
import io
import os

import pytest

from pyevolver import Session
from pyevolver.commands.output import histogram_text
from pyevolver.commands.values import Quit
from pyevolver.errors import CommandError

from reference import run_reference

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def session():
    return Session.load(CUBE, out=io.StringIO(), err=io.StringIO())


def lines(text):
    return [l for l in text.split("\n") if l.strip()]


SCRIPT = """print 1/3
print "hello"
printf "%g %10.4f\\n", 1/3, 2
printf "plain %% text\\n"
histogram(vertex, x)
loghistogram(edge, length)
histogram(facet, area)
v
"""


def test_output_matches_reference(evolver):
    ref = lines("\n".join(run_reference(evolver, CUBE, SCRIPT)))
    s = session()
    s.run(SCRIPT)
    assert lines(s.out.getvalue()) == ref


def test_errprintf_goes_to_stderr():
    s = session()
    s.run('errprintf "%d oops\\n", 3')
    assert s.err.getvalue() == "3 oops\n" and s.out.getvalue() == ""


def test_printf_formats_without_arguments_refused():
    s = session()
    with pytest.raises(CommandError, match="PRINTF string has formats"):
        s.run('printf "%g\\n"')
    with pytest.raises(CommandError, match="ERRPRINTF"):
        s.run('errprintf "%g\\n"')


def test_histogram_text_bins():
    # values 2..14: 21 bins, an edge value counts in the bin below (REF)
    text = histogram_text([float(v) for v in range(2, 15)])
    rows = text.strip().split("\n")
    assert len(rows) == 21
    assert sum(int(r.split()[-1]) for r in rows) == 13
    assert histogram_text([]) == "No qualifying values.\n"
    assert histogram_text([3.0, 3.0]).split() == ["3", "-", "3", "2"]
    log = histogram_text([-1.0, 0.0, 1.0, 10.0, float("nan")], log=True).strip().split("\n")
    assert log[0].split() == ["<=", "0.0", "2"] and log[-1].split() == ["NaN", "1"]
    assert len(log) == 22 and sum(int(r.split()[-1]) for r in log[1:-1]) == 2


def test_quit_status():
    s = session()
    with pytest.raises(Quit) as exc:
        s.run("q 3")
    assert exc.value.code == 3
    with pytest.raises(Quit) as exc:
        s.run("quit 257")
    assert exc.value.code == 1


def test_suppress_warning_is_a_command(evolver, tmp_path):
    # REF: read sections call it (suppress the hessian's "not positive definite")
    s = session()
    s.run("suppress_warning 1825; suppress_warning 1055; unsuppress_warning 1825")
    assert s.suppressed_warnings == {1055}
    with pytest.raises(CommandError, match="needs a warning number"):
        s.run("suppress_warning")
    ref = run_reference(evolver, CUBE, "suppress_warning 1825\nprint 7\n", cwd=str(tmp_path))
    assert [ln.strip() for ln in ref if ln.strip()] == ["7"]
