"""pyevolver.datafile (the package): its modules import, its grammars ship
with it, and the reader it exports reads the shipped cube into the right
counts (8 vertices, 12 edges, 6 faces, 1 body; Euler characteristic 2)."""
from __future__ import annotations

import importlib
import os
import pkgutil

import numpy as np

import pyevolver.datafile as datafile
from pyevolver.datafile import grammar, reader

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CUBE = os.path.join(ROOT, "datafiles", "cube.fe")


def test_every_module_of_the_package_imports():
    names = {m.name for m in pkgutil.iter_modules(datafile.__path__)}
    assert {"reader", "writer", "grammar", "top", "elements", "located", "scan",
            "preprocess"} <= names
    for name in names:
        mod = importlib.import_module(f"pyevolver.datafile.{name}")
        assert mod.__name__ == f"pyevolver.datafile.{name}"


def test_grammar_files_ship_with_the_package():
    here = os.path.dirname(datafile.__file__)
    for fname in ("fe_top.lark", "fe_elements.lark"):
        path = os.path.join(here, fname)
        assert os.path.isfile(path) and os.path.getsize(path) > 0
    # the parsers are built from them (and cached: one parser per grammar)
    assert grammar.top_parser() is grammar.top_parser()
    assert grammar.line_parser() is grammar.line_parser()


def test_reader_exports():
    assert set(reader.__all__) == {"Reader", "read_datafile", "top_parser", "line_parser"}
    assert reader.top_parser is grammar.top_parser


def test_cube_counts_and_euler_characteristic():
    sc = reader.read_datafile(CUBE)
    nv, ne, nf, nb = (len(getattr(sc, k).ids) for k in ("vertices", "edges", "faces",
                                                         "bodies"))
    assert (nv, ne, nf, nb) == (8, 12, 6, 1)
    assert nv - ne + nf == 2
    X = np.asarray(sc.vertices.data, float)
    assert X.shape == (8, 3) and set(np.unique(X)) == {0.0, 1.0}
    # every edge of a face loop is used twice, once in each direction (closed surface)
    loops = [list(map(int, f)) for f in sc.faces.data]
    signed = [e for loop in loops for e in loop]
    assert sorted(signed) == sorted(-e for e in signed)
    assert sorted(abs(e) for e in signed) == sorted(list(range(1, 13)) * 2)
    # the body: all six faces, volume 1
    assert sorted(map(int, sc.bodies.data[0])) == [1, 2, 3, 4, 5, 6]
    assert sc.bodies.attrs[0] == [("volume", [1.0])]
    assert sc.read_text is not None and "gogo" in sc.read_text
