"""Direct tests of pyevolver.commands.refused: commands the Evolver has and
pyevolver refuses by name (the message names the command), never as unknown
words; the surface is left as it was."""
import io
import os

import numpy as np
import pytest

from pyevolver import Session
from pyevolver.commands import registry
from pyevolver.commands.refused import (LETTER_LATER, WORD_LATER, _letter_later,
                                        _word_later, _x_abort, _x_unsupported)
from pyevolver.errors import CommandError, UnsupportedError

from reference import run_reference

CUBE = os.path.join(os.path.dirname(__file__), "..", "..", "datafiles", "cube.fe")


def session():
    return Session.load(CUBE, out=io.StringIO(), err=io.StringIO())


def test_handlers_name_the_command():
    with pytest.raises(UnsupportedError, match=r"command e \(extrapolation\)"):
        _letter_later(None, "e", None)
    with pytest.raises(UnsupportedError, match="command saddle"):
        _word_later(None, "SADDLE", None)
    with pytest.raises(UnsupportedError, match="system.*never run programs"):
        _x_unsupported(None, ("unsupported", "system", "scripts never run programs"))
    with pytest.raises(CommandError, match="aborted"):
        _x_abort(None, ("abort",))


def test_every_refused_word_is_refused_by_name():
    s = session()
    X = s.surface.X.copy()
    e0 = s.total_energy
    checked = 0
    for word in sorted(WORD_LATER) + sorted(LETTER_LATER):
        if registry.COMMANDS[word].handler not in (_word_later, _letter_later):
            continue                  # implemented elsewhere (fix, optimize, ...)
        with pytest.raises(CommandError) as exc:
            s.run(word)
        msg = str(exc.value)
        if word in ("fix", "unfix") and "syntax error" in msg:
            continue                  # bare fix/unfix: a syntax error in the Evolver too
        assert "not supported in pyevolver" in msg and word.lower() in msg.lower(), msg
        checked += 1
    assert checked > 20
    assert np.array_equal(s.surface.X, X) and s.total_energy == e0


def test_the_evolver_has_the_refused_commands(evolver):
    """The refused words are Evolver commands: REF runs them without a syntax error,
    pyevolver refuses them by name."""
    words = ["detorus", "e", "C"]       # (saddle: implemented, commands/eigen.py)
    p = run_reference(evolver, CUBE, "\n".join(words) + "\n")
    assert not any("syntax error" in l.lower() for l in p)
    s = session()
    for w in words:
        with pytest.raises(CommandError, match="not supported in pyevolver"):
            s.run(w)


def test_unsupported_statements_refused_with_reason():
    s = session()
    with pytest.raises(CommandError, match=r"system \(scripts never run programs\)"):
        s.run('system "ls"')
    with pytest.raises(CommandError, match="dissolve"):
        s.run("dissolve vertex[1]")
    with pytest.raises(CommandError, match="Command aborted"):
        s.run("aa := 1; abort")
    assert "aa" not in s.variables
