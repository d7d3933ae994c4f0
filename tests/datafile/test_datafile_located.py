"""pyevolver.datafile.located: the wording of parse errors (``describe``,
``_expected``), the walk over an expression, and the located errors the
reader raises from them (FILE:LINE:COL, the source line and a caret)."""
from __future__ import annotations

import pytest
from lark.exceptions import UnexpectedCharacters, UnexpectedInput

from pyevolver.datafile.grammar import line_parser, top_parser
from pyevolver.datafile.located import _expected, _LocatedName, _walk, describe
from pyevolver.datafile.reader import read_datafile
from pyevolver.errors import DatafileError
from pyevolver.expr import nodes as N


def parse_error(parser, text, start):
    with pytest.raises(UnexpectedInput) as exc:
        parser().parse(text, start=start)
    return exc.value


def test_describe_unexpected_token_names_what_was_expected():
    text = "define vertex attribute x bar"
    e = parse_error(top_parser, text, "start")
    assert (e.line, e.column) == (1, 27)
    assert describe(e, text) == "unexpected 'bar': expected attr_type"
    text = "2 2 ) 3"
    msg = describe(parse_error(line_parser, text, "edge_line"), text)
    assert msg.startswith("unexpected ')': expected ") and "'('" in msg and "'-'" in msg


def test_describe_end_of_line_and_bad_characters():
    text = "parameter a = "
    msg = describe(parse_error(top_parser, text, "start"), text)
    assert msg.startswith("unexpected end of line: expected ") and "a number" in msg
    text = "parameter a = 1 $"
    e = parse_error(top_parser, text, "start")
    assert isinstance(e, UnexpectedCharacters) and e.column == 17
    assert describe(e, text) == "unexpected character '$'"
    # a word the lexer cannot take here is named as a word
    text = "x = foo"
    e = UnexpectedCharacters(text, 4, 1, 5)
    assert describe(e, text) == ("unexpected 'foo': not a keyword, parameter or value "
                                 "allowed here")
    # anything else: the first line of its message
    assert describe(ValueError("first\nsecond"), "") == "first"


def test_expected_lists_are_readable_and_short():
    assert _expected({"NUMBER", "LPAR", "__ANON_0", "LIST_NEG"}) == "'(', a number"
    assert _expected({"__ANON_1"}) == "something else"
    many = {f"K{k}_KW" for k in range(9)}
    out = _expected(many).split(", ")
    assert len(out) == 7 and out[-1] == "..." and out[0] == "k0"


def test_walk_visits_every_node():
    x, y, two = N.Var("x"), N.Var("y"), N.Num(2.0)
    e = N.Bin("+", N.Bin("*", two, x), y)
    nodes = list(_walk(e))
    assert nodes[0] is e and len(nodes) == 5
    assert {id(n) for n in nodes} >= {id(x), id(y), id(two)}
    assert [n.name for n in nodes if isinstance(n, N.Var)] == ["x", "y"]


def test_located_name_carries_its_place():
    exc = _LocatedName("qq", 3, 7)
    assert (exc.name, exc.line, exc.col, str(exc)) == ("qq", 3, 7, "qq")


@pytest.mark.parametrize("text, line, col, words", [
    ("parameter a = 1\nfoo bar\nvertices\n1 0 0 0\n", 2, 1, "unexpected 'foo'"),
    ("vertices\n1 0 0 0\n2 1 0 0\nedges\n1 1 2\n2 2 ) 1\n", 6, 5, "in edge line"),
    ("parameter a = 1 $\nvertices\n1 0 0 0\n", 1, 17, "unexpected character '$'"),
])
def test_reader_errors_point_at_the_line_and_column(tmp_path, text, line, col, words):
    path = tmp_path / "bad.fe"
    path.write_text(text)
    with pytest.raises(DatafileError) as exc:
        read_datafile(str(path))
    e = exc.value
    assert words in e.message and (e.line, e.column) == (line, col)
    src = text.split("\n")[line - 1]
    head, excerpt, caret = str(e).split("\n")
    assert head.startswith(f"{path}:{line}:{col}: ")
    # the source line, and a caret under the column
    assert excerpt == "    " + src
    assert caret == "    " + " " * (col - 1) + "^"


def test_missing_file_is_a_datafile_error(tmp_path):
    path = str(tmp_path / "none.fe")
    with pytest.raises(DatafileError) as exc:
        read_datafile(path)
    assert exc.value.filename == path and "cannot read datafile" in exc.value.message
