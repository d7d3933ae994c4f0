"""Plain numeric element sections read at once (pyevolver/datafile/table.py):
the same scene as the line-by-line reader, which still reads anything else."""
import numpy as np
import pytest

from pyevolver.datafile import table as T
from pyevolver.datafile.reader import read_datafile
from pyevolver.errors import DatafileError

HEAD = "// test\n\nvertices\n"


def _octahedron(n_extra=0):
    """A closed octahedron plus ``n_extra`` unused vertices (a long vertex table)."""
    v = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    lines = [f"{i + 1} {x:.17g} {y:.17g} {z:.17g}" for i, (x, y, z) in enumerate(v)]
    lines += [f"{7 + k}  {0.5 + k * 1e-3:.17g} -{0.25:.17g} 1.5e-3" for k in range(n_extra)]
    edges = [(1, 3), (3, 2), (2, 4), (4, 1), (1, 5), (3, 5), (2, 5), (4, 5),
             (1, 6), (3, 6), (2, 6), (4, 6)]
    faces = [(1, 6, -5), (2, 7, -6), (3, 8, -7), (4, 5, -8),
             (-1, 9, -10), (-2, 10, -11), (-3, 11, -12), (-4, 12, -9)]
    return (HEAD + "\n".join(lines) + "\n\nedges\n" +
            "\n".join(f"{i + 1} {a} {b}" for i, (a, b) in enumerate(edges)) + "\n\nfaces\n" +
            "\n".join(f"{i + 1} {a} {b} {c}" for i, (a, b, c) in enumerate(faces)) +
            "\n\nbodies\n1 " + " ".join(str(i + 1) for i in range(8)) + " volume 1\n")


def _scene(text, fast, monkeypatch, tmp_path):
    monkeypatch.setattr(T, "MIN_CHARS", 0 if fast else 10 ** 12)
    f = tmp_path / "t.fe"
    f.write_text(text)
    return read_datafile(str(f))


def _blocks(sc):
    out = []
    for k in ("vertices", "edges", "faces", "bodies"):
        b = getattr(sc, k)
        data = b.data.tolist() if isinstance(b.data, np.ndarray) else \
            [np.asarray(d).tolist() for d in b.data]
        out.append((np.asarray(b.ids).tolist(), data, list(b.lines), b.attrs))
    return out, sc.warnings


@pytest.mark.parametrize("extra", [0, 300])
def test_same_scene_as_the_line_reader(extra, monkeypatch, tmp_path):
    text = _octahedron(extra)
    fast = _scene(text, True, monkeypatch, tmp_path)
    slow = _scene(text, False, monkeypatch, tmp_path)
    assert _blocks(fast) == _blocks(slow)
    assert isinstance(fast.vertices.data, np.ndarray)
    assert fast.vertices.data.shape == (6 + extra, 3)
    assert list(fast.vertices.lines)[:2] == [4, 5]      # each vertex's source line


@pytest.mark.parametrize("line, taken", [
    ("7 0.5 0.5 0.5", True),
    ("7 0.5 0.5 0.5 fixed", False),        # a word: the line reader
    ("7 0.5 +0.5 0.5", False),             # '+' continues a value (REF's "1 +2" is 3)
    ("7 0.5 0.5", False),                  # a shorter line (padded, warned by the reader)
    ("7.0 0.5 0.5 0.5", False),            # the id must be digits
    ("-7 0.5 0.5 0.5", False),
    ("  7e0 0.5 0.5 0.5", False),
    ("\t 7 0.5 0.5 0.5", True),           # blanks before the id
    ("7 0.5 0.5 0.5 " + " 1" * 3, False),  # another count of numbers
    ("7 0.5 0.5 1e", False),               # not one number
    ("7 0.5.5 0.5 0.5", False),            # malformed number: the reader's message
    ("7 0.5 0.5 0.5\r", False),            # (carriage returns are normalised before)
])
def test_what_the_table_path_takes(line, taken, monkeypatch):
    rows = "\n".join(f"{k} 0.25 -0.5 1.5e-3" for k in range(1, 7)) + "\n" + line + "\n\n"
    monkeypatch.setattr(T, "MIN_CHARS", 0)
    got = T.numeric_table(rows, 1, [], 2000)
    assert (got is not None) == taken
    if taken:
        values, lens, src = got
        assert lens.tolist() == [4] * 7 and src.tolist() == list(range(1, 8))
        assert values[-4:].tolist() == [7, 0.5, 0.5, 0.5]


@pytest.mark.parametrize("old, new, words", [
    ("\n2 -1 0 0\n", "\n2 -1 0.0.0 0\n", "malformed number '0.0.0'"),
    ("\n3 0 1 0\n", "\n0 0 1 0\n", "out of range"),
])
def test_errors_are_the_line_readers(old, new, words, monkeypatch, tmp_path):
    text = _octahedron(0).replace(old, new)
    msgs = []
    for fast in (True, False):
        with pytest.raises(DatafileError) as exc:
            _scene(text, fast, monkeypatch, tmp_path)
        msgs.append(str(exc.value))
    assert msgs[0] == msgs[1] and words in msgs[0]


@pytest.mark.parametrize("text", ["1 2 3", "1 -0 2", " +5 -7\n8 ", "99999999999999999999 1",
                                  "9007199254740993 1", "1 2.5", "1 nan", "", "1 2e3"])
def test_floats_of_reads_as_fromstring(text):
    want = np.fromstring(text, dtype=float, sep=" ")
    got = T.floats_of(text)
    assert got.dtype == want.dtype and np.array_equal(np.signbit(got), np.signbit(want))
    np.testing.assert_array_equal(got, want)
    for bad in ("1 x", "1 5-", "0x10"):
        with pytest.raises(ValueError):
            T.floats_of(bad)
