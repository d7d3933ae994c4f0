"""Direct tests of the pyevolver.session package: it exports Session, the
class of pyevolver.session.core, also pyevolver.Session."""
import io
import os

import pyevolver
import pyevolver.session as session_pkg
from pyevolver.session import Session
from pyevolver.session import core

from reference import numbers

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def test_exports():
    assert session_pkg.__all__ == ["Session"]
    assert Session is core.Session is pyevolver.Session


def test_session_from_the_package_loads_the_cube(evolver):
    nv, ne, nf, area = numbers(evolver, CUBE, ["vertex_count", "edge_count", "facet_count",
                                               "total_area"])
    s = Session.load(CUBE, out=io.StringIO(), err=io.StringIO())
    assert (s.count("vertex"), s.count("edge"), s.count("facet")) == (nv, ne, nf)
    assert nv - ne + nf == 2                          # a sphere's Euler characteristic
    assert s.total_area == area == 6.0
    assert repr(s) == (f"<Session {CUBE}: {int(nv)} vertices, {int(ne)} edges, {int(nf)} "
                       f"facets, 1 body; energy {area:.10g}>")
    assert repr(Session(out=io.StringIO())) == "<Session: no surface>"
