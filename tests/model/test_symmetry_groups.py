"""The symmetry groups of pyevolver.model.groups on hand-written datafiles
(tests/data/symmetry_groups: annulus sectors whose last side is the first
one carried by a group element, and a wedge about an axial point), against
evolver-nox-d run live: `g`, `r` and `u` (the new edges' codes in `list
edges`), `list vertices`, `V`, energies and dumps both ways; the commands refused
by name."""
import os

import pytest

import pyevolver
from comparison import _same, run_pyevolver
from pyevolver.errors import PyEvolverError
from reference import run_reference

DATA = os.path.join(os.path.dirname(__file__), "..", "data", "symmetry_groups")
SLOW = pytest.mark.slow
EVOLVING = ["rotate_axial", "screw_symmetry", "cubocta", "cubelat",
            pytest.param("rotate", marks=SLOW), pytest.param("flip_rotate", marks=SLOW),
            pytest.param("central_symmetry", marks=SLOW), pytest.param("xyz", marks=SLOW)]
SCRIPT = ("g 10\nprint total_energy\nr\nlist edges\ng 5\nlist vertices\nlist facets\n"
          "print total_energy\nprint vertex_count + edge_count + facet_count\n")
EQUI = "u\nlist edges\nlist facets\ng 3\nprint total_energy\n"
AVERAGE = "V\ng 3\nrawv\nrawestv\nlist vertices\nprint total_energy\n"


def _path(name):
    return os.path.join(DATA, name + ".fe")


def _ref(evolver, path, script):
    return [ln for ln in run_reference(evolver, path, script)
            if ln.strip() and not ln.startswith(("Element memory", "Total data memory"))]


def _ours(path, script):
    rc, out, err = run_pyevolver(path, script)
    assert rc == 0, err
    assert not err, err
    return [ln for ln in out if ln.strip()]


@pytest.mark.parametrize("name", EVOLVING)
def test_evolve_and_refine_as_the_evolver(evolver, name):
    path = _path(name)
    script = SCRIPT + EQUI + ("" if name == "rotate_axial" else AVERAGE)
    ref = _ref(evolver, path, script)
    out = _ours(path, script)
    assert len(ref) > 100
    assert _same(out, ref, 1e-9), "\n".join(out)


def test_quarter_turn_as_the_evolver(evolver):
    """The facets of quarter_turn.fe (their corners placed by REF's
    products of codes), its total area and `g` (REF's forces leave out the
    corners with nonzero codes); `r` is refused by name."""
    path = _path("quarter_turn")
    script = ("list facets\nprint total_area\nprint wrap_compose(4096, 126976)\ng 5\n"
              "list vertices\nU\ng 3\nprint total_energy\n")
    ref = [ln for ln in _ref(evolver, path, script)
           if not ln.startswith(("WARNING 2000", "NOTE: There were")) and "Line 71" not in ln]
    assert _same(_ours(path, script), ref, 1e-9)
    with pytest.raises(PyEvolverError, match='`r` in SYMMETRY_GROUP "quarter_turn"'):
        pyevolver.load(path).run("r")


@pytest.mark.parametrize("name", ["cubocta", pytest.param("xyz", marks=SLOW)])
def test_hessian_steps_as_the_evolver(evolver, name):
    """`hessian` and the eigenvalue commands (hessian_normal's normals: the
    facets' area vectors summed as computed, without the maps, as REF)."""
    path = _path(name)
    script = "g 5\nhessian\nhessian\nprint total_energy\neigenprobe 1\nlanczos 1\n"
    assert _same(_ours(path, script), _ref(evolver, path, script), 1e-9)


@pytest.mark.parametrize("name", ["cubocta", pytest.param("rotate", marks=SLOW),
                                  pytest.param("screw_symmetry", marks=SLOW),
                                  pytest.param("flip_rotate", marks=SLOW)])
def test_edge_bisection_as_the_evolver(evolver, name):
    """`K`, `l` and `refine edges`: the new edges' codes as `r`'s; `K`'s
    midpoint, when the choosing facet runs along the edge backwards, in the
    head's frame (g⁻¹ of the midpoint) as REF puts it, the codes unchanged."""
    path = _path(name)
    for script in ("g 5\nK 0.9\nlist vertices\nlist edges\nlist facets\ng 3\n",
                   "g 5\nl 0.2\nlist edges\ng 2\nrefine edges where id < 9\nlist edges\ng 3\n"):
        assert _same(_ours(path, script), _ref(evolver, path, script), 1e-9), script


@pytest.mark.parametrize("name", ["rotate_body", pytest.param("cubocta", marks=SLOW),
                                  pytest.param("screw_symmetry", marks=SLOW)])
def test_edge_deletion_as_the_evolver(evolver, name):
    """`t` and `delete edges`: the eliminated vertex's edges' codes composed
    with the deleted edge's; an edge whose ends another edge joins too (a
    copy across the group: the closed tube's rings) is left, as REF."""
    path = _path(name)
    script = "g 5\nt 0.35\nlist vertices\nlist edges\nlist facets\ng 5\nv\n"
    assert _same(_ours(path, script), _ref(evolver, path, script), 1e-9)


@pytest.mark.parametrize("name", ["rotate_axial", pytest.param("cubelat", marks=SLOW)])
def test_dumps_both_ways(evolver, tmp_path, name):
    path = _path(name)
    check = "g 3\nlist edges\nprint total_energy\n"
    ref_dump = tmp_path / "ref.dmp"
    run_reference(evolver, path, f'r\ng 2\ndump "{ref_dump}"\n')
    ours_dump = tmp_path / "ours.dmp"
    _ours(path, f'r\ng 2\ndump "{ours_dump}"\n')
    text = ours_dump.read_text()
    assert f'SYMMETRY_GROUP "{name.split("_")[0]}"' in text and " wrap " in text
    for dump in (ref_dump, ours_dump):
        assert _same(_ours(str(dump), check), _ref(evolver, str(dump), check), 1e-9), dump.name


@pytest.mark.parametrize("command", ["o", "n 0.1", "w 0.1", "delete facet[5]",
                                     "equiangulate edge[5]", "quadratic"])
def test_commands_without_the_group_are_refused_by_name(command):
    sess = pyevolver.load(_path("rotate"))
    before = sess.surface.X.copy()
    with pytest.raises(PyEvolverError, match='in SYMMETRY_GROUP "rotate"'):
        sess.run(command)
    assert (sess.surface.X == before).all()


def test_wrap_attribute_and_functions():
    sess = pyevolver.load(_path("xyz"))
    vals = [sess.value(e) for e in ("edge[3].wrap", "wrap_compose(1, 1)", "wrap_inverse(1)",
                                    "symmetry_group", "torus")]
    assert vals == [1, -1, -1, 1, 0]


def test_vertex_averaging_next_to_an_axial_point_is_refused():
    sess = pyevolver.load(_path("rotate_axial"))
    for command in ("V", "rawv", "rawestv", "K 0.9", "l 0.2", "refine edges where id < 3",
                    "t 0.6", "delete edge[3]"):
        with pytest.raises(PyEvolverError, match="axial point"):
            sess.run(command)
    sess.run("u")


def test_axial_point_attribute_and_listing(evolver):
    path = _path("rotate_axial")
    script = "print vertex[1].axial_point\nprint vertex[2].axial_point\nlist vertices\n"
    assert _same(_ours(path, script), _ref(evolver, path, script), 1e-12)


def test_double_axial_point_stops_as_in_the_evolver(evolver, tmp_path):
    """The manual's flag for flip_rotate; REF 2.70 does not read it."""
    text = open(_path("rotate_axial")).read().replace('"rotate"', '"flip_rotate"')
    path = tmp_path / "dax.fe"
    path.write_text(text.replace("0.3 axial_point fixed", "0 double_axial_point"))
    with pytest.raises(PyEvolverError, match=r"dax\.fe:\d+"):
        pyevolver.load(str(path))
    import subprocess
    ref = subprocess.run([evolver, "-p1", str(path)], input="q\nq\n", stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, timeout=60).stdout
    assert "ERROR 2105" in ref and "double_axial_point" in ref
