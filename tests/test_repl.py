"""The interactive REPL, driven through a pseudo-terminal (pexpect):
multi-line input with the ``more> `` prompt, Tab completion, history kept
across runs, and Ctrl-C during a long loop."""
import os
import sys

import pytest

from conftest import example

pexpect = pytest.importorskip("pexpect")
pytest.importorskip("prompt_toolkit")

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def _spawn(tmp_path):
    env = dict(os.environ)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    env["PYEVOLVER_HISTORY"] = str(tmp_path / "history")
    env["TERM"] = "xterm"
    env["PROMPT_TOOLKIT_NO_CPR"] = "1"
    child = pexpect.spawn(sys.executable, ["-m", "pyevolver", example("cube.fe")], env=env,
                          cwd=str(tmp_path), encoding="utf-8", timeout=30,
                          dimensions=(40, 200))
    child.expect_exact("Enter command:")
    return child


def _quit(child):
    child.sendline("q")
    child.expect(pexpect.EOF)
    child.close()
    assert child.exitstatus == 0


def test_multiline_completion_history(tmp_path):
    child = _spawn(tmp_path)
    child.sendline("showme_long := {")
    child.expect_exact("more>")
    child.sendline('printf "value %g\\n", 6*7 }')
    child.expect_exact("Enter command:")
    child.send("showme_l\t")                 # Tab completes the user command
    child.sendline("")
    child.expect_exact("value 42")
    child.expect_exact("Enter command:")
    _quit(child)
    with open(tmp_path / "history") as fh:
        assert "showme_long" in fh.read()
    # a new run recalls the last command with the Up arrow
    child = _spawn(tmp_path)
    child.sendline("showme_long := { print 5 }")
    child.expect_exact("Enter command:")
    child.send("\x1b[A\x1b[A\x1b[A")          # back past this run's line and run 1's "q"
    child.sendline("")                       # to run 1's "showme_long"
    child.expect(r"\s5\r\n")
    child.expect_exact("Enter command:")
    child.send("xyz\x03")                    # Ctrl-C at the prompt drops the line
    child.expect_exact("Enter command:")
    _quit(child)


def test_ctrl_c_in_long_loop_keeps_surface(tmp_path):
    child = _spawn(tmp_path)
    child.sendline("print vertex[2].x")
    child.expect(r"\s1\r\n")
    child.expect_exact("Enter command:")
    child.sendline("while 1 do { vertex[2].x := vertex[2].x + 1 }")
    import time
    time.sleep(1.5)
    child.sendintr()
    child.expect_exact("Interrupted")
    child.expect_exact("Enter command:")
    child.sendline("print vertex[2].x")
    child.expect(r"\s1\r\n")                 # as before the interrupted command
    child.expect_exact("Enter command:")
    child.sendline("g 100000")
    time.sleep(2)
    child.sendintr()
    child.expect_exact("stopped after a complete iteration")
    child.expect_exact("Enter command:")
    child.sendline('printf "E=%.6f\\n", total_energy')
    child.expect(r"E=(\d\.\d+)")
    assert float(child.match.group(1)) < 6.0     # the iterations done are kept
    _quit(child)
