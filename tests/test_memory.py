"""pyevolver.memory: glibc's allocator thresholds are set at import, once,
and not when the user says otherwise."""
import os
import subprocess
import sys

import pytest

from pyevolver import memory

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _child(env_extra):
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYEVOLVER_MALLOC", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_")}
    env.update(env_extra, PYTHONPATH=ROOT)
    p = subprocess.run([sys.executable, "-c", "import pyevolver, pyevolver.memory as m; "
                        "print(m._done)"], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    return p.stdout.strip()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_thresholds_are_set_at_import_on_glibc():
    assert _child({}) == "True"
    assert memory.tune_allocator() is memory.tune_allocator()       # once, then remembered


def test_the_user_can_keep_the_defaults():
    assert _child({"PYEVOLVER_MALLOC": "0"}) == "False"
    assert _child({"MALLOC_TRIM_THRESHOLD_": "131072"}) == "False"


def test_loading_runs_the_step_and_restores():
    calls = []

    @memory.loading
    def step(x, fail=False):
        calls.append(memory._depth)
        if fail:
            raise ValueError("bad")
        return step2(x) + 1

    @memory.loading
    def step2(x):
        calls.append(memory._depth)
        return x * 2

    assert step(3) == 7 and memory._depth == 0
    with pytest.raises(ValueError):
        step(1, fail=True)
    assert memory._depth == 0
    on = memory._mallopt is not None        # (glibc: the thresholds lowered once, nested too)
    assert calls == ([1, 1, 1] if on else [0, 0, 0])


GIVE_BACK = """
import numpy as np, pyevolver, pyevolver.memory as m
def rss():
    return int(open('/proc/self/status').read().split('VmRSS:')[1].split()[0]) // 1024
blocks = [np.ones(1 << 17) for _ in range(400)]   # 1 MB blocks in the heap (below 32 MiB)
del blocks[::2]                 # every other one freed: holes between kept blocks,
held = rss()                    # not a free top that free() itself trims
m.give_back()
print(held, rss(), m._trim is not False)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's malloc_trim")
def test_give_back_returns_freed_heap_pages():
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYEVOLVER_MALLOC", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_")}
    env["PYTHONPATH"] = ROOT
    out = subprocess.run([sys.executable, "-c", GIVE_BACK], capture_output=True, text=True,
                         env=env, timeout=120, check=True).stdout.split()
    held, after, active = int(out[0]), int(out[1]), out[2] == "True"
    assert active
    assert held - after > 150, (held, after)      # (MB: most of the 200 freed)
    env["PYEVOLVER_MALLOC"] = "0"                  # the user's allocator: left alone
    out = subprocess.run([sys.executable, "-c", GIVE_BACK], capture_output=True, text=True,
                         env=env, timeout=120, check=True).stdout.split()
    assert out[2] == "False"
