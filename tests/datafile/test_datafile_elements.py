"""pyevolver.datafile.elements: the element sections (vertices, edges,
faces, bodies) read into the Scene's blocks, by the numpy fast path and by
the grammar, through the public reader; malformed lines are located."""
from __future__ import annotations

import math

import numpy as np
import pytest

from pyevolver.datafile.elements import ElementSections
from pyevolver.datafile.reader import Reader, read_datafile
from pyevolver.errors import DatafileError
from pyevolver.limits import MAX_FACE_EDGES

# a unit square pyramid: 5 vertices, 8 edges, 5 faces (closed: V - E + F = 2)
PYRAMID = """parameter hh = 1
vertices
1 0 0 0
2 1 0 0
3 1 1 0
4 0 1 0
5 0.5 0.5 hh
edges
1 1 2
2 2 3
3 3 4
4 4 1
5 1 5
6 2 5
7 3 5
8 4 5
faces
1 -4 -3 -2 -1
2 1 6 -5
3 2 7 -6
4 3 8 -7
5 4 5 -8
bodies
1 1 2 3 4 5
"""


def read(text):
    return read_datafile("el.fe", text)


def rows(block):
    return [list(map(float, d)) for d in block.data]


def test_reader_is_an_element_reader():
    assert issubclass(Reader, ElementSections)


def test_pyramid_counts_loops_and_volume():
    sc = read(PYRAMID)
    V, E, F = (np.asarray(getattr(sc, k).ids) for k in ("vertices", "edges", "faces"))
    assert (len(V), len(E), len(F), len(sc.bodies.ids)) == (5, 8, 5, 1)
    assert len(V) - len(E) + len(F) == 2
    X = np.array(rows(sc.vertices))
    ends = {int(i): tuple(map(int, d)) for i, d in zip(E, sc.edges.data)}
    vol = 0.0
    for loop in sc.faces.data:
        # each face's signed edges form a closed loop, head to tail
        verts = []
        for e in map(int, loop):
            a, b = ends[abs(e)] if e > 0 else ends[abs(e)][::-1]
            verts.append((a, b))
        assert all(verts[k][1] == verts[(k + 1) % len(verts)][0] for k in range(len(verts)))
        P = X[[a - 1 for a, _ in verts]]
        for k in range(1, len(P) - 1):        # fan triangles: divergence theorem
            vol += np.dot(P[0], np.cross(P[k], P[k + 1])) / 6
    assert vol == pytest.approx(1 / 3, rel=1e-14)        # base 1, height 1


def test_fast_path_and_grammar_give_the_same_numbers():
    plain = read(PYRAMID.replace("0.5 0.5 hh", "0.5 0.5 1"))
    # the same surface with expressions, attributes and a parameter (grammar path)
    text = (PYRAMID.replace("2 1 0 0", "2 cos(0) 0 0 fixed")
            .replace("5 0.5 0.5 hh", "5 1/2 sqrt(0.25) hh*1")
            .replace("3 3 4\n", "3 3 4 tension 2*hh\n"))
    sc = read(text)
    assert np.array_equal(np.array(rows(sc.vertices)), np.array(rows(plain.vertices)))
    assert rows(sc.edges) == rows(plain.edges)
    assert sc.vertices.attrs == {1: [("fixed", [])]}
    assert sc.edges.attrs == {2: [("tension", [2.0])]}
    assert list(sc.vertices.lines) == [3, 4, 5, 6, 7]
    # all-numeric sections stay one array
    assert isinstance(plain.vertices.data, np.ndarray) and plain.vertices.data.shape == (5, 3)


def test_attributes_quantities_and_warnings():
    text = ("define vertex attribute rc real[3]\n"
            "quantity q1 energy method facet_area\n"
            "vertices\n1 0 0 0 rc {1 2 3}\n2 1 0\n3 0 1 0\n"
            "edges\n1 1 2\n2 2 3 color red\n3 3 1 bogus\n"
            "faces\n1 1 2 3 q1-\n")
    sc = read(text)
    assert sc.vertices.attrs[0] == [("attribute", ["rc", 1.0, 2.0, 3.0])]
    # too few coordinates: the rest are 0, with a warning (REF WARNING 1127)
    assert rows(sc.vertices)[1] == [1.0, 0.0, 0.0]
    assert sc.edges.attrs[1] == [("color", [4.0])]            # red is colour 4
    assert sc.faces.attrs[0] == [("quantity", ["q1", -1])]
    assert sc.warnings == [
        ("wrong number of coordinates for vertex 2: 2 instead of 3 (the rest are 0)", 5, None),
        ("edge 3: unexpected word 'bogus' (ignored)", 10, 7)]
    assert rows(sc.edges)[2] == [3.0, 1.0]


BASE = "parameter a = 1\nvertices\n1 0 0 0\n2 1 0 0\n3 0 1 0\nedges\n1 1 2\n2 2 3\n3 3 1\n" \
       "faces\n1 1 2 3\n"


@pytest.mark.parametrize("old, new, line, col, words", [
    ("2 1 0 0", "2 1.2.3 0 0", 4, 3, "malformed number '1.2.3'"),
    ("2 1 0 0", "2 1 b 0", 4, 5, "undefined parameter 'b'"),
    ("2 1 0 0", "2 1 0 0 bogus", 4, 9, "undefined parameter 'bogus'"),
    ("2 2 3", "2 2 ) 3", 8, 5, "unexpected ')'"),
    ("2 2 3", "2 2 3; 4", 8, 6, "unexpected ';': one element per line"),
    ("1 1 2 3", "1 1 2 3 tension", 11, 9, "facet 1: 'tension' needs a value"),
    ("1 1 2 3", "1 1 2.5 3", 11, None, "expected an integer id, got 2.5"),
    ("1 0 0 0", "0 0 0 0", 3, 1, "vertex id 0 is out of range"),
    ("3 0 1 0", "3 0 1e400 0 fixed", 5, None, "is not a finite number"),
])
def test_malformed_lines_are_located(old, new, line, col, words):
    with pytest.raises(DatafileError) as exc:
        read(BASE.replace(old, new, 1))
    e = exc.value
    assert (e.line, e.column) == (line, col) and words in e.message
    assert str(e).startswith(f"el.fe:{line}" + (f":{col}" if col else "") + ": ")
    assert e.excerpt == new


def test_comment_lines_keep_the_file_line_numbers():
    text = "/* two\nlines */\n" + BASE.replace("2 1 0 0", "2 1 0 c")
    with pytest.raises(DatafileError) as exc:
        read(text)
    assert (exc.value.line, exc.value.column) == (6, 7)


def test_too_many_face_edges_and_sections_twice():
    n = MAX_FACE_EDGES + 1
    with pytest.raises(DatafileError, match=f"face 1 has {n} edges"):
        read(BASE.replace("1 1 2 3", "1 " + " ".join(["1"] * n)))
    with pytest.raises(DatafileError) as exc:
        read(BASE + "faces\n2 1 2 3\n")
    assert (exc.value.line, exc.value.column) == (12, 1)
    assert "section 'faces' appears twice" in exc.value.message


def test_expression_values_on_element_lines():
    sc = read("parameter t = pi/3\nvertices\n1 cos(t) sin(t) -1\n2 (1 -3) 0 0\n")
    x, y, z = rows(sc.vertices)[0]
    assert (x, z) == (pytest.approx(0.5, rel=1e-15), -1.0)
    assert y == pytest.approx(math.sqrt(3) / 2, rel=1e-15)
    # inside parentheses a minus after a space is a subtraction
    assert rows(sc.vertices)[1] == [-2.0, 0.0, 0.0]
