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
