"""pyevolver.studies.meshes: closed triangle meshes and the datafile writer."""
import numpy as np
import pytest

from pyevolver.datafile.reader import read_datafile
from pyevolver.studies.meshes import (edges, fe_text, icosahedron, icosphere, torus_grid,
                                      torus_offset, write_fe)


def _closed(F):
    """Every edge in exactly two triangles, traversed once each way."""
    E, idx = edges(F)
    tail, head = F.ravel(), np.roll(F, -1, axis=1).ravel()
    counts = np.bincount(idx.ravel(), minlength=len(E))
    forward = np.bincount(idx.ravel()[tail < head], minlength=len(E))
    return bool(np.all(counts == 2) and np.all(forward == 1))


def _volume(X, F):
    a, b, c = X[F[:, 0]], X[F[:, 1]], X[F[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


@pytest.mark.parametrize("level", [0, 1, 2])
def test_icosphere_counts_closedness_and_orientation(level):
    X, F = icosphere(level)
    E, _ = edges(F)
    assert len(X) == 10 * 4 ** level + 2 and len(F) == 20 * 4 ** level
    assert len(X) - len(E) + len(F) == 2                    # genus 0
    assert _closed(F) and _volume(X, F) > 0
    assert np.allclose(np.linalg.norm(X, axis=1), 1.0)


def test_icosahedron_is_regular():
    X, F = icosahedron()
    E, _ = edges(F)
    lengths = np.linalg.norm(X[E[:, 0]] - X[E[:, 1]], axis=1)
    assert len(E) == 30 and np.allclose(lengths, lengths[0])
    assert np.all(np.bincount(E.ravel()) == 5)


@pytest.mark.parametrize("make, m, n", [(torus_grid, 5, 9), (torus_offset, 6, 10)])
def test_tori_have_euler_characteristic_zero_and_valence_six(make, m, n):
    X, F = make(m, n, R=2.0, r=0.5)
    E, _ = edges(F)
    assert len(X) == m * n and len(F) == 2 * m * n
    assert len(X) - len(E) + len(F) == 0
    assert np.all(np.bincount(E.ravel()) == 6)
    assert _closed(F) and _volume(X, F) > 0


def test_bad_torus_sizes_are_refused():
    with pytest.raises(ValueError):
        torus_grid(2, 9)
    with pytest.raises(ValueError):
        torus_offset(5, 9)                                    # odd row count


def test_edges_give_each_facet_side():
    F = np.array([[0, 1, 2], [0, 2, 3]])
    E, idx = edges(F)
    assert E.tolist() == [[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]]
    assert np.all(np.sort(E[idx].reshape(-1, 2), axis=1)
                  == np.sort(np.stack([F, np.roll(F, -1, axis=1)], -1).reshape(-1, 2), axis=1))


def test_fe_text_reads_back(tmp_path):
    X, F = icosphere(1)
    text = fe_text(X, F, header="// header", face_attrs="tension 0")
    assert text.startswith("// header\n\nvertices\n")
    path = write_fe(str(tmp_path / "s.fe"), X, F)
    scene = read_datafile(path)
    assert len(scene.vertices.ids) == len(X) and len(scene.faces.ids) == len(F)
    assert np.allclose(np.asarray(scene.vertices.data, float), X)
