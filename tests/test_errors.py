"""pyevolver.errors: every refusal names the docs page (once), and
"did you mean" suggestions for unknown words."""
import io
import os

import pytest

from pyevolver import Session
from pyevolver.errors import (DOCS_PAGE, CommandError, DatafileError, UnsupportedError,
                              did_you_mean)

CUBE = os.path.join(os.path.dirname(__file__), "..", "datafiles", "cube.fe")


def test_did_you_mean():
    assert did_you_mean("refin", ["refine", "r", "g"]) == "; did you mean 'refine'?"
    two = did_you_mean("hessian_seak", ["hessian_seek", "hessian_menu", "hessian"])
    assert two == "; did you mean 'hessian_seek' or 'hessian_menu'?"
    assert did_you_mean("zzz", ["refine", "g"]) == ""
    assert did_you_mean("Gravity_Constnt", ["gravity_constant"]) == \
        "; did you mean 'gravity_constant'?"
    assert did_you_mean("same", ["same"]) == ""


def test_refusals_name_the_docs_page_once():
    e = UnsupportedError("wulff", "no crystalline integrands")
    assert str(e) == f"not supported in pyevolver: wulff (no crystalline integrands); " \
                     f"see {DOCS_PAGE}"
    assert str(CommandError(str(e))).count(DOCS_PAGE) == 1
    d = DatafileError("not supported in pyevolver: WULFF", "a.fe", 3, 1, "wulff 'x'")
    assert d.format().splitlines()[0] == f"a.fe:3:1: not supported in pyevolver: WULFF; " \
                                         f"see {DOCS_PAGE}"
    assert DOCS_PAGE not in str(CommandError("unknown command 'x'"))


@pytest.mark.parametrize("cmd, hint", [
    ("refin", "did you mean 'refine'?"),
    ("print total_energi", "did you mean 'total_energy'"),
    ("print vertex[1].fixd", "did you mean 'fixed'?"),
    ("print facet[1].aera", "did you mean 'area'?"),
])
def test_unknown_commands_names_and_attributes_get_a_suggestion(cmd, hint):
    s = Session.load(CUBE, out=io.StringIO(), err=io.StringIO())
    with pytest.raises(Exception) as exc:
        s.run(cmd)
    assert hint in str(exc.value)


def test_unknown_datafile_keywords_get_a_suggestion(tmp_path):
    for text, hint in [("gravity_constnt 2\n", "did you mean 'gravity_constant'?"),
                       ("STRIN\n", "did you mean 'string'?")]:
        p = tmp_path / "k.fe"
        p.write_text(text + "vertices\n1 0 0 0\n2 1 0 0\nedges\n1 1 2\n")
        with pytest.raises(DatafileError) as exc:
            Session.load(str(p), out=io.StringIO())
        assert hint in str(exc.value) and str(exc.value).startswith(f"{p}:1:1:")
    p = tmp_path / "v.fe"
    p.write_text("vertices\n1 0 0 0 fixd\n2 1 0 0\nedges\n1 1 2\n")
    with pytest.raises(DatafileError, match="undefined parameter 'fixd'; did you mean 'fixed'"):
        Session.load(str(p), out=io.StringIO())


def test_no_internal_vocabulary_in_messages():
    """No string literal a user can see (docstrings and comments aside)
    speaks of the project's work items ("the evolve issue", "issue 23")."""
    import re
    import tokenize
    root = os.path.join(os.path.dirname(__file__), "..", "pyevolver")
    bad = []
    skip = (tokenize.INDENT, tokenize.NEWLINE, tokenize.NL, tokenize.ENCODING, tokenize.DEDENT)
    for folder, _, files in os.walk(root):
        for name in files:
            if not name.endswith(".py"):
                continue
            path = os.path.join(folder, name)
            with open(path, "rb") as fh:
                toks = list(tokenize.tokenize(fh.readline))
            for i, t in enumerate(toks):
                if t.type != tokenize.STRING or not re.search(r"\bissues?\b", t.string, re.I):
                    continue
                if toks[i - 1].type in skip and toks[i + 1].type == tokenize.NEWLINE:
                    continue                                  # a docstring
                bad.append(f"{os.path.relpath(path, root)}:{t.start[0]}: {t.string[:60]}")
    assert not bad, bad
