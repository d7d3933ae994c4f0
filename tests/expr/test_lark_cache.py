"""The grammars' parsers kept on disk (pyevolver.expr.lark_cache): the stored
parser parses and fails exactly as a freshly built one."""
import os
import pickle
import re

import pytest
from lark import Lark
from lark.exceptions import UnexpectedInput

from pyevolver.commands import parser as command_module
from pyevolver.datafile import grammar as datafile_grammar
from pyevolver.expr import lark_cache as LC

COMMANDS = ["g 5; r; g 5; hessian", "gogo := { g 5; r; hessian; }",
            "foreach vertex vv where z > 0 do printf \"%g\\n\", vv.x",
            "set facet tension 2 where id < 3", "print max(vertex, sqrt(x^2+y^2))",
            "if total_energy > 1 then g 2 else { r; u }", "define vertex attribute h real[2]",
            "list edges where length > 0.1", "a := {1, 2, 3}", "x.y.z := 3",
            "print 3 = 1", "procedure p(real a) { print a }", "histogram(edge, length)",
            # errors: located messages come from these
            "print (", "set 3 4", "g 5 ;; ) ", "printf \"%d\" 3 4", "{ g 5", "@"]
TOP = ["parameter a = 3\nconstraint 1\nformula: z = 0\n",
       "quantity q energy method facet_area global\n",
       "define vertex attribute h real\nSTRING\n", "parameter = 3\n", "constraint 1 formula:\n"]


def _grammar_and_options(which):
    if which == "commands":
        with open(os.path.join(command_module._HERE, "commands.lark")) as fh:
            text = command_module.expr_grammar() + "\n" + fh.read()
        return text, dict(parser="lalr", lexer="contextual", start="start",
                          maybe_placeholders=False)
    with open(os.path.join(datafile_grammar._HERE, "fe_top.lark")) as fh:
        text = datafile_grammar.expr_grammar() + "\n" + fh.read()
    return text, dict(parser="lalr", lexer="contextual", start="start", maybe_placeholders=False,
                      lexer_callbacks={"UNSUPPORTED_KW": datafile_grammar._refuse,
                                       "UNSUPPORTED2_KW": datafile_grammar._refuse})


def _outcome(parser, text):
    try:
        return ("tree", parser.parse(text))
    except UnexpectedInput as e:        # (the expected set's order is a set's)
        return ("error", type(e).__name__, e.line, e.column, sorted(str(e).splitlines()),
                sorted(getattr(e, "expected", None) or getattr(e, "allowed", None) or ()))
    except Exception as e:      # a lexer callback's refusal
        return ("raised", type(e).__name__, str(e))


@pytest.mark.parametrize("which,inputs", [("commands", COMMANDS), ("top", TOP)])
def test_stored_parser_parses_and_fails_as_a_fresh_one(tmp_path, monkeypatch, which, inputs):
    monkeypatch.setenv("PYEVOLVER_CACHE_DIR", str(tmp_path))
    grammar, options = _grammar_and_options(which)
    fresh = Lark(grammar, **options)
    built = LC.cached_lark(grammar, **options)          # builds and stores
    files = os.listdir(tmp_path)
    assert len(files) == 1 and files[0].startswith("lark-")
    stored = LC.cached_lark(grammar, **options)          # loads
    assert stored is not built and isinstance(stored, Lark)
    # the scanners are restored when first used
    lexers = set(stored.parser.lexer.lexers.values())
    assert all(type(lx._scanner) is LC._LazyScanner for lx in lexers)
    for text in inputs:
        want = _outcome(fresh, text)
        assert _outcome(built, text) == want, text
        assert _outcome(stored, text) == want, text
    used = [lx for lx in lexers if type(lx._scanner) is not LC._LazyScanner]
    assert 0 < len(used) < len(lexers)


def test_damaged_file_is_rebuilt(tmp_path, monkeypatch):
    monkeypatch.setenv("PYEVOLVER_CACHE_DIR", str(tmp_path))
    grammar = 'start: WORD+\nWORD: /[a-z]+/i\n%ignore " "\n'
    LC.cached_lark(grammar, parser="lalr")
    (path,) = [tmp_path / f for f in os.listdir(tmp_path)]
    path.write_bytes(path.read_bytes()[:100])               # truncated
    p = LC.cached_lark(grammar, parser="lalr")
    assert [str(t) for t in p.parse("ab Cd").children] == ["ab", "Cd"]
    assert pickle.loads(path.read_bytes()).parse("x").children == ["x"]   # stored again


def test_cache_off_and_key(tmp_path, monkeypatch):
    monkeypatch.setenv("PYEVOLVER_CACHE_DIR", "")
    assert LC.cache_dir() is None
    p = LC.cached_lark('start: "a"+\n', parser="lalr")
    assert p.parse("aa").data == "start"
    assert LC.cache_key("g", {"parser": "lalr"}) != LC.cache_key("g ", {"parser": "lalr"})
    assert LC.cache_key("g", {"parser": "lalr"}) != LC.cache_key("g", {"parser": "earley"})
    monkeypatch.delenv("PYEVOLVER_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert LC.cache_dir() == str(tmp_path / "pyevolver")


@pytest.mark.parametrize("pattern,flags", [
    (r"(?P<A>(?i:do\b))|(?P<B>[a-z_][a-z0-9_]*)", 0),
    (r"\/\*(.|\n)*?\*\/|\/\/[^\n]*", 0), (r"(?P<N>\d+\.?\d*(e[+-]?\d+)?)", re.I),
    (r"[^\W\d]+\s*(?=\()", re.M), (r"a{2,5}?b*+c", 0)])
def test_restored_pattern_is_the_compiled_one(pattern, flags):
    p = re.compile(pattern, flags)
    args = LC._program(p)
    q = LC._restore_pattern(*args)
    assert q == p and q.groupindex == p.groupindex and q.groups == p.groups
    for s in ["do", "DO x", "/* c\n */", "12.5e3", "foo (", "aaabbc", "aab"]:
        m, n = p.match(s), q.match(s)
        assert (m and (m.group(0), m.lastgroup)) == (n and (n.group(0), n.lastgroup))
