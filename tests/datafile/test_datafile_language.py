"""The datafile language of the manual ("The datafile" chapter) beyond the
basic grammar: named constraints and boundaries, string parameters,
top-section procedures and functions, PERIODS and VIEW_MATRIX by
expressions, expressions as element values (where a sign starts a new
value), array attributes, singular section keywords, body PRESSURE, the
other top-section keywords, and the lines the Evolver only warns about.

Each small datafile is written from the manual in ``tmp_path``; the numbers
come from the live reference Evolver run in the test.
"""
from __future__ import annotations

import io

import numpy as np
import pytest

from pyevolver.errors import DatafileError
from pyevolver.session.core import Session
from reference import numbers, run_reference

# a tetrahedron (4 vertices, 6 edges, 4 faces, 1 body): filled in by format()
TETRA = """{top}
{vkw}
1 0 0 0 {v1}
2 1 0 0 {v2}
3 0 1 0 {v3}
4 0 0 1 {v4}
{ekw}
1 1 2 {e1}
2 2 3
3 3 1
4 1 4
5 2 4
6 3 4
{fkw}
1 1 2 3 {f1}
2 1 5 -4
3 2 6 -5
4 3 4 -6
{bkw}
1 -1 2 3 4 {b1}
"""


def tetra(top="", vkw="vertices", ekw="edges", fkw="faces", bkw="bodies", **kw):
    fields = {k: kw.get(k, "") for k in ("v1", "v2", "v3", "v4", "e1", "f1", "b1")}
    return TETRA.format(top=top, vkw=vkw, ekw=ekw, fkw=fkw, bkw=bkw, **fields)


def write(tmp_path, text, name="t.fe"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def ours(path, exprs, commands=""):
    """pyevolver's values of ``exprs`` after loading ``path`` and running
    ``commands``; also returns what went to stderr."""
    out, err = io.StringIO(), io.StringIO()
    with np.errstate(all="ignore"):
        ses = Session.load(path, out=out, err=err)
        if commands:
            ses.run(commands, stop_on_error=False)
        mark = out.tell()
        for e in exprs:
            ses.run(f'printf "RESULT %.17g\\n", {e}\n')
    vals = [float(l.split()[1]) for l in out.getvalue()[mark:].splitlines()
            if l.startswith("RESULT")]
    assert len(vals) == len(exprs), out.getvalue()
    return vals, err.getvalue()


def ref_numbers(evolver, path, exprs, commands=""):
    if not commands:
        return numbers(evolver, path, exprs)
    cmds = commands + "\n" + "".join(f'printf "RESULT %.17g\\n", {e}\n' for e in exprs)
    lines = run_reference(evolver, path, cmds)
    vals = [float(l.split()[1]) for l in lines if l.startswith("RESULT")]
    assert len(vals) == len(exprs), "\n".join(lines)
    return vals


def same(a, b, rel=1e-9):
    assert np.allclose(a, b, rtol=rel, atol=1e-12), (a, b)


def compare(evolver, path, exprs, commands=""):
    got, err = ours(path, exprs, commands)
    same(got, ref_numbers(evolver, path, exprs, commands))
    return err


# ---------------------------------------------------------------------------
# named constraints and boundaries

NAMED = """
constraint aa
formula: x = 0.5
constraint bb
formula: y = 0.25
constraint 1
formula: z = 0
constraint top nonnegative
formula: z = 0.5
"""


def test_named_constraints_take_the_lowest_free_number(evolver, tmp_path):
    # aa takes 1, bb 2; the explicit 'constraint 1' then moves aa to 3; top is 4
    path = write(tmp_path, tetra(NAMED, v2="constraint aa", v3="constraint 1,bb",
                                 v4="constraints top", e1="constraint aa"))
    compare(evolver, path, ["aa", "bb", "top", "high_constraint", "total_area",
                            "vertex[2].x", "vertex[3].y", "vertex[4].z",
                            "vertex[2].on_constraint aa", "vertex[2].on_constraint 3",
                            "vertex[3].on_constraint bb", "edge[1].on_constraint aa",
                            "sum(vertex where on_constraint bb, 1)"])


def test_valid_constraint_and_boundary(evolver, tmp_path):
    path = write(tmp_path, tetra(NAMED, v2="constraint aa"))
    compare(evolver, path, ["valid_constraint(aa)", "valid_constraint(top)",
                            "valid_constraint(5)", "valid_constraint(2)",
                            "valid_boundary(1)", "is_constraint[top].nonnegative",
                            "is_constraint[top].fixed", "is_constraint[aa].fixed",
                            "is_constraint[1].nonpositive"])


def test_named_constraints_in_commands(evolver, tmp_path):
    path = write(tmp_path, tetra(NAMED, v2="constraint aa"))
    cmds = ("set vertex[4] constraint aa\nunset vertex[2] constraint aa\n"
            "cnt := 0; foreach vertex vv where on_constraint aa do cnt += 1")
    compare(evolver, path, ["vertex[4].x", "vertex[4].on_constraint aa",
                            "vertex[2].on_constraint aa", "cnt", "total_area"], cmds)


def test_list_shows_constraint_names(evolver, tmp_path):
    path = write(tmp_path, tetra(NAMED, v2="constraint aa", e1="constraint bb"))
    ref = run_reference(evolver, path, "list vertex[2]\nlist edge[1]\n")
    out = io.StringIO()
    ses = Session.load(path, out=out)
    ses.run("list vertex[2]\nlist edge[1]\n")
    mine = out.getvalue()
    assert "constraints aa" in " ".join(ref) and "constraints aa" in mine
    assert "constraints bb" in " ".join(ref) and "constraints bb" in mine


def test_named_boundary(evolver, tmp_path):
    text = """
boundary ring parameters 1
x1: cos(p1)
x2: sin(p1)
x3: 0
vertices
1 0 boundary ring fixed
2 2 boundary ring fixed
3 4 boundary ring fixed
edges
1 1 2 boundary ring
2 2 3 boundary ring
3 3 1 boundary ring
faces
1 1 2 3
"""
    path = write(tmp_path, text)
    compare(evolver, path, ["ring", "high_boundary", "vertex[2].x", "vertex[3].y",
                            "vertex[1].on_boundary ring", "total_area"])


def test_named_constraint_defined_twice_is_located(tmp_path):
    path = write(tmp_path, tetra("constraint aa\nformula: x = 0\nconstraint aa\nformula: y = 0\n"))
    with pytest.raises(DatafileError) as info:
        Session.load(path)
    assert info.value.line == 3 and "aa" in str(info.value)


# ---------------------------------------------------------------------------
# string parameters, top-section procedures and functions

def test_string_parameter(evolver, tmp_path):
    top = 'PARAMETER origin_name = "abc_def"\nparameter nn = 3\n'
    path = write(tmp_path, tetra(top))
    cmd = 'xx := sprintf "%s_%g", origin_name, nn; print xx\nprint origin_name\n'
    ref = run_reference(evolver, path, cmd)
    out = io.StringIO()
    Session.load(path, out=out).run(cmd)
    ref = [l for l in ref if l.strip()]
    assert ref == ["abc_def_3", "abc_def"]
    assert out.getvalue().split() == ref


def test_top_section_procedures_and_functions(evolver, tmp_path):
    # the manual's example (forward declaration, then the definition), and a
    # function defined before the parameters
    top = """procedure tester();
function real sq(real xx) { return xx*xx }
parameter aaa = 4
procedure tester() { aaa := aaa + 1 }
parameter bbb = 5
"""
    path = write(tmp_path, tetra(top) + "read\ntester()\n")
    compare(evolver, path, ["aaa", "sq(bbb)", "total_area"], "tester()")


# ---------------------------------------------------------------------------
# PERIODS and VIEW_MATRIX by expressions

TORUS = """TORUS_FILLED
parameter ll = 1.25
periods
ll 0 0
0 2*ll/2 0
0 0 (ll - 0.25)
view_matrix
ll 0 0 0
0 1 0 0
0 0 1 -ll/2
0 0 0 1
"""


def test_periods_by_expressions(evolver, tmp_path):
    # twointor.fe's cell with periods written as expressions of a parameter
    with open(__import__("conftest").example("twointor.fe")) as fh:
        text = fh.read()
    head, rest = text.split("vertices", 1)
    path = write(tmp_path, TORUS + "\nvertices" + rest)
    compare(evolver, path, ["total_energy", "body[1].volume", "body[2].volume"])
    # a changed parameter reaches the periods at recalc (manual)
    compare(evolver, path, ["total_energy", "body[1].volume"], "ll := 1.3\nrecalc")


# ---------------------------------------------------------------------------
# expressions as element values; where a sign starts a new value

@pytest.mark.parametrize("coords", ["0.5 -0.25 1", "0.5 - 0.25 1", "0.5 -aa 1",
                                    "1 (2 -3) 4", "0.5 0.25 +1", "0.5 +0.25 1",
                                    "cos(pi/3) sin(pi/3) 0.5", "1 atan2(1, -1) 4",
                                    "1 ((2) -3) 4", "0.5 0.25"])
def test_sign_starts_a_value(evolver, tmp_path, coords):
    text = tetra("parameter aa = 0.75\n").replace("4 0 0 1 \n", f"4 {coords}\n")
    path = write(tmp_path, text)
    compare(evolver, path, ["vertex[4].x", "vertex[4].y", "vertex[4].z", "total_energy"])


# ---------------------------------------------------------------------------
# attributes, section keywords, body pressure

@pytest.mark.parametrize("decl", ["real[3]", "real [3]", "real[ nn ]", "real[nn+1-1]",
                                  "integer[3]"])
def test_array_attribute_declarations(evolver, tmp_path, decl):
    top = f"parameter nn = 3\ndefine vertex attribute kk {decl}\n"
    path = write(tmp_path, tetra(top, v1="kk {1,2,3}", v2="kk 4 5 6"))
    compare(evolver, path, ["vertex[1].kk[3]", "vertex[2].kk[2]"])


def test_two_dimensional_attribute(evolver, tmp_path):
    from pyevolver.datafile.reader import read_datafile
    top = "define facet attribute ff real[2][3]\n"
    path = write(tmp_path, tetra(top, f1="ff {{1,2,3},{4,5,6}} tension 2"))
    compare(evolver, path, ["total_energy"])
    assert read_datafile(path).attributes[("facet", "ff")][1:] == (6, [2, 3])


@pytest.mark.parametrize("kws", [("vertex", "edge", "face", "body"),
                                 ("vertices", "edges", "facets", "bodies"),
                                 ("vertex", "edges", "facet", "bodies")])
def test_singular_and_plural_sections(evolver, tmp_path, kws):
    v, e, f, b = kws
    path = write(tmp_path, tetra(vkw=v, ekw=e, fkw=f, bkw=b, b1="volume 0.2"))
    compare(evolver, path, ["vertex_count", "edge_count", "facet_count", "body_count",
                            "total_energy"])


def test_body_pressure(evolver, tmp_path):
    # prescribed pressure: energy area - P V (manual, "Body pressure")
    path = write(tmp_path, tetra(b1="pressure 2"))
    compare(evolver, path, ["total_energy", "body[1].pressure"])
    compare(evolver, path, ["total_energy", "body[1].volume"], "g 3")


# ---------------------------------------------------------------------------
# top-section keywords

@pytest.mark.parametrize("top", ["merit_factor 2", "zoom_vertex 3", "zoom_radius 2.0",
                                 "suppress_warning 1825", "unsuppress_warning 1825",
                                 "parameter yy = 2 pscale = 2 pdelta = 0.1",
                                 "optimizing_parameter xx = 1 pdelta = 0.001",
                                 "keep_originals",
                                 "view_transforms 1 color red 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1",
                                 "view_transform_generators 1\n-1 0 0 0\n0 1 0 0\n0 0 1 0\n"
                                 "0 0 0 1"])
def test_settings_that_change_no_number(evolver, tmp_path, top):
    path = write(tmp_path, tetra(top + "\n", b1="volume 0.2"))
    compare(evolver, path, ["total_energy", "total_area"])


@pytest.mark.parametrize("top,word,line", [
    ("constraint 1 content_rank 2\nformula: z = 0", "CONTENT_RANK", 1),
    ("square_gaussian_curvature 1", "SQUARE_GAUSSIAN_CURVATURE", 1),
    ("define vertex attribute kk real function { self.kk := 1 }", "FUNCTION", 1),
    ("function real sq(real xx) { return xx*xx }\nparameter pp = sq(3)", "sq", 2),
])
def test_unsupported_settings_refused_by_name(tmp_path, top, word, line):
    path = write(tmp_path, tetra(top + "\n"))
    with pytest.raises(DatafileError) as info:
        Session.load(path)
    assert "not supported in pyevolver" in str(info.value) and word in str(info.value)
    assert info.value.line == line


# ---------------------------------------------------------------------------
# lines the Evolver warns about and reads on

@pytest.mark.parametrize("where", ["e1", "f1", "b1"])
def test_unknown_word_warns_and_goes_on(evolver, tmp_path, where):
    # REF: WARNING 2110 / 2115 / 2119 "Unexpected token", the rest of the line read
    path = write(tmp_path, tetra(**{where: "foo tension 3" if where != "b1" else
                                    "foo volume 0.2"}))
    err = compare(evolver, path, ["total_energy", "total_area"])
    assert "warning" in err and "foo" in err and "t.fe:" in err


def test_unknown_word_on_a_vertex_line_is_an_error(tmp_path):
    path = write(tmp_path, tetra(v2="foo"))
    with pytest.raises(DatafileError) as info:
        Session.load(path)
    assert info.value.line == 4 and "foo" in str(info.value)


def test_too_few_coordinates_warns(evolver, tmp_path):
    # REF: WARNING 1127 "Wrong number of coordinates", the missing ones 0
    text = tetra().replace("4 0 0 1 \n", "4 0.5 0.5\n")
    path = write(tmp_path, text)
    err = compare(evolver, path, ["vertex[4].z", "total_area"])
    assert "t.fe:6" in err and "coordinates" in err


def test_user_function_on_an_element_line_refused_by_name(tmp_path):
    # REF evaluates it with its command interpreter (vertex x = 4 here)
    top = "function real sq(real xx) { return xx*xx }\n"
    path = write(tmp_path, tetra(top).replace("2 1 0 0 \n", "2 sq(1) 0 0\n"))
    with pytest.raises(DatafileError) as info:
        Session.load(path)
    assert "not supported in pyevolver" in str(info.value) and "sq" in str(info.value)
    assert info.value.line == 5


def test_forward_declared_names(evolver, tmp_path):
    # REF's dumps declare named constraints ahead: "constraint pinned;"
    top = ("constraint bb;\nconstraint aa;\nconstraint 1\nformula: z = 0\n"
           "constraint aa\nformula: x = 0.5\nconstraint bb\nformula: y = 0.25\n")
    path = write(tmp_path, tetra(top, v2="constraint aa", v3="constraint 1,bb"))
    compare(evolver, path, ["aa", "bb", "high_constraint", "vertex[2].x", "vertex[3].y",
                            "total_area"])


def test_list_keeps_the_order_of_constraints(evolver, tmp_path):
    # REF lists an element's constraints as its datafile line gave them, then
    # those set later (named ones have small numbers: aa is 3 here)
    path = write(tmp_path, tetra(NAMED, v2="constraint 1,aa", v3="constraints bb 1",
                                 e1="constraint aa 1"))
    cmds = "list vertex\nlist edge[1]\nset vertex[4] constraint bb\nlist vertex[4]\n"
    ref = [l for l in run_reference(evolver, path, cmds) if "constraints" in l]
    out = io.StringIO()
    Session.load(path, out=out).run(cmds)
    mine = [l for l in out.getvalue().splitlines() if "constraints" in l]
    assert len(ref) == 4
    assert [l.split("constraints")[1].split("/*")[0].split() for l in mine] == \
        [l.split("constraints")[1].split("/*")[0].split() for l in ref]


@pytest.mark.parametrize("etype", ["facet", "facets", "face", "faces"])
def test_define_takes_plural_and_face(evolver, tmp_path, etype):
    path = write(tmp_path, tetra(f"define {etype} attribute kk real\n", f1="kk 2.5"))
    compare(evolver, path, ["facet[1].kk", "facet[2].kk", "total_area"])


def test_dump_keeps_the_names(evolver, tmp_path):
    # a dump writes named constraints and boundaries by name (declared ahead,
    # as REF's dumps do) and loads back with the same geometry
    path = write(tmp_path, tetra(NAMED, v2="constraint aa", v3="constraint 1,bb",
                                 e1="constraint aa"))
    out = io.StringIO()
    ses = Session.load(path, out=out)
    ses.run(f'dump "{tmp_path / "d.dmp"}"')
    text = (tmp_path / "d.dmp").read_text()
    assert "constraint aa;" in text and "CONSTRAINT aa" in text
    again, _ = ours(str(tmp_path / "d.dmp"), ["vertex[2].on_constraint aa", "total_area",
                                              "edge[1].on_constraint aa"])
    same(again, ref_numbers(evolver, path, ["vertex[2].on_constraint aa", "total_area",
                                            "edge[1].on_constraint aa"]))


def test_on_assign_call(evolver, tmp_path):
    # the manual's example: the procedure runs after each assignment
    top = ("procedure tester();\nparameter aaa = 4\nparameter bbb = 5 on_assign_call tester\n"
           "procedure tester() { aaa := bbb + 1 }\n")
    path = write(tmp_path, tetra(top))
    compare(evolver, path, ["aaa", "bbb"])
    compare(evolver, path, ["aaa", "bbb"], "bbb := 7")
    compare(evolver, path, ["aaa", "bbb"], "bbb := 7; bbb += 2")


def test_on_assign_call_needs_a_declared_procedure(tmp_path):
    path = write(tmp_path, tetra("parameter bbb = 5 on_assign_call tester\n"))
    with pytest.raises(DatafileError) as info:
        Session.load(path)
    assert "tester" in str(info.value) and info.value.line == 1


# ---------------------------------------------------------------------------
# vertex extra attributes in a level-set formula (the manual: "z = zfix")

ZFIX_TOP = """
define vertex attribute zfix real
constraint 1 formula: z = zfix
"""


@pytest.mark.parametrize("commands", ["", "g 3", "r; g 3; set vertex zfix 1.1 where id == 4; "
                                      "recalc; g 4"])
def test_vertex_attribute_in_a_constraint_formula(evolver, tmp_path, commands):
    path = write(tmp_path, tetra(top=ZFIX_TOP, v4="constraint 1 zfix 1.2",
                                 b1="volume 0.2"))
    compare(evolver, path, ["vertex[4].z", "total_energy", "total_area", "body[1].volume"],
            commands)


@pytest.mark.parametrize("commands", ["", "g 3; r; g 3"])
def test_array_attribute_entry_in_a_constraint_formula(evolver, tmp_path, commands):
    top = "define vertex attribute zz real[2]\nconstraint 1 formula: z = zz[2] + 0*zz[1]\n"
    path = write(tmp_path, tetra(top=top, v4="constraint 1 zz 0.5 1.3", b1="volume 0.2"))
    compare(evolver, path, ["vertex[4].z", "total_energy", "body[1].volume"], commands)


def test_array_attribute_entry_out_of_range_is_located(tmp_path):
    top = "define vertex attribute zz real[2]\nconstraint 1 formula: z = zz[3]\n"
    path = write(tmp_path, tetra(top=top, v4="constraint 1 zz 0.5 1.3"))
    with pytest.raises(DatafileError) as exc:
        Session.load(path, out=io.StringIO(), err=io.StringIO())
    assert "zz[3]" in str(exc.value) and "out of range" in str(exc.value)
    assert exc.value.line
