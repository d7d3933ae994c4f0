"""The interactive REPL, driven through a pseudo-terminal (pexpect):
multi-line input with the ``more> `` prompt, Tab completion, history kept
across runs, and Ctrl-C during a long loop."""
import os
import signal
import sys
import time

import pytest

from conftest import example

pexpect = pytest.importorskip("pexpect")
pytest.importorskip("prompt_toolkit")

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.dirname(__file__)), ".."))


def _spawn(tmp_path):
    env = dict(os.environ)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    env["PYEVOLVER_HISTORY"] = str(tmp_path / "history")
    env["TERM"] = "xterm"
    env["PROMPT_TOOLKIT_NO_CPR"] = "1"
    # preexec_fn: Ctrl-C reaches the child even when this process inherited
    # SIGINT as ignored (a background job of a shell without job control)
    child = pexpect.spawn(sys.executable, ["-m", "pyevolver", example("cube.fe")], env=env,
                          cwd=str(tmp_path), encoding="utf-8", timeout=30,
                          dimensions=(40, 200),
                          preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
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


def test_ctrl_c_in_g_returns_within_one_iteration(tmp_path):
    """``g 100000`` and Ctrl-C: the prompt returns after at most the
    iteration in progress, and the surface is that of the last complete
    iteration (its energy is the last one printed, and recalc agrees)."""
    import re
    child = _spawn(tmp_path)
    child.sendline("r; r")
    child.expect_exact("Enter command:")
    child.sendline("g 100000")
    stamps = []
    energy = None
    for _ in range(6):
        child.expect(r"\d+\. area: +\S+ energy: +(\S+)")
        stamps.append(time.monotonic())
        energy = child.match.group(1)
    per_iteration = (stamps[-1] - stamps[0]) / 5
    t0 = time.monotonic()
    child.sendintr()
    child.expect_exact("stopped after a complete iteration")
    latency = time.monotonic() - t0
    later = re.findall(r"energy: +(\S+)", child.before)
    if later:
        energy = later[-1]
    child.expect_exact("Enter command:")
    assert latency < 2.0 + 2 * per_iteration, (latency, per_iteration)
    child.sendline('printf "E=%.15g\\n", total_energy')
    child.expect(r"E=(\S+)\r\n")
    assert float(child.match.group(1)) == pytest.approx(float(energy), rel=1e-14)
    child.expect_exact("Enter command:")
    child.sendline('recalc; printf "R=%.15g V=%d\\n", total_energy, vertex_count')
    child.expect(r"R=(\S+) V=(\d+)\r\n")
    assert float(child.match.group(1)) == pytest.approx(float(energy), rel=1e-14)
    assert int(child.match.group(2)) == 194         # the cube (14 vertices) refined twice
    child.expect_exact("Enter command:")
    _quit(child)


def test_completion_of_variables_quantities_attributes(tmp_path):
    """Tab completes a variable, a defined attribute and built-in attributes
    at the terminal; !! repeats the last command (echoed, as REF does)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    env["PYEVOLVER_HISTORY"] = str(tmp_path / "history")
    env["TERM"] = "xterm"
    env["PROMPT_TOOLKIT_NO_CPR"] = "1"
    child = pexpect.spawn(sys.executable, ["-m", "pyevolver", example("qmound.fe")], env=env,
                          cwd=str(tmp_path), encoding="utf-8", timeout=30,
                          dimensions=(40, 200))
    child.expect_exact("Enter command:")
    child.sendline("zebra_width := 0.25")
    child.expect_exact("Enter command:")
    child.sendline("define vertex attribute wobble_amount real")
    child.expect_exact("Enter command:")
    def typed(*parts):
        # each Tab completes before the next keys arrive
        for p in parts:
            child.send(p)
            time.sleep(0.3)
        child.send("\r")
    typed("print zebra_w\t", " * 4")                  # a variable
    child.expect(r"\s1\r\n")
    child.expect_exact("Enter command:")
    typed("print vol.targ\t")                        # a quantity's attribute
    child.expect(r"\s1\r\n")
    child.expect_exact("Enter command:")
    typed("print vertex[3].wobble_am\t", " + vertex[3].vertex_norm\t", "[3]")  # attributes
    child.expect(r"\s(-?[\d.e-]+)\r\n")
    child.expect_exact("Enter command:")
    child.sendline("!!")
    child.expect_exact("print vertex[3].wobble_amount + vertex[3].vertex_normal[3]")
    child.expect_exact("Enter command:")
    _quit(child)


def test_completer_offers_session_names():
    """The completer's candidates: commands, variables, quantities, defined
    attributes, toggles and keywords of the loaded session."""
    import io
    from prompt_toolkit.document import Document
    from pyevolver import Session
    from pyevolver.cli.main import _completer
    s = Session.load(example("qmound.fe"), out=io.StringIO(), err=io.StringIO())
    s.run("my_var := 3\ndefine edge attribute my_attr real\nmy_cmd := { print 1 }")
    comp = _completer(s)

    def words(text):
        return {c.text for c in comp.get_completions(Document(text), None)}
    assert words("print my_") == {"my_var", "my_attr", "my_cmd"}
    assert "vol" in words("print vo")                   # the quantity
    assert "conj_grad" in words("conj_")                # a toggle
    assert "vertex_normal" in words("print vertex[1].vertex_n")
    assert words("foreac") == {"foreach"}
