"""The datafile's lines kept for error excerpts (pyevolver/datafile/source_lines.py)."""
import pytest

from pyevolver.datafile.source_lines import SourceLines


@pytest.mark.parametrize("text", ["a\nbb\n\nccc", "a\r\nbb\rx\n", "", "\n", "é\nü x\n",
                                  "one line"])
def test_like_the_list_of_lines(text):
    ref = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    lines = SourceLines(text)
    assert len(lines) == len(ref) and bool(lines)
    assert [lines[k] for k in range(len(ref))] == ref
    assert lines[-1] == ref[-1] and lines[0:2] == ref[0:2] and list(lines) == ref
    assert lines == ref
    with pytest.raises(IndexError):
        lines[len(ref)]
