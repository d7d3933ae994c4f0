"""The command line in batch mode: ``--timeout`` stops a runaway command,
Ctrl-C (SIGINT) exits with status 130 and leaves no half-written file."""
import os
import signal
import subprocess
import sys
import time

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.dirname(__file__)), ".."))
CUBE = os.path.join(ROOT, "datafiles", "cube.fe")


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _sigint_default():
    # the child reacts to SIGINT even when this test process inherited it as
    # ignored (a background job started by a shell without job control)
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _run(args, script, cwd, timeout=60):
    return subprocess.run([sys.executable, "-m", "pyevolver", *args], input=script,
                          capture_output=True, text=True, cwd=cwd, env=_env(),
                          timeout=timeout)


def test_timeout_stops_a_runaway_command(tmp_path):
    # (the limit covers loading too: 2 s leaves room for the parsers' first use)
    script = ("aa := 1\nwhile 1 do aa := aa + 1\nprint aa\n"
              "g 100000000\nprintf \"E=%.10g\\n\", total_energy\nq\n")
    t0 = time.monotonic()
    p = _run(["--timeout", "2", CUBE], script, tmp_path)
    assert time.monotonic() - t0 < 30
    assert p.returncode == 0, p.stderr
    assert "Traceback" not in p.stderr
    msgs = [l for l in p.stderr.splitlines() if "time limit" in l]
    assert len(msgs) == 2 and all(l.startswith("<stdin>:") for l in msgs), p.stderr
    # the stopped commands left everything as before them: aa is 1, the
    # cube's energy its area 6
    assert p.stdout.split()[0] == "1"
    assert "E=6\n" in p.stdout


def test_timeout_needs_a_positive_number(tmp_path):
    for bad in ("0", "-1", "abc", "inf"):
        p = _run(["--timeout", bad, CUBE], "q\n", tmp_path)
        assert p.returncode == 2 and "timeout" in p.stderr and "Traceback" not in p.stderr


def _interrupt_after(proc, tmp_path, ready, seconds=60):
    t0 = time.monotonic()
    while not ready():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < seconds, "the command never started"
        time.sleep(0.05)
    time.sleep(0.3)
    proc.send_signal(signal.SIGINT)
    return proc.communicate(timeout=60)


@pytest.mark.parametrize("command", ["{ g 100000 } >>> \"out.txt\"",
                                     "{ while 1 do print 1 } >> \"out.txt\""])
def test_sigint_in_batch_mode_exits_130_writing_nothing(tmp_path, command):
    (tmp_path / "go").write_text("")
    script = f'{command}\ndump "after.fe"\nq\n'
    proc = subprocess.Popen([sys.executable, "-m", "pyevolver", CUBE], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=tmp_path, env=_env(), preexec_fn=_sigint_default)
    proc.stdin.write(script)
    proc.stdin.flush()

    def writing():          # the redirection's temporary file (>>>) or the file
        # opened for appending (>>) exists: the body runs
        return any(n.endswith(".tmp") or n == "out.txt" for n in os.listdir(tmp_path))
    out, err = _interrupt_after(proc, tmp_path, writing)
    assert proc.returncode == 130, (out, err)
    assert "Traceback" not in err and "Interrupted" in err
    # nothing partial: no output file, no temporary, no dump after the interrupt
    assert sorted(os.listdir(tmp_path)) == ["go"]


def test_sigint_while_loading_exits_130(tmp_path):
    # a datafile whose read section loops: SIGINT during it is batch mode too
    text = (open(CUBE).read().split("read")[0] +
            "read\nprint 12345\nwhile 1 do { aa := 1 }\n")
    df = tmp_path / "loop.fe"
    df.write_text(text)
    proc = subprocess.Popen([sys.executable, "-u", "-m", "pyevolver", str(df)],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=tmp_path, env=_env(),
                            preexec_fn=_sigint_default)
    assert proc.stdout.readline().split() == ["12345"]      # the loop is about to run
    time.sleep(0.3)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err, err


def test_quit_in_the_read_section(tmp_path):
    # `q` while the datafile's read section runs used to end in a traceback
    text = open(CUBE).read().split("read")[0] + "read\nprint 7\nq 3\nprint 8\n"
    (tmp_path / "quit.fe").write_text(text)
    p = _run(["quit.fe"], "print 9\n", tmp_path)
    assert p.returncode == 3 and p.stdout.split() == ["7"]
    assert "Traceback" not in p.stderr and p.stderr == ""
