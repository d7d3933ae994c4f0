"""pyevolver.datafile.scan and .located: the scanners around the grammars."""
from pyevolver.datafile.located import _expected
from pyevolver.datafile.scan import (_BAD_NUMBER, _binary_minus_in_parens, _long_numeric,
                                     _lowest_free, _plain_tail, _proc_end, _skip_transforms)


def test_malformed_numbers():
    assert _BAD_NUMBER.search("x = 1.2.3").group(0) == "1.2.3"
    assert _BAD_NUMBER.search("x = 1e").group(0) == "1e"
    assert _BAD_NUMBER.search("x = 1e-3 + 2.5") is None


def test_plain_tail_gives_the_grammar_items():
    assert _plain_tail(" fixed constraint 1 2", 10) == [
        ("kw", "fixed", 12), ("kw", "constraint", 18), 1.0, 2.0]
    assert _plain_tail(" tension 2*x", 0) is None


def test_long_numeric_lines():
    line = " ".join(str(k) for k in range(1, 600))
    assert _long_numeric(line) == ("all", None)
    kind, head = _long_numeric(line + " fixed")
    assert kind == "head" and head.end() == len(line)
    assert _long_numeric(line + " +3") == (None, None)       # '+3' after a space: addition
    assert _long_numeric("1e308 2 3") == (None, None)        # the id must be digits


def test_minus_after_a_space_inside_parentheses_is_a_subtraction():
    assert _binary_minus_in_parens("1 (2 -3) 4") == "1 (2\x1a-3) 4"
    assert _binary_minus_in_parens("atan2(y, -x)") == "atan2(y, -x)"
    assert _binary_minus_in_parens("1 -2") == "1 -2"


def test_procedure_ends():
    text = 'procedure p() { print "}"; };rest'
    k = text.index("(")
    assert text[:_proc_end(text, k)] == 'procedure p() { print "}"; }'
    assert _proc_end("procedure q();x", len("procedure q")) == len("procedure q();")
    assert _proc_end("procedure r( { ", len("procedure r")) is None


def test_view_transforms_are_skipped():
    # 2 transforms in 2D space: (2+1)^2 numbers each, the second after a colour
    data = " 2 " + " 1" * 9 + " color red" + " 0" * 9 + " tail"
    assert data[_skip_transforms(data, 0, 2):] == " tail"


def test_lowest_free_number():
    assert _lowest_free({1: "a", 3: "c"}, {2: "b"}) == 4
    assert _lowest_free({}, {}, also=1) == 2


def test_expected_terminals_are_worded():
    assert _expected({"NUMBER", "LPAR", "__ANON_1"}) == "'(', a number"
    assert _expected(set()) == "something else"


def test_first_word_as_the_regex():
    # the array search of a long line's first word finds what _FIRST_WORD finds
    from pyevolver.datafile.scan import _FIRST_WORD, _first_word
    for line in ["1 2 3", "1 2e5 3 volume 2", "e5 1", "1 .e2", "1 2 _x", "1 2d3 D3",
                 "7 1.5E3 fixed", "1 2 3 é", "", "1 2 x3"]:
        a, b = _FIRST_WORD.search(line), _first_word(line)
        assert (a and a.start()) == (b and b.start()), line
