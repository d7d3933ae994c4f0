"""BLAS thread control (pyevolver.threads): the setting from
PYEVOLVER_BLAS_THREADS, the limit inside the steps and the user's
setting restored after them."""
import io
import sys

import pytest
from threadpoolctl import threadpool_info

from conftest import example
from pyevolver import Session
from pyevolver import threads as TH


def _blas_threads():
    return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]


@pytest.mark.parametrize("raw,want", [(None, 1), ("", 1), ("2", 2), ("0", None),
                                      ("off", None), ("-3", None), ("many", 1)])
def test_setting(monkeypatch, raw, want):
    if raw is None:
        monkeypatch.delenv(TH.ENV, raising=False)
    else:
        monkeypatch.setenv(TH.ENV, raw)
    assert TH.setting() == want


def test_limit_inside_and_restored_after(monkeypatch):
    import numpy  # noqa: F401  (loads the BLAS)
    before = _blas_threads()
    if not before:
        pytest.skip("no BLAS library that threadpoolctl knows")
    monkeypatch.delenv(TH.ENV, raising=False)
    with TH.limited():
        assert set(_blas_threads()) == {1}
    assert _blas_threads() == before
    monkeypatch.setenv(TH.ENV, "off")
    with TH.limited():
        assert _blas_threads() == before


def test_g_and_hessian_run_limited(monkeypatch):
    from pyevolver.evolve.iterate import Iterator
    inside = []
    real_search = Iterator._line_search

    def search(self, *args):
        inside.append((TH._depth, set(_blas_threads())))
        return real_search(self, *args)
    monkeypatch.setattr(Iterator, "_line_search", search)
    seen = []

    @TH.blas_limited
    def probe():
        return _blas_threads()
    assert probe.__name__ == "probe"
    real = TH.limited

    def spy():
        seen.append(1)
        return real()
    monkeypatch.setattr(TH, "limited", spy)
    s = Session.load(example("cube.fe"), out=io.StringIO())
    s.g(2)
    assert len(inside) == 2                     # each g step runs inside the limit
    assert all(depth >= 1 and threads <= {1} for depth, threads in inside)
    s.hessian(echo=False)
    assert len(seen) == 1
    assert set(probe()) <= {1}


def test_controller_made_again_after_new_imports(monkeypatch):
    """scipy's linear algebra (its own BLAS) is imported when first used,
    after the controller may have been made: a new import makes a new one."""
    import types
    first = TH._control()
    if first is None:
        pytest.skip("threadpoolctl is not installed")
    assert TH._control() is first
    monkeypatch.setitem(sys.modules, "pyevolver_test_new_module", types.ModuleType("x"))
    assert TH._control() is not first


def test_interrupted_nested_use_finished_late_changes_nothing(monkeypatch):
    """A time limit can stop a command after a nested use entered and
    before its exit ran; its generator is then closed by the garbage
    collector after the outer use ended.  That late exit must not make the
    depth negative (which made the next `g` steps each set the limit again
    and the next `hessian` run outside it)."""
    import gc
    monkeypatch.setenv(TH.ENV, "off")
    with TH.limited():
        orphan = TH.limited()
        orphan.__enter__()                  # (never exited: the interrupted use)
        assert TH._depth == 2
    assert TH._depth == 0
    del orphan
    gc.collect()
    assert TH._depth == 0
    with TH.limited():
        assert TH._depth == 1
        with TH.limited():
            assert TH._depth == 2
        assert TH._depth == 1
    assert TH._depth == 0


@pytest.mark.parametrize("orig,argv0,want", [
    (["python", "-m", "pyevolver", "cube.fe"], "-m", True),
    (["python", "-m", "pyevolver.cli.main"], "-m", True),
    (["python", "-m", "pytest", "-q"], "/x/pytest/__main__.py", False),
    (["/venv/bin/python", "/venv/bin/pyevolver", "cube.fe"], "/venv/bin/pyevolver", True),
    (["python", "-c", "import pyevolver"], "-c", False),
    (["python", "run.py"], "run.py", False)])
def test_is_program(monkeypatch, orig, argv0, want):
    monkeypatch.setattr(sys, "orig_argv", orig, raising=False)
    monkeypatch.setattr(sys, "argv", [argv0])
    assert TH.is_program() is want


def _fresh(code, env):
    import os
    import subprocess
    full = {k: v for k, v in os.environ.items() if k not in TH._BLAS_ENV and k != TH.ENV}
    full.update(env)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=full, check=True).stdout.split()


PROGRAM = ("import sys; sys.orig_argv = ['python', '-m', 'pyevolver']\n"
           "import os, pyevolver\n"
           "from threadpoolctl import threadpool_info\n"
           "print(os.environ.get('OPENBLAS_NUM_THREADS', '-'),"
           " *sorted({i['num_threads'] for i in threadpool_info()"
           " if i['internal_api'] == 'openblas'}))\n")


def test_program_starts_openblas_with_one_thread():
    # the program (not a user's script) sets OPENBLAS_NUM_THREADS before numpy
    # loads, unless the user chose a count or PYEVOLVER_BLAS_THREADS=0
    out = _fresh(PROGRAM, {})
    if len(out) == 1:
        pytest.skip("numpy's BLAS is not OpenBLAS")
    assert out == ["1", "1"]
    assert _fresh(PROGRAM, {TH.ENV: "2"}) == ["2", "2"]
    assert _fresh(PROGRAM, {"OPENBLAS_NUM_THREADS": "2"})[0] == "2"
    assert _fresh(PROGRAM, {TH.ENV: "0"})[0] == "-"
    script = PROGRAM.replace("sys.orig_argv = ['python', '-m', 'pyevolver']", "pass")
    assert _fresh(script, {})[0] == "-"


def test_process_wide_limit_stays_after_steps(monkeypatch):
    import numpy  # noqa: F401  (loads the BLAS)
    from threadpoolctl import ThreadpoolController
    before = _blas_threads()
    if not before:
        pytest.skip("no BLAS library that threadpoolctl knows")
    monkeypatch.delenv(TH.ENV, raising=False)
    monkeypatch.setattr(TH, "_process", False)
    monkeypatch.setattr(TH, "_kept", None)
    guard = ThreadpoolController()
    original = [(lib, lib.num_threads) for lib in guard.lib_controllers]
    try:
        TH.process_wide()
        assert set(_blas_threads()) == {1}
        with TH.limited():
            assert set(_blas_threads()) == {1}
        assert set(_blas_threads()) == {1}          # not lifted between steps
    finally:
        TH._process = False
        TH._controller = None
        for lib, n in original:
            lib.set_num_threads(n)
    assert _blas_threads() == before


def test_library_loaded_inside_a_step_is_limited_at_once_and_restored(monkeypatch):
    """scipy's SuperLU brings scipy's OpenBLAS when the first hessian loads
    it, inside the step's limit: it is limited from then to the step's end."""
    import numpy  # noqa: F401
    if not _blas_threads():
        pytest.skip("no BLAS library that threadpoolctl knows")
    monkeypatch.delenv(TH.ENV, raising=False)
    made = []
    real = TH._control

    class Spy:
        def __init__(self, ctl):
            self.ctl = ctl

        def limit(self, **kw):
            lim = self.ctl.limit(**kw)
            made.append(lim)
            return lim

    monkeypatch.setattr(TH, "_control", lambda: Spy(real()))
    with TH.limited():
        assert len(made) == 1
        TH.libraries_loaded()           # (as superlu._load does)
        assert len(made) == 2 and len(TH._late) == 1
        assert set(_blas_threads()) == {1}
    assert TH._late == []
