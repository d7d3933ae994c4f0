"""pyevolver.model.scene: the declarations a datafile makes, before any
geometry: defaults, the string / torus / dimension properties and the
records the reader fills."""
import numpy as np

from pyevolver.datafile.reader import read_datafile
from pyevolver.model import scene as SC

TEXT = """
PARAMETER rad = 2.5
constraint 1
formula: x^2 + y^2 = rad^2
boundary 2 parameters 1
x1: cos(p1)
x2: sin(p1)
x3: 0
quantity qa energy modulus 3 method facet_area global
method_instance mlen method edge_length
quantity ql info_only method mlen

vertices
1 0 0 0
2 1 0 0
3 0 1 0
edges
1 1 2
2 2 3
3 3 1
faces
1 1 2 3
"""


def test_defaults_and_properties():
    sc = SC.Scene()
    assert sc.filename == "<datafile>"
    assert sc.space_dimension == 3 and not sc.string and not sc.torus
    assert sc.vertices.ids == [] and sc.constraints == {} and sc.periods is None
    assert SC.Scene().parameters is not sc.parameters           # fresh containers
    sc.flags.add("string")
    assert sc.string
    sc2 = SC.Scene(values={"surface_dimension": 1, "space_dimension": 2})
    assert sc2.string and sc2.space_dimension == 2
    assert SC.Scene(flags={"torus_filled"}).torus
    m = SC.MethodDecl("facet_area")
    assert m.modulus == 1.0 and not m.is_global and m.vector is None


def test_reader_fills_the_declarations():
    sc = read_datafile("decls.fe", TEXT)
    assert isinstance(sc, SC.Scene) and sc.filename == "decls.fe"
    assert sc.parameters["rad"] == 2.5
    c = sc.constraints[1]
    assert isinstance(c, SC.ConstraintDecl) and c.id == 1 and c.energy is None
    b = sc.boundaries[2]
    assert isinstance(b, SC.BoundaryDecl) and b.nparams == 1 and len(b.coords) == 3
    q = sc.quantities["qa"]
    assert isinstance(q, SC.QuantityDecl) and q.kind == "energy" and q.modulus == 3
    assert [m.method for m in q.methods] == ["facet_area"] and q.methods[0].is_global
    assert sc.method_instances["mlen"].method == "edge_length"
    assert sc.quantities["ql"].kind == "info_only"
    # element blocks: datafile ids in order, their defining numbers
    assert list(sc.vertices.ids) == [1, 2, 3] and list(sc.faces.ids) == [1]
    assert np.allclose(sc.vertices.data[1], [1, 0, 0])
    assert list(sc.edges.data[2]) == [3, 1]
    assert list(sc.faces.data[0]) == [1, 2, 3]
    # the source line of each element (1-based)
    src = TEXT.splitlines()
    assert [src[n - 1] for n in sc.vertices.lines] == ["1 0 0 0", "2 1 0 0", "3 0 1 0"]
    assert [src[n - 1] for n in sc.edges.lines] == ["1 1 2", "2 2 3", "3 3 1"]
