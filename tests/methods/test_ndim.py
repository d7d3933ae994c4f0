"""pyevolver.methods.ndim: the soapfilm model in SPACE_DIMENSION 4 and 5.

Areas against closed forms (a unit square rotated into R^4 has area 1), the
total energy's gradient (facet tensions, edge tensions, linear_elastic_B)
against central differences, ``g`` with level-set constraints in x4, x5, and
the refusals by name of what needs three dimensions (the transcripts against
evolver-nox-d are in tests/reference/test_space_dimension_reference.py)."""
import io

import numpy as np
import pytest
from finite_differences import assert_gradient, central_gradient
from tolerances import ROUNDOFF

import pyevolver
from pyevolver.errors import PyEvolverError, UnsupportedError
from pyevolver.evolve.gradient import energy_gradient
from pyevolver.methods import ndim as ND


def _rotation(d, seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).standard_normal((d, d)))
    return q


def _square(d, seed=0, top="", faces_extra=""):
    """The unit square (two triangles, centre vertex) rotated into R^d."""
    P = np.zeros((5, d))
    P[:4, :2] = [[0, 0], [1, 0], [1, 1], [0, 1]]
    P[4, :2] = [0.5, 0.5]
    P = P @ _rotation(d, seed).T + 0.3
    verts = "\n".join(f"{k + 1} " + " ".join(f"{x:.17g}" for x in p) for k, p in enumerate(P))
    return (f"space_dimension {d}\n{top}\nvertices\n{verts}\n"
            "edges\n1 1 2\n2 2 3\n3 3 4\n4 4 1\n5 1 5\n6 2 5\n7 3 5\n8 4 5\n"
            f"faces\n1 1 6 -5 {faces_extra}\n2 2 7 -6 {faces_extra}\n"
            f"3 3 8 -7 {faces_extra}\n4 4 5 -8 {faces_extra}\n")


def _load(tmp_path, text, name="nd.fe"):
    p = tmp_path / name
    p.write_text(text)
    return pyevolver.load(str(p), out=io.StringIO(), err=io.StringIO())


@pytest.mark.parametrize("d", [4, 5])
def test_a_rotated_unit_square_has_area_1(tmp_path, d):
    sess = _load(tmp_path, _square(d, seed=d))
    t = sess.surface.evaluate()
    assert type(t) is ND.NDTotals and sess.surface.X.shape == (5, d)
    assert abs(t.total_area - 1.0) <= ROUNDOFF
    assert abs(sess.value("total_energy") - 1.0) <= ROUNDOFF
    assert np.allclose(t.edge_length[:4], 1.0, rtol=ROUNDOFF)


def test_the_energy_gradient_matches_central_differences(tmp_path):
    # facet tensions, an edge tension and linear_elastic_B, every coordinate free
    rng = np.random.default_rng(5)
    top = ("quantity st energy method linear_elastic_B global\n"
           "define facet attribute poisson_ratio real")
    sess = _load(tmp_path, _square(5, 1, top, "poisson_ratio 0.3 tension 0.7"))
    s = sess.surface
    s.X = s.X + 0.1 * rng.standard_normal(s.X.shape)
    s.eattr["tension"] = rng.uniform(0.0, 1.0, s.ne)
    t = s.evaluate()
    assert set(t.terms) >= {"facet_tension", "edge_tension"}
    g = energy_gradient(t)
    assert g.shape == (5, 5)
    assert_gradient(g, central_gradient(s, lambda s: s.evaluate().energy, dims=5))


def test_g_keeps_the_constraints_in_x4_x5(tmp_path):
    top = ("constraint 1 formula: x4 = 0.2\nconstraint 2 formula: x4^2 + x5^2 = 1\n")
    text = _square(5, 2, top).replace("\n5 ", "\n5 ", 1)
    lines = text.split("\n")
    k = lines.index("vertices")
    lines[k + 1] += " constraint 1"
    lines[k + 2] += " constraint 1, 2"
    sess = _load(tmp_path, "\n".join(lines))
    sess.run("g 5")
    X = sess.surface.X
    assert abs(X[0, 3] - 0.2) <= 1e-12 and abs(X[1, 3] - 0.2) <= 1e-12
    assert abs(X[1, 3] ** 2 + X[1, 4] ** 2 - 1) <= 1e-12
    assert sess.value("total_energy") < 1.0


@pytest.mark.parametrize("top, words", [
    ("quantity a energy method facet_area global",
     "SPACE_DIMENSION 5: method facet_area (quantity a) needs 3 dimensions"),
    ("quantity a energy function 2", "SPACE_DIMENSION 5: FUNCTION quantities (a) need"),
    ("constraint 1 formula: x4 = 0.3\nenergy:\ne1: 0\ne2: 0\ne3: x4\ne4: 0\ne5: 0",
     "SPACE_DIMENSION 5: constraint energy and content integrals need 3 dimensions"),
])
def test_what_needs_three_dimensions_is_refused_by_name(tmp_path, top, words):
    text = _square(5, 3, top)
    if "constraint 1" in top:
        text = text.replace("edges\n1 1 2\n", "edges\n1 1 2 constraint 1\n")
    with pytest.raises(PyEvolverError) as exc:
        _load(tmp_path, text)
    assert "not supported in pyevolver" in str(exc.value) and words in str(exc.value)


def test_bodies_are_refused_at_the_space_dimension_line(tmp_path):
    with pytest.raises(PyEvolverError) as exc:
        _load(tmp_path, "\n" + _square(4, 0) + "bodies\n1 1 2 3 4\n")
    assert exc.value.line == 2
    assert "SPACE_DIMENSION 4: bodies need 3 dimensions" in str(exc.value)


@pytest.mark.parametrize("cmd, words", [
    ("saddle", "the Hessian's eigenvalues need 3 dimensions"),
    ("eigenprobe 0", "the Hessian's eigenvalues need 3 dimensions"),
    ("M 2", "the quadratic model needs 3 dimensions"),
    ('export("{tmp}/a.vtu")', "mesh exports need 3 dimensions"),
    ("print vertex[1].vertex_normal[1]", "facet normals need 3 dimensions"),
])
def test_commands_that_need_three_dimensions_are_refused(tmp_path, cmd, words):
    sess = _load(tmp_path, _square(5, 4))
    X0 = sess.surface.X.copy()
    with pytest.raises(PyEvolverError) as exc:
        sess.run(cmd.format(tmp=tmp_path))
    assert f"not supported in pyevolver: SPACE_DIMENSION 5: {words}" in str(exc.value)
    assert np.array_equal(sess.surface.X, X0) and sess.surface.nf == 4


def test_pictures_are_refused(tmp_path):
    from pyevolver.io.render import snapshot
    sess = _load(tmp_path, _square(4, 4))
    with pytest.raises(UnsupportedError, match="SPACE_DIMENSION 4: pictures need 3"):
        snapshot(sess.surface, str(tmp_path / "a.png"))


def test_coordinates_past_the_space_dimension_are_errors(tmp_path):
    out = io.StringIO()
    p = tmp_path / "c.fe"
    p.write_text(_square(4, 0))
    sess = pyevolver.load(str(p), out=out, err=out)
    sess.run("print vertex[2].x4 - vertex[2].w")
    assert out.getvalue().split() == ["0"]
    with pytest.raises(PyEvolverError, match="Coordinate dimension exceeds space dimension"):
        sess.run("print vertex[2].x5")
