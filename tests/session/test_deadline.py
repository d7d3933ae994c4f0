"""One time limit over loading and every command (issue 25): the alarm
stops a single long command or a long load; the surface is restored."""
from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from pyevolver.commands.values import TimeLimitExceeded
from pyevolver.errors import CommandError
from pyevolver.session import deadline
from pyevolver.session.core import Session

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")
CUBE = os.path.join(ROOT, "datafiles", "cube.fe")


def _icosphere(tmp_path, level):
    out = tmp_path / f"ico{level}.fe"
    subprocess.run([sys.executable, os.path.join(ROOT, "benchmarks", "make_icosphere.py"),
                    "--level", str(level), "--out", str(out)], check=True,
                   capture_output=True)
    return str(out)


def test_alarm_raises_in_a_single_long_python_call():
    with pytest.raises(deadline.Alarm):
        with deadline.alarm(0.2):
            while True:             # one "command" that never ticks
                pass
    assert signal.getitimer(signal.ITIMER_REAL)[0] == 0      # disarmed


def test_alarm_nested_keeps_the_outer_limit():
    t = time.monotonic()
    with pytest.raises(deadline.Alarm):
        with deadline.alarm(0.3):
            with deadline.alarm(100):
                while True:
                    pass
    assert time.monotonic() - t < 50


def test_single_long_command_is_stopped_and_undone(monkeypatch):
    """A long step inside one command (no interpreter tick in it): the
    alarm stops it; the surface, the g history and the counters are as
    before."""
    import pyevolver.commands.remesh as R
    s = Session.load(CUBE, out=io.StringIO(), err=io.StringIO())
    s.run("g 2")
    X, hist, energy = s.surface.X.copy(), list(s.history), s.total_energy
    counter = s.iteration_counter

    def hang(session, echo=True):
        session.surface.X[:] += 1.0
        session.history.append((99, 0.0, 0.0))
        session.iteration_counter += 5
        while True:
            pass
    monkeypatch.setattr(R, "refine", hang)
    s.time_limit = 0.5
    with pytest.raises(TimeLimitExceeded, match=r"<command>:1: the command ran longer "
                                                r"than 0.5 s"):
        s.run("r")
    s.time_limit = None
    assert np.array_equal(s.surface.X, X)
    assert s.history == hist and s.total_energy == energy
    assert s.iteration_counter == counter


def test_api_timeout_on_run_and_load(tmp_path):
    s = Session.load(CUBE, out=io.StringIO(), err=io.StringIO(), timeout=30)
    assert s.time_limit == 30
    s.time_limit = None
    with pytest.raises(CommandError, match="ran longer than 0.3 s"):
        s.run("while 1 do ii := 1", timeout=0.3)
    assert s.time_limit is None
    s.run("print 1", timeout=1)
    with pytest.raises(ValueError):
        s.run("print 1", timeout=-1)
    big = _icosphere(tmp_path, 5)
    with pytest.raises(TimeLimitExceeded, match="loading the datafile ran longer"):
        Session.load(big, out=io.StringIO(), err=io.StringIO(), timeout=0.01)


def test_cli_timeout_on_loading(tmp_path):
    """``--timeout`` covers loading: non-zero exit and a message."""
    big = _icosphere(tmp_path, 5)
    r = subprocess.run([sys.executable, "-m", "pyevolver", "--timeout", "0.01", big],
                       stdin=subprocess.DEVNULL, capture_output=True, text=True, cwd=ROOT,
                       timeout=120)
    assert r.returncode == 1
    assert "loading the datafile ran longer than 0.01 s" in r.stderr


@pytest.mark.slow
def test_cli_timeout_on_loading_29mb(tmp_path):
    big = _icosphere(tmp_path, 7)
    assert os.path.getsize(big) > 29e6
    r = subprocess.run([sys.executable, "-m", "pyevolver", "--timeout", "1", big],
                       stdin=subprocess.DEVNULL, capture_output=True, text=True, cwd=ROOT,
                       timeout=300)
    assert r.returncode == 1 and "ran longer than 1 s" in r.stderr


def test_sigterm_undoes_the_command_and_exits_143(tmp_path):
    p = subprocess.Popen([sys.executable, "-m", "pyevolver", CUBE], cwd=ROOT,
                         stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    p.stdin.write('print "ready"\nwhile 1 do ii := 1\n')
    p.stdin.flush()
    line = p.stdout.readline()
    while "ready" not in line:
        line = p.stdout.readline()
    time.sleep(0.5)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 143 and "Terminated." in err
