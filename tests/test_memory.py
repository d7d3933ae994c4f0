"""pyevolver.memory: glibc's allocator thresholds are set at import, once,
and not when the user says otherwise."""
import os
import subprocess
import sys

import pytest

from pyevolver import memory

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _child(env_extra, show="m._done"):
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYEVOLVER_MALLOC", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_",
                        "NUMPY_MADVISE_HUGEPAGE")}
    env.update(env_extra, PYTHONPATH=ROOT)
    p = subprocess.run([sys.executable, "-c", "import pyevolver, pyevolver.memory as m; "
                        f"print({show})"], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    return p.stdout.strip()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_thresholds_are_set_at_import_on_glibc():
    assert _child({}) == "True"
    assert memory.tune_allocator() is memory.tune_allocator()       # once, then remembered


def test_the_user_can_keep_the_defaults():
    assert _child({"PYEVOLVER_MALLOC": "0"}) == "False"
    assert _child({"MALLOC_TRIM_THRESHOLD_": "131072"}) == "False"


# numpy's own setting, read back by setting it (the call returns the old value)
HUGE = "m._huge, __import__('numpy')._core.multiarray._set_madvise_hugepage(True)"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the kernel's huge pages")
def test_numpys_huge_page_requests_are_off_unless_the_user_says():
    assert _child({}, HUGE) == "True False"
    assert _child({"NUMPY_MADVISE_HUGEPAGE": "1"}, HUGE) == "False True"
    assert _child({"PYEVOLVER_MALLOC": "0"}, HUGE) == "False True"
    assert memory.huge_pages_off() is memory.huge_pages_off()


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
