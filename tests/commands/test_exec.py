"""``exec stringexpr`` (REF manual, commands.htm#exec): the string is parsed
and run as commands at run time, in the global scope.  Compared with the
Evolver run live; scripts stay data (``system`` inside an exec string is
refused like anywhere else)."""
import os

from comparison import _run_both, _same, run_pyevolver
from conftest import EXAMPLES

CUBE = os.path.join(EXAMPLES, "cube.fe")

SCRIPT = """exec "print 1+2"
exec sprintf "define vertex attribute prop%d real", 3
print vertex[1].prop3
aa := 5
exec "aa := aa*2; print aa"
exec "{print 7; print 8}"
bbb := "print 55"
exec bbb
exec "exec \\"print 66\\""
exec "vertex[1].z := 0.25"; print vertex[1].z
exec "g 1"
exec "fudge := 1.5"
print fudge * 2
exec ""
"""


def test_exec_runs_strings_like_the_evolver(evolver, tmp_path):
    _, ref, out, err = _run_both(evolver, CUBE, SCRIPT, tmp_path)
    assert _same(out, ref), (out, ref, err)
    assert "error" not in err.lower(), err


def test_exec_hides_locals_and_names_its_string(evolver, tmp_path):
    """REF: inside a procedure, ``exec "print xx"`` does not see parameter
    ``xx`` (a syntax error there, an undefined name here), and the error
    stops the command; ``exec 5`` is refused."""
    script = ('procedure pp(real xx) { exec "print 11"; exec "print xx"; print 99 }\n'
              'pp(4)\nexec 5\nprint 42\n')
    _, ref, out, err = _run_both(evolver, CUBE, script, tmp_path)
    assert [ln.strip() for ln in ref if ln.strip() in ("11", "99", "42")] == ["11", "42"]
    assert [ln.strip() for ln in out if ln.strip()] == ["11", "42"]
    assert 'exec "print xx"' in err and "xx" in err
    assert "exec needs a quoted string" in err


def test_exec_cannot_reach_a_program(tmp_path):
    sentinel = tmp_path / "pwned"
    code, out, err = run_pyevolver(CUBE, f'exec "system \\"touch {sentinel}\\""\nq\n',
                                   cwd=str(tmp_path))
    assert not sentinel.exists()
    assert "system" in err and "not supported" in err, err
