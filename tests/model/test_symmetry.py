"""pyevolver.model.symmetry: SYMMETRY_GROUP "torus" (symtest.fe, the surface
of twointor.fe given with group elements), its wrap codes, REF's rules for
its body volumes, listings and dumps (evolver-nox-d run live), and the
refusal of the other built-in groups by name."""
import io
import os

import numpy as np
import pytest

import pyevolver
from comparison import _same, run_pyevolver
from conftest import example
from pyevolver.errors import PyEvolverError
from pyevolver.model import symmetry
from reference import run_reference

SYMTEST = example("symtest.fe")


def test_codes_round_trip():
    w = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1],
                  [-1, 1, 0], [1, 0, -1], [2, -3, 5]])
    codes = symmetry.encode_torus(w)
    assert codes[:6].tolist() == [1, 31, 64, 1984, 4096, 126976]
    assert codes[6] == 95 and codes[7] == 126977          # symtest.fe's edges 14, 20
    assert (symmetry.decode_torus(codes) == w).all()


def test_load_is_the_torus_model_with_euclidean_volumes():
    s = pyevolver.load(SYMTEST).surface
    assert s.symmetry_group == "torus"
    assert (s.periods == np.eye(3)).all()
    tw = pyevolver.load(example("twointor.fe")).surface
    assert (s.eattr["wrap"] == tw.eattr["wrap"]).all()
    assert np.allclose(s.X, tw.X)
    t = s.evaluate()
    assert t.energy == pytest.approx(tw.evaluate().energy, rel=1e-14)
    # REF: the facets' contents unwrapped from their first vertex, no cell lift
    assert t.volumes == pytest.approx([0.15625, -0.15625], rel=1e-14)


@pytest.mark.parametrize("name", sorted(n for n, why in symmetry.GROUPS.items() if why)
                         + ["no_such_group"])
def test_other_groups_are_refused_by_name(name, tmp_path):
    path = tmp_path / "g.fe"
    path.write_text(f'SYMMETRY_GROUP "{name}"\nvertices\n1 0 0 0\n2 1 0 0\n'
                    f'edges\n1 1 2 wrap 1\n')
    with pytest.raises(PyEvolverError) as exc:
        pyevolver.load(str(path))
    msg = str(exc.value)
    assert "not supported in pyevolver" in msg and f'"{name}"' in msg
    assert "g.fe:1" in msg


def test_wrap_needs_a_group(tmp_path):
    path = tmp_path / "w.fe"
    path.write_text("vertices\n1 0 0 0\n2 1 0 0\nedges\n1 1 2 wrap 1\n")
    with pytest.raises(PyEvolverError, match="WRAP without SYMMETRY_GROUP"):
        pyevolver.load(str(path))


def test_group_variables_and_functions():
    out = io.StringIO()
    sess = pyevolver.load(SYMTEST, out=out)
    sess.run("print symmetry_group\nprint torus\nprint wrap_compose(64, 31)\n"
             "print wrap_inverse(edge[20].wrap)")
    assert [float(x) for x in out.getvalue().split()] == [1, 0, 95, 4127]


SCRIPT = ("v\nlist edges where id < 8\ng 5\nr\ng 3\nv\n"
          "list vertices where id > 115\nprint total_energy\n")


def test_as_the_evolver(evolver):
    """Volumes, wrap codes in `list edges`, `g`, `r`: REF's lines."""
    ref = run_reference(evolver, SYMTEST, SCRIPT)
    rc, out, err = run_pyevolver(SYMTEST, SCRIPT)
    assert rc == 0, err
    keep = [l for l in ref if not l.startswith(("Element memory", "Total data memory"))]
    assert _same(out, keep, 1e-10), "\n".join(out)


def test_dumps_both_ways(evolver, tmp_path):
    """REF's dump after `g 3` (``wrap`` codes, SYMMETRY_GROUP) loads in
    pyevolver with REF's numbers, and pyevolver's dump in REF."""
    check = "v\ng 3\nprint total_energy\n"
    ref_dump = tmp_path / "ref.dmp"
    run_reference(evolver, SYMTEST, f'g 3\ndump "{ref_dump}"\n')
    ours_dump = tmp_path / "ours.dmp"
    rc, _, err = run_pyevolver(SYMTEST, f'g 3\ndump "{ours_dump}"\n')
    assert rc == 0, err
    assert 'SYMMETRY_GROUP "torus"' in ours_dump.read_text()
    assert "wrap 1984" in ours_dump.read_text()
    for dump in (ref_dump, ours_dump):
        ref = run_reference(evolver, str(dump), check)
        rc, out, err = run_pyevolver(str(dump), check)
        assert rc == 0, err
        assert _same(out, ref, 1e-10), (dump.name, out, ref)


def test_face_centres_spokes_wrap():
    """A face of more than three edges gets its centre in the unwrapped rim
    and spokes wrapped to it (the centres of symtest.fe are twointor's)."""
    s = pyevolver.load(SYMTEST).surface
    D = s.X[s.E[:, 1]] - s.X[s.E[:, 0]] + s.wrap_shift()
    L = np.linalg.norm(D, axis=1)
    assert np.allclose(np.sort(np.unique(L.round(12))), [0.25, np.sqrt(2) / 4])
    assert os.path.basename(SYMTEST) == "symtest.fe"


SYMTORUS = os.path.join(os.path.dirname(__file__), "..", "data", "symtorus.fe")


@pytest.mark.parametrize("script", [
    "v\ng 5\nv\nr\ng 5\nv\nlist edges where id < 12\n",
    "r\ng 5\nt 0.12\ng 3\nw 0.004\ng 3\nK 0.3\ng 3\nV\nu\ng 3\nv\n",
])
def test_sheared_cell_with_a_fixed_volume_as_the_evolver(evolver, script):
    """A hand-written wavy sheet in a sheared cell (PERIODS with the group),
    its body volume fixed: the Euclidean volume's gradient drives the
    pressure, as REF."""
    ref = run_reference(evolver, SYMTORUS, script)
    rc, out, err = run_pyevolver(SYMTORUS, script)
    assert rc == 0, err
    keep = lambda lines: [l for l in lines if l.strip() and not l.startswith(
        ("Element memory", "Total data memory"))]
    assert _same(keep(out), keep(ref), 1e-9), "\n".join(keep(out))


def test_volume_gradient_against_differences():
    from pyevolver.evolve.gradient import body_volume_gradients
    s = pyevolver.load(SYMTORUS).surface
    g = body_volume_gradients(s.evaluate())[0]
    X0 = s.X.copy()
    h = 1e-6
    for v, k in [(0, 2), (4, 0), (8, 1), (6, 2)]:
        s.X = X0.copy()
        s.X[v, k] += h
        up = s.evaluate().volumes[0]
        s.X = X0.copy()
        s.X[v, k] -= h
        down = s.evaluate().volumes[0]
        assert (up - down) / (2 * h) == pytest.approx(g[v, k], abs=1e-8)
    s.X = X0


@pytest.mark.parametrize("code", ["1e300", "nan", "-1e30"])
def test_a_wrap_code_that_is_no_integer_is_a_located_error(code, tmp_path):
    """(found by the datafile fuzzer: a huge code overflowed the code array)"""
    p = tmp_path / "w.fe"
    p.write_text('symmetry_group "torus"\nvertices\n1 0 0 0\n2 0.5 0 0\nedges\n'
                 f"1 1 2 wrap {code}\n")
    with pytest.raises(PyEvolverError, match=r"w.fe:6: edge 1: wrap expects one group element"):
        pyevolver.load(str(p), out=io.StringIO())
