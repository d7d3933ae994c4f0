"""Direct tests of pyevolver.commands.parser: statements into tuples, errors
with their location; the statements the Evolver accepts parse, the ones it
rejects do not."""
import os
import subprocess

import pytest

from pyevolver.commands.parser import command_parser, parse_command
from pyevolver.commands.values import Generator, Proc
from pyevolver.errors import CommandError
from pyevolver.expr import nodes as N

from reference import run_reference


def reference_errors(exe, text):
    """The Evolver's messages (stderr) for ``text``."""
    p = subprocess.run([exe, "-p1", CUBE], input=text + "\nq\nq\n", capture_output=True,
                       text=True, timeout=30, errors="replace")
    return p.stderr

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def one(text):
    ast = parse_command(text)
    assert ast[0] == "seq" and len(ast[1]) == 1
    return ast[1][0]


def test_statement_shapes():
    st = one("g 10")
    assert st[:2] == ("bare", "g") and isinstance(st[2], N.Num) and st[2].value == 10
    st = one("if 1 then print 2 else print 3")
    assert st[0] == "if" and st[2][0] == "print" and st[3][0] == "print"
    assert one("if 1 then print 2")[3] is None
    st = one("for (i := 1; i < 3; i++) print i")
    assert st[0] == "for" and st[1][0] == "assign" and st[3][0] == "opassign" \
        and st[4][0] == "print"
    st = one("while i < 3 do i := i + 1")
    assert st[0] == "while" and st[2][0] == "assign"
    st = one("hist := {g; r}")
    assert st[0] == "define" and st[1] == "hist" and [x[1] for x in st[2][1]] == ["g", "r"]
    assert len(parse_command("g 2; r; u")[1]) == 3


def test_procedures_and_generators():
    st = one("procedure pp(real a, integer b) { print a }")
    assert st[0] == "procdef" and isinstance(st[1], Proc)
    assert st[1].name == "pp" and st[1].params == [("real", "a"), ("integer", "b")]
    st = one("foreach vertex vv where vv.x > 0 do print vv.id")
    assert st[0] == "foreach" and isinstance(st[1], Generator)
    assert st[1].kind == "vertex" and st[1].var == "vv" and st[1].where is not None


def test_set_is_disambiguated():
    # `set vertex y y+1` means: attribute y to y+1 (the value gets a leading 0+)
    st = one("set vertex y y+1")
    assert st[0] == "set" and st[2] == "y"
    assert isinstance(st[3], N.Bin) and st[3].op == "+"


def test_syntax_errors_name_the_place():
    with pytest.raises(CommandError, match=r"file.cmd:7:8: syntax error: unexpected end"):
        parse_command("print 1+", where="file.cmd", line=7)
    with pytest.raises(CommandError, match=r"syntax error"):
        parse_command("print )")
    with pytest.raises(CommandError, match="nested more than"):
        parse_command("{" * 300 + "print 1" + "}" * 300)
    assert command_parser() is command_parser()      # built once


GOOD = ["print 1+2*3", "aa := 2; print aa^2", "if 2 > 1 then print 5 else print 6",
        "for (ii := 1; ii <= 2; ii++) print ii", "foreach vertex vv where vv.id < 3 do print vv.id",
        "print sum(facet, area)", 'printf "%g\\n", max(vertex, x)']
BAD = ["print )", "if then print 1", "aa := := 3"]


def test_reference_and_parser_agree(evolver):
    """What the Evolver runs parses; what it calls a syntax error does not."""
    for text in GOOD:
        parse_command(text)
    ref = run_reference(evolver, CUBE, "\n".join(GOOD) + "\n")
    assert [l.strip() for l in ref if l.strip()][:2] == ["7", "4"]
    for text in BAD:
        with pytest.raises(CommandError):
            parse_command(text)
        assert "syntax error" in reference_errors(evolver, text), text
    assert "rror" not in reference_errors(evolver, "\n".join(GOOD))
