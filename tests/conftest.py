"""Shared fixtures: the reference Evolver (evolver-nox-d) and example paths.

Comparison tests run the reference live.  Under CI (``CI=true``) a missing
reference fails the run instead of skipping: a skipped comparison proves
nothing.
"""
import os
import shutil

import pytest

EXAMPLES = "/usr/share/doc/evolver/examples"
SHARED = os.path.join(os.path.dirname(__file__), "..", "..", "shared", "reference-checks")
HERE = os.path.dirname(__file__)


def _ref_binary():
    return shutil.which("evolver-nox-d")


@pytest.fixture(scope="session")
def evolver():
    exe = _ref_binary()
    if exe is None or not os.path.isdir(EXAMPLES):
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("evolver-nox-d / evolver-doc are not installed: .ci/run must install "
                        "them (apt-get install -y evolver-nox evolver-doc)")
        pytest.skip("reference evolver-nox-d not installed")
    return exe


def example(name):
    return os.path.join(EXAMPLES, name)


def jittered_surface(name, seed, scale):
    """The surface of the example ``name`` refined once, its vertices moved
    by Gaussian noise of size ``scale`` (seed ``seed``): no symmetry left to
    hide a wrong sign in a Hessian or gradient test."""
    import io
    import numpy as np
    from pyevolver import Session
    s = Session.load(example(name), out=io.StringIO())
    s.refine(echo=False)
    s.surface.X += scale * np.random.default_rng(seed).standard_normal(s.surface.X.shape)
    return s.surface


# ---------------------------------------------------------------------------
# nightly-style runs and the fuzz counts


def pytest_addoption(parser):
    parser.addoption("--runslow", action="store_true", default=False,
                     help="also run the tests marked slow (long studies); the same as -m ''")
    parser.addoption("--nightly", action="store_true", default=False,
                     help="also run the long tests marked 'nightly' (more fuzz inputs)")


def pytest_configure(config):
    """pyproject's addopts deselect the ``slow`` tests (``-m 'not slow'``);
    ``--runslow`` (or ``-m slow`` / ``-m ''`` on the command line) runs them.
    ``--nightly`` runs the nightly fuzz sizes."""
    if config.getoption("--runslow"):
        config.option.markexpr = ""
    if config.getoption("--nightly"):
        os.environ["PYEVOLVER_NIGHTLY"] = "1"
    config.addinivalue_line("markers", "cholmod: needs scikit-sparse (the optional cholmod "
                            "extra); deselected where it is not installed")


def _has_cholmod():
    try:
        import sksparse.cholmod  # noqa: F401
    except ImportError:
        return False
    return True


def pytest_collection_modifyitems(config, items):
    # the README's install (the test extra) has no CHOLMOD: its tests are
    # deselected there, run where `pip install -e ".[cholmod]"` succeeded
    if not _has_cholmod():
        chol = [item for item in items if "cholmod" in item.keywords]
        if chol:
            items[:] = [item for item in items if "cholmod" not in item.keywords]
            config.hook.pytest_deselected(items=chol)
    if os.environ.get("PYEVOLVER_NIGHTLY", "") not in ("", "0"):
        return
    # deselected (not skipped: CI must show no skips), like the slow tests
    nightly = [item for item in items if "nightly" in item.keywords]
    if nightly:
        items[:] = [item for item in items if "nightly" not in item.keywords]
        config.hook.pytest_deselected(items=nightly)


def pytest_terminal_summary(terminalreporter):
    try:
        import fuzzing
    except ImportError:
        return
    if fuzzing.COUNTS:
        terminalreporter.write_sep("-", "fuzz inputs run")
        for target, n in sorted(fuzzing.COUNTS.items()):
            t = fuzzing.TIMES.get(target)
            terminalreporter.write_line(f"{target}: {n}" + (
                f" in {t[0]:.1f} s ({t[1]:.1f} s CPU)" if t else ""))
    changed = getattr(terminalreporter.config, "_repo_changes", None)
    if changed:
        terminalreporter.write_sep("-", "files the tests wrote into the repository")
        for path in changed:
            terminalreporter.write_line(path)


# ---------------------------------------------------------------------------
# the tests write nothing into the repository (no .dmp next to a tracked
# datafile, no output files): they work on tmp_path copies

REPO = os.path.dirname(os.path.abspath(HERE))
_IGNORED = {".git", ".venv", "__pycache__", ".pytest_cache", ".hypothesis", "build"}


def _repo_files():
    """``{path: (size, mtime_ns)}`` of the repository's files (without
    caches and ignored build output)."""
    out = {}
    for root, dirs, files in os.walk(REPO):
        dirs[:] = [d for d in dirs if d not in _IGNORED and not d.endswith(".egg-info")
                   and os.path.join(root, d) != os.path.join(REPO, "benchmarks", "data")]
        for f in files:
            if f.endswith(".pyc"):
                continue
            p = os.path.join(root, f)
            try:
                st = os.stat(p)
            except OSError:
                continue
            out[os.path.relpath(p, REPO)] = (st.st_size, st.st_mtime_ns)
    return out


def _is_worker(config):
    """A pytest-xdist worker (``-n 2``): the controller checks the repository
    and prints the fuzz counts the workers send it."""
    return hasattr(config, "workerinput")


def pytest_sessionstart(session):
    if not _is_worker(session.config):
        session.config._repo_before = _repo_files()


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error):
    """xdist: add a worker's fuzz counts and times to the controller's."""
    sent = getattr(node, "workeroutput", {}).get("fuzz")
    if not sent:
        return
    import fuzzing
    for target, n in sent["counts"].items():
        fuzzing.COUNTS[target] = fuzzing.COUNTS.get(target, 0) + n
    for target, (wall, cpu) in sent["times"].items():
        w0, c0 = fuzzing.TIMES.get(target, (0.0, 0.0))
        fuzzing.TIMES[target] = (w0 + wall, c0 + cpu)


def pytest_sessionfinish(session, exitstatus):
    if _is_worker(session.config):
        import sys
        fz = sys.modules.get("fuzzing")
        if fz is not None and fz.COUNTS:
            session.config.workeroutput["fuzz"] = {
                "counts": dict(fz.COUNTS), "times": {k: list(v) for k, v in fz.TIMES.items()}}
        return
    before = getattr(session.config, "_repo_before", None)
    if before is None:
        return
    after = _repo_files()
    changed = sorted(p for p in after if before.get(p) != after[p])
    if changed:
        session.config._repo_changes = changed
        if session.exitstatus == 0:
            session.exitstatus = 1
