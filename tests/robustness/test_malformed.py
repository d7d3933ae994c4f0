"""Malformed datafiles must give one located error message, never a traceback.

Each file in tests/malformed/ is cube.fe with exactly one defect; its first
line is a comment naming the defect and its line.  The expected line numbers
below are what a user needs to see, not necessarily what the library reports
today.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from pyevolver.errors import DatafileError, UnsupportedError

REPO = Path(__file__).resolve().parents[2]
MALFORMED = Path("tests") / "malformed"  # relative to REPO, as a user would type it

# file -> line of the defect
EXPECTED_LINE = {
    "truncated.fe": 24,             # '9   1' : edge with no head, file ends
    "unknown_keyword.fe": 5,        # 'frobnicate 3'
    "missing_edge.fe": 30,          # face 1 '1 10 -5 99'
    "open_loop.fe": 30,             # face 1 '1 10 -5 -10'
    "bad_number.fe": 7,             # vertex 2 '1.0.0 0.0 0.0'
    "unterminated_comment.fe": 37,  # the '/*' on the bodies line
    "undefined_parameter.fe": 12,   # vertex 7 'rad 1.0 1.0'
    "unsupported.fe": 5,            # 'LOAD_LIBRARY'
    # resource limits and values that once gave tracebacks (issue 10)
    "deep_nesting.fe": 8,           # sin(sin(... 300 deep
    "huge_id.fe": 9,                # vertex id 10^12
    "macro_bomb.fe": 42,            # #define doubling 39 times
    "missing_value.fe": 38,         # 'density' at the end of the body line
    "absurd_attribute.fe": 2,       # real[1000000000] per vertex
    "infinite_coordinate.fe": 10,   # 1e400
    "function_arity.fe": 2,         # log(2, 3)
}

# file -> list of alternatives groups: every group must have at least one
# alternative present (case-insensitive) in the first line of the message.
EXPECTED_WORDS = {
    "truncated.fe": [("edge",)],
    "unknown_keyword.fe": [("frobnicate",)],
    "missing_edge.fe": [("99",)],
    "open_loop.fe": [("face",), ("loop", "clos")],
    "bad_number.fe": [("1.0.0", "number")],
    "unterminated_comment.fe": [("comment",)],
    "undefined_parameter.fe": [("rad",)],
    "unsupported.fe": [("not supported",), ("load_library",)],
    "deep_nesting.fe": [("nested",), ("200",)],
    "huge_id.fe": [("1000000000000",), ("range",)],
    "macro_bomb.fe": [("#define",), ("100000",)],
    "missing_value.fe": [("density",), ("value",)],
    "absurd_attribute.fe": [("big",), ("1000000000",)],
    "infinite_coordinate.fe": [("finite",)],
    "function_arity.fe": [("log",), ("argument",)],
}

FILES = sorted(EXPECTED_LINE)


def test_every_malformed_file_is_covered():
    on_disk = sorted(p.name for p in (REPO / MALFORMED).glob("*.fe"))
    assert on_disk == FILES
    assert sorted(EXPECTED_WORDS) == FILES


@pytest.mark.parametrize("name", FILES)
def test_header_comment_states_line(name):
    first = (REPO / MALFORMED / name).read_text().splitlines()[0]
    assert first.startswith("//")
    assert f"(line {EXPECTED_LINE[name]})" in first


def _check_words(name, first_line, path):
    # only the message after 'FILE:LINE[:COL]: ' counts (the file name itself
    # contains words such as 'number' or 'edge')
    msg = first_line.split(str(path), 1)[-1]
    low = msg.lower()
    for group in EXPECTED_WORDS[name]:
        assert any(w.lower() in low for w in group), (
            f"{name}: expected one of {group!r} in message: {first_line!r}")


def _location_re(path, line):
    # FILE:LINE: msg   or   FILE:LINE:COL: msg
    return re.compile(rf"^{re.escape(str(path))}:{line}(:\d+)?: \S")


@pytest.mark.parametrize("name", FILES)
def test_cli_reports_one_located_error(name):
    path = MALFORMED / name
    env = dict(os.environ)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    proc = subprocess.run(
        [sys.executable, "-m", "pyevolver", str(path)],
        cwd=REPO, env=env, stdin=subprocess.DEVNULL,
        capture_output=True, text=True, timeout=60,
    )
    out, err = proc.stdout, proc.stderr
    assert "Traceback" not in err, err
    assert "Traceback" not in out, out
    assert proc.returncode == 1, (proc.returncode, out, err)
    lines = err.splitlines()
    assert lines, "nothing on stderr"
    line = EXPECTED_LINE[name]
    assert _location_re(path, line).match(lines[0]), (
        f"first stderr line should start with '{path}:{line}': {lines[0]!r}")
    # exactly one error message: only one line carries a FILE:LINE location
    located = [l for l in lines if l.startswith(f"{path}:")]
    assert len(located) == 1, err
    _check_words(name, lines[0], path)


@pytest.mark.parametrize("name", FILES)
def test_library_raises_located_error(name):
    from pyevolver.datafile.reader import read_datafile
    from pyevolver.model.build import build_surface

    path = str(REPO / MALFORMED / name)
    with pytest.raises((DatafileError, UnsupportedError)) as info:
        build_surface(read_datafile(path))
    exc = info.value
    first = str(exc).splitlines()[0]
    line = EXPECTED_LINE[name]
    if isinstance(exc, DatafileError) or getattr(exc, "line", None) is not None:
        assert exc.line == line, f"{name}: line {exc.line}, expected {line}: {first!r}"
        assert _location_re(path, line).match(first), first
    _check_words(name, first, path)
    if name == "unsupported.fe":
        assert "not supported" in str(exc)
