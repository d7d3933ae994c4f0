"""The check after every command (issue 25): non-finite results fail and
are undone, zero-area facets and unconverged projections warn as the
Evolver does, numerical failures are explained, overflow at load is named."""
from __future__ import annotations

import io
import subprocess

import numpy as np
import pytest

from pyevolver.errors import CommandError, DatafileError
from pyevolver.session import health
from pyevolver.session.core import Session

TRI = """vertices
1 0 0 0
2 1 0 0
3 2 0 0
4 0 1 0
edges
1 1 2
2 2 3
3 3 1
4 2 4
5 4 1
faces
1 1 2 3
2 1 4 5
"""

UNSAT = """constraint 1
formula: x^2 + y^2 + 1 = 0
vertices
1 0 0 0 constraint 1
2 1 0 0
3 0 1 0
edges
1 1 2
2 2 3
3 3 1
faces
1 1 2 3
"""

SINGULAR = """constraint 1
formula: (x^2 + y^2 - 1)^2 = 0
vertices
1 1 0 0 constraint 1
2 0 1 0 constraint 1
3 0 0 1
4 0.5 0.5 1
edges
1 1 2
2 2 3
3 3 1
4 2 4
5 4 3
faces
1 1 2 3
2 -2 4 5
"""


def _ref(exe, path, commands):
    r = subprocess.run([exe, "-p1", str(path)], input=commands + "q\nq\n",
                       capture_output=True, text=True, timeout=60)
    return r.stdout + r.stderr


def _load(text, name="t.fe"):
    out, err = io.StringIO(), io.StringIO()
    return Session.load(name, out=out, err=err, text=text), out, err


def test_zero_area_facet_warns_like_the_evolver(evolver, tmp_path):
    s, out, err = _load(TRI)
    s.run("list facets")            # no motion: no warning (REF warns in g)
    assert "Zero area" not in err.getvalue()
    s.run("g 1")
    assert err.getvalue().count("WARNING! Zero area for facet 1.") == 1
    s.run("g 1")                   # the same set of facets: not repeated
    assert err.getvalue().count("Zero area") == 1
    path = tmp_path / "zero.fe"
    path.write_text(TRI)
    ref = _ref(evolver, path, "g 1\n")
    assert "WARNING! Zero area for facet 1." in ref


def test_unsatisfiable_constraint_warns_1792(evolver, tmp_path):
    s, out, err = _load(UNSAT)
    s.run("g 1")
    assert "WARNING 1792: Vertex 1 doesn't converge to constraint 1" in err.getvalue()
    path = tmp_path / "unsat.fe"
    path.write_text(UNSAT)
    assert "WARNING 1792: Vertex 1 doesn't converge to constraint 1" in \
        _ref(evolver, path, "g 1\n")


def test_singular_hessian_is_a_located_plain_error():
    s, out, err = _load(SINGULAR)
    X = s.surface.X.copy()
    with pytest.raises(CommandError) as e:
        s.run("hessian", where="script.cmd", line=7)
    msg = str(e.value)
    assert msg.startswith("script.cmd:7: ") and "singular linear system" in msg
    assert "LinAlgError" not in msg and "internal error" not in msg
    assert np.array_equal(s.surface.X, X)


def test_command_making_energy_infinite_fails_and_is_undone():
    s, out, err = _load(TRI.replace("4 0 1 0", "4 0 1 0"))
    e0 = s.total_energy
    with pytest.raises(CommandError, match="total energy infinite"):
        s.run("set facet tension 1e308; set facet[2] tension 1e308*1e10/1e10")
    s.run("print 1")            # the session goes on
    with pytest.raises(CommandError, match="total energy infinite"):
        s.run("set vertex[4] y 1e200")
    assert s.total_energy == e0 and s.surface.X[3, 1] == 1.0


def test_overflowing_coordinate_at_load_is_a_located_error():
    with pytest.raises(DatafileError, match="ovf.fe:5: vertex coordinate inf"):
        _load(TRI.replace("4 0 1 0", "4 0 1e999 0"), "ovf.fe")


def test_overflowing_energy_at_load_is_named():
    s, out, err = _load(TRI.replace("4 0 1 0", "4 0 1e200 0"), "big.fe")
    assert "big.fe: warning: the total energy is infinite" in err.getvalue()
    s.run("print 1")             # a command that leaves it as it was does not fail
    s.run("set vertex[4] y 1")   # nor one that makes it finite again
    assert np.isfinite(s.total_energy)


def test_explain():
    assert "division by zero" in health.explain(ZeroDivisionError())
    assert "could not be solved" in health.explain(np.linalg.LinAlgError("SVD did not converge"))


def test_relaxed_elastic_reference_that_overflows_loads_with_the_warning(tmp_path):
    """Found by the deep hostile fuzz: a reference coordinate of 1e308 made
    relaxed_elastic's metric not positive definite in the first evaluation
    of the load (numpy's LinAlgError escaped).  Now its facets' values are
    NaN and the load warns, as for any overflow."""
    text = ("space_dimension 5\nquantity rel info_only method relaxed_elastic global\n"
            "define vertex attribute ref_coord real[2]\ndefine facet attribute poisson_ratio real\n"
            "constraint 1 formula: x4 = ref_coord[1]\nconstraint 2 formula: x5 = ref_coord[2]\n"
            "vertices\n1 0 0 0 0 0 fixed ref_coord 0 0\n"
            "2 1.2 0 0.1 1 0.1 constraint 1,2 ref_coord 1e308 0\n"
            "3 0 0.9 0.2 0 1 constraint 1,2 ref_coord 0 1\n"
            "edges\n1 1 2\n2 2 3\n3 3 1\nfaces\n1 1 2 3\n")
    err = io.StringIO()
    with np.errstate(all="ignore"):
        Session.load("el.fe", out=io.StringIO(), err=err, text=text, run_read=False)
    assert "el.fe: warning: the total energy is " in err.getvalue()      # (NaN or infinite)


def test_numerical_failure_while_loading_is_a_datafile_error(monkeypatch):
    """What is left of a numerical failure in a load's first evaluation is
    a DatafileError in plain words, not a traceback."""
    from pyevolver.model import surface as S

    def singular(self):
        raise np.linalg.LinAlgError("Singular matrix")
    monkeypatch.setattr(S.Surface, "evaluate", singular)
    with pytest.raises(DatafileError) as e:
        Session.load("c.fe", out=io.StringIO(), err=io.StringIO(), run_read=False,
                     text="vertices\n1 0 0 0\n2 1 0 0\n3 0 1 0\nedges\n1 1 2\n2 2 3\n3 3 1\n"
                          "faces\n1 1 2 3\n")
    assert str(e.value).startswith("c.fe: evaluating the loaded surface met a singular")
