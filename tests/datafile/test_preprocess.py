"""pyevolver.datafile.preprocess: newlines, comments, macros, sections."""
import pytest

from pyevolver.datafile.preprocess import (Section, _TooLong, blank_comments, expand_macros,
                                           normalise_newlines, preprocess, read_source)
from pyevolver.errors import DatafileError


def test_newlines_and_dos_eof_are_normalised():
    assert normalise_newlines("a\r\nb\rc\n\x1a") == "a\nb\nc\n "


def test_comments_become_spaces_and_keep_positions():
    text = 'x // one\n/* two\nthree */ y "// kept"\n'
    out = blank_comments(text, "f.fe")
    assert len(out) == len(text) and out.count("\n") == text.count("\n")
    assert out.split("\n")[0].rstrip() == "x"
    assert out.split("\n")[2].strip() == 'y "// kept"'


def test_unterminated_comment_is_located():
    with pytest.raises(DatafileError) as exc:
        blank_comments("a\n  /* open\n", "f.fe")
    assert exc.value.line == 2 and exc.value.column == 3


def test_define_expands_whole_tokens_and_rescans():
    macros = {"A": "B + 1", "B": "2", "AB": "never"}
    assert expand_macros("A * AA", macros) == "2 + 1 * AA"
    assert expand_macros('"A" A', macros) == '"A" 2 + 1'


def test_macros_that_double_are_refused():
    with pytest.raises(_TooLong):
        expand_macros("X", {"X": "X X"})


def test_sections_in_order_with_their_first_lines():
    text = ("#define SIDE 2\nparameter s = SIDE\n\nvertices\n1 0 0 SIDE\n"
            "edges\n1 1 1\nread\ng 5\n")
    sections, macros = preprocess(text, "t.fe")
    assert macros == {"SIDE": "2"}
    assert [s.kind for s in sections] == ["top", "vertices", "edges", "read"]
    assert all(isinstance(s, Section) for s in sections)
    assert "parameter s = 2" in sections[0].text
    assert sections[1].line == 4 and "1 0 0 2" in sections[1].text
    assert sections[-1].text.strip() == "g 5" and sections[-1].line == 8


def test_singular_section_names():
    sections, _ = preprocess("vertex\n1 0 0 0\nfacet\n1 1 2 3\nbody\n1 1\n", "t.fe")
    assert [s.kind for s in sections] == ["top", "vertices", "faces", "bodies"]


def test_read_source_takes_any_byte(tmp_path):
    p = tmp_path / "latin.fe"
    p.write_bytes(b"// caf\xe9\nvertices\n")
    assert read_source(str(p)) == "// caf\u00e9\nvertices\n"


def test_comments_and_sections_far_into_a_large_text():
    # the comment scan runs from the first '/' or '"' to the line of the last
    # '/'; the section search looks at lines starting with a letter
    rows = "\n".join(f"{k} {k} 0 0" for k in range(1, 3000))
    text = ("// head\nparameter p = 1 /* c */\nvertices\n" + rows + "\nedges\n1 1 2 // e\n"
            + rows.replace(" 0 0", "") + '\nfaces /* x\n y */\n  BODIES\n1 1 "s//t"\n')
    sections, _ = preprocess(text, "f.fe")
    assert [s.kind for s in sections] == ["top", "vertices", "edges", "faces", "bodies"]
    assert sections[2].text.startswith("\n1 1 2     \n")
    assert not sections[3].text.strip() and sections[4].line == text.count("\n") - 1
    clean = blank_comments(text, "f.fe")
    assert len(clean) == len(text) and "/*" not in clean and '"s//t"' in clean
