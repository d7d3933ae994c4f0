"""docs/datafile-keywords.md is true: every keyword the table lists as
supported or accepted loads with the reference Evolver's numbers, every
refused one is refused by name at its line.

Each row's example is put into ``datafiles/cube.fe`` (read section removed):
``top:`` lines go into the top section, ``vertex 1:`` / ``edge 1:`` /
``face 1:`` / ``body 1:`` text is appended to that element's line.  The
reference numbers come from evolver-nox-d run live on the same file (energy,
area, counts and body volume after loading, then the energies of ``g 2``).
"""
from __future__ import annotations

import io
import os
import re

import pytest

from pyevolver import Session
from pyevolver.errors import PyEvolverError

from reference import run_reference

HERE = os.path.dirname(os.path.dirname(__file__))
TABLE = os.path.join(HERE, "..", "docs", "datafile-keywords.md")
CUBE = os.path.join(HERE, "..", "datafiles", "cube.fe")

_ROW = re.compile(r"^\| `([^`|]+)`[^|]*\| (supported|accepted|refused|loads|random|extension) \| (?:`([^|]*?)`)? *\|")


def _rows():
    rows = []
    with open(TABLE, encoding="utf-8") as fh:
        for line in fh:
            m = _ROW.match(line)
            if m:
                rows.append((m.group(1), m.group(2), m.group(3)))
    return rows


ROWS = _rows()
EXAMPLES = [r for r in ROWS if r[2]]


def test_table_is_complete():
    """The table covers the manual's top-section list (a sample of its names)
    and every row has a status."""
    names = {r[0].split()[0].lower() for r in ROWS}
    for kw in ("parameter", "constraint", "boundary", "quantity", "method_instance",
               "quadratic", "metric", "symmetry_group", "wulff", "phasefile", "pressure",
               "diffusion", "optimizing_parameter", "vertices_predicted", "view_matrix",
               "periods", "keep_originals", "suppress_warning", "zoom_vertex",
               "load_library", "mobility", "hessian_special_normal_vector"):
        assert kw in names, kw
    assert len(EXAMPLES) > 80


def _datafile(example: str) -> str:
    with open(CUBE, encoding="utf-8") as fh:
        text = fh.read()
    text = text[:text.index("\nread")] + "\n"
    top, elems = [], []
    mode = "top"
    for part in example.split("\\n"):
        m = re.match(r"(top|vertex|edge|face|body)(?: (\d+))?([:=]) ?(.*)$", part)
        if m:
            mode = m.group(1)
            if mode == "top":
                top.append(m.group(4))
            else:
                elems.append((mode, int(m.group(2)), m.group(3), m.group(4)))
        elif mode == "top":
            top.append(part)
        else:
            raise AssertionError(f"bad example line {part!r}")
    lines = text.split("\n")
    section = None
    heads = {"vertices": "vertex", "edges": "edge", "faces": "face", "bodies": "body"}
    for k, line in enumerate(lines):
        word = line.split()[0].lower() if line.split() else ""
        if word in heads:
            section = heads[word]
            continue
        for kind, eid, how, tail in elems:
            if section == kind and word == str(eid):
                lines[k] = (line.rstrip() + " " + tail) if how == ":" else f"{eid} {tail}"
    out = "\n".join(lines)
    at = out.index("\nvertices")
    return out[:at] + "\n" + "\n".join(top) + "\n" + out[at:]


_PRINT = ('printf "R %.15g %.15g %d %d %d %d %.15g\\n", total_energy, total_area, '
          'vertex_count, edge_count, facet_count, body_count, body[1].volume\n'
          'g 2\nprintf "G %.15g\\n", total_energy\n')


def _numbers(lines):
    r = [ln for ln in lines if ln.startswith("R ")]
    g = [ln for ln in lines if ln.startswith("G ")]
    assert r and g, "\n".join(lines)
    return [float(v) for v in r[-1].split()[1:]] + [float(g[-1].split()[1])]


def _close(a, b, rtol=1e-9):
    return abs(a - b) <= rtol * max(abs(a), abs(b), 1.0)


@pytest.mark.parametrize("keyword,status,example", EXAMPLES,
                         ids=[f"{r[0]}-{i}" for i, r in enumerate(EXAMPLES)])
def test_keyword(evolver, keyword, status, example, tmp_path):
    path = tmp_path / "kw.fe"
    path.write_text(_datafile(example))
    if status == "refused":
        with pytest.raises(PyEvolverError) as exc:
            Session.load(str(path), out=io.StringIO(), err=io.StringIO())
        msg = str(exc.value)
        word = keyword.split()[0].lower()
        assert "not supported" in msg.lower() and word in msg.lower(), msg
        assert re.search(r"kw\.fe:\d+", msg), msg
        return
    if status == "extension":
        # pyevolver reads it; the reference stops at it with a syntax error
        Session.load(str(path), out=io.StringIO(), err=io.StringIO())
        ref = run_reference(evolver, str(path), _PRINT, cwd=str(tmp_path))
        assert not any(ln.startswith("R ") for ln in ref), ref
        return
    out = io.StringIO()
    s = Session.load(str(path), out=out, err=io.StringIO())
    ref_lines = run_reference(evolver, str(path), _PRINT, cwd=str(tmp_path))
    if status in ("loads", "random"):
        # the load-time numbers are the reference's; g is refused by name
        # ("loads") or runs with random motion that no number can be compared
        # with ("random": jiggling)
        s.run('printf "R %.15g %.15g %d %d %d %d %.15g\\n", total_energy, total_area, '
              'vertex_count, edge_count, facet_count, body_count, body[1].volume')
        got = [float(v) for v in out.getvalue().split("R ")[-1].split()]
        ref = [float(v) for v in [ln for ln in ref_lines if ln.startswith("R ")][0].split()[1:]]
        assert got[2:6] == ref[2:6] and all(_close(a, b) for a, b in zip(got, ref)), (got, ref)
        if status == "random":
            s.run_one("g 2")
            assert "energy:" in out.getvalue()
            return
        with pytest.raises(PyEvolverError, match="not supported"):
            s.run_one("g 2")
        return
    s.run(_PRINT)
    got = _numbers(out.getvalue().splitlines())
    ref = _numbers(ref_lines)
    assert got[2:6] == ref[2:6], (got, ref)
    for a, b in zip(got[:2] + got[6:], ref[:2] + ref[6:]):
        assert _close(a, b), (got, ref)
