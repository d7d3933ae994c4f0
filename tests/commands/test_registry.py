"""The command registry (pyevolver.commands.registry) and the command
families registered in it, run through a Session on cube.fe."""
import inspect
import io
import os
import re

import pytest

from pyevolver.commands import interpreter as I
from pyevolver.commands import (constraints, element_attrs, elements, files, fixing, listing,
                                registry, remesh, variables)
from pyevolver.session.core import Session

HERE = os.path.dirname(os.path.dirname(__file__))
ROOT = os.path.dirname(HERE)
CUBE = os.path.join(ROOT, "datafiles", "cube.fe")
GRAMMAR = os.path.join(ROOT, "pyevolver", "commands", "commands.lark")

# grammar terminals that are command keywords (the others are the language:
# if, while, procedure, define, local, ...)
COMMAND_TERMINALS = ("LIST", "SET", "UNSET", "REFINE", "EDGESWAP", "DELETE", "READ", "DUMP",
                     "LOAD_CMD", "ABORT", "FIX", "UNFIX", "HISTOGRAM", "PRINT", "PRINTF",
                     "ERRPRINTF")


def _session():
    return Session.load(CUBE, out=io.StringIO(), err=io.StringIO())


def _terminal_words(name):
    text = open(GRAMMAR).read()
    m = re.search(rf"^{name}(?:\.\d+)?: /\(?([^/)]*)\)?\\b/i", text, re.M)
    assert m, name
    return m.group(1).split("|")


def test_every_command_keyword_of_the_grammar_is_registered():
    words = registry.words()
    for term in COMMAND_TERMINALS:
        for w in _terminal_words(term):
            assert w in words, (term, w)
    # the statements the parser makes for commands all have a handler
    for tag in ("list", "set", "unset", "refine", "edgeswap", "delete", "read", "dump", "load",
                "abort", "fix", "fix_name", "histogram", "print", "printf", "define_attr",
                "define_constraint", "unsupported"):
        assert callable(registry.statement(tag).handler), tag


def test_every_registered_name_has_a_handler():
    assert registry.COMMANDS and registry.STATEMENTS
    for key, cmd in list(registry.COMMANDS.items()) + list(registry.STATEMENTS.items()):
        assert callable(cmd.handler), key
        assert cmd.names and cmd.family, key
    for word in ("g", "r", "u", "V", "O", "j", "t", "w", "l", "K", "n", "v", "q", "U", "G",
                 "m", "recalc", "bfgs", "newton", "hessian", "hessian_seek", "quiet",
                 "conj_grad", "export", "snapshot", "plot_history", "history", "show_vol",
                 "edgeweed", "areaweed", "equiangulate", "rawv", "optimize"):
        assert registry.lookup(word) is not None, word


def test_lookup_letters_exact_words_any_case():
    assert registry.lookup("g").family == "evolution"
    assert registry.lookup("G").name == "G"
    assert registry.lookup("g12") is registry.lookup("g")
    assert registry.lookup("G12") is None
    assert registry.lookup("QUIET") is registry.lookup("quiet")
    assert registry.lookup("R") is None                       # r is a letter: exact case
    assert registry.lookup("history", arg=object()) is None   # takes no argument
    assert registry.lookup("jiggle").family == "toggles"      # a toggle before 'not yet'


def test_duplicate_registration_in_another_family_is_refused():
    with pytest.raises(ValueError):
        registry.register("recalc", family="elsewhere")(lambda interp, raw, arg: None)


def test_interpreter_has_no_command_word_chain():
    src = inspect.getsource(I.Interpreter._x_bare)
    assert "==" not in src and " in (" not in src
    assert len(open(I.__file__).read().splitlines()) <= 800


def test_remesh_commands_change_the_surface():
    s = _session()
    remesh.refine(s)
    assert s.surface.nv == 50
    assert remesh.equiangulate(s) == 0
    s.run("r")
    assert s.surface.nv > 50
    s2 = _session()
    n = remesh.edge_divide_long(s2, 0.5)
    assert n == s2.counts["refine"] and n > 0
    s3 = _session()
    s3.run("V")
    assert "Vertex averaging done." in s3.out.getvalue()


def test_element_functions():
    s = _session()
    assert elements.count(s, "vertex") == s.surface.nv == 14
    v = elements.element(s, "vertex", 1)
    assert (v.kind, v.i) == ("vertex", 0)
    edges = elements.sub_elements(s, v, "edge")
    assert edges and all(e.kind == "edge" for e in edges)
    assert element_attrs.get_attr(s, v, "x", None) == pytest.approx(s.surface.X[0, 0])
    element_attrs.set_attr(s, v, "x", None, 0.25)
    assert s.surface.X[0, 0] == 0.25
    s.run("define vertex attribute aa real[2]; set vertex aa[1] 3")
    assert s.value("vertex[2].aa[1]") == 3.0


def test_constraints_and_fix():
    s = _session()
    s.run("define constraint cc formula: x = 0.25")
    cid = max(s.surface.constraints)
    assert constraints.constraint_label(s, cid) == "cc"
    s.run("set vertex[1] constraint cc")
    assert s.surface.X[0, 0] == pytest.approx(0.25)
    assert s.value("vertex[1].on_constraint cc") == 1.0
    els = [elements.element(s, "vertex", 2)]
    assert fixing.fix_elements(s, els, True) == 1
    assert s.value("vertex[2].fixed") == 1.0


def test_files_read_and_listing(tmp_path):
    cmd = tmp_path / "a.cmd"
    cmd.write_text("aa := 3\nprint aa * 2\n")
    s = _session()
    files.read_file(s, str(cmd))
    assert s.out.getvalue().endswith("6\n")
    assert "Body" in listing.show_vol(s)
    s.run("list vertex[1]")
    assert "// Id" in s.out.getvalue()


def test_variables():
    s = _session()
    assert variables.internal(s, "vertex_count") == s.surface.nv
    variables.set_variable(s, "aa", 2.0)
    assert s.value("aa") == 2.0
    with pytest.raises(Exception, match="read-only"):
        variables.set_variable(s, "vertex_count", 1.0)


def test_session_repr_and_values():
    s = _session()
    r = repr(s)
    assert "cube.fe" in r and "vertices" in r and "energy 6" in r
    assert s.value("total_energy") == pytest.approx(6.0)
    assert s.count("facet") == s.surface.n_facets


def test_commands_modules_import_no_session_and_run_no_code():
    """No module of pyevolver.commands imports pyevolver.session (layers),
    and none can run code or programs."""
    d = os.path.dirname(I.__file__)
    for fn in os.listdir(d):
        if not fn.endswith(".py"):
            continue
        src = open(os.path.join(d, fn)).read()
        assert not re.search(r"^\s*(from|import) (\.\.|pyevolver\.)session", src, re.M), fn
        for word in ("eval(", "exec(", "subprocess", "os.system", "os.popen", "__import__",
                     "pickle"):
            pattern = r"(?<![\w.])" + re.escape(word) if word[0].isalpha() else re.escape(word)
            assert not re.search(pattern, src), (fn, word)
