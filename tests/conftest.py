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


def pytest_collection_modifyitems(config, items):
    if os.environ.get("PYEVOLVER_NIGHTLY", "") not in ("", "0"):
        return
    skip = pytest.mark.skip(reason="nightly: run with --nightly or PYEVOLVER_NIGHTLY=1")
    for item in items:
        if "nightly" in item.keywords:
            item.add_marker(skip)


def pytest_terminal_summary(terminalreporter):
    try:
        import fuzzing
    except ImportError:
        return
    if fuzzing.COUNTS:
        terminalreporter.write_sep("-", "fuzz inputs run")
        for target, n in sorted(fuzzing.COUNTS.items()):
            terminalreporter.write_line(f"{target}: {n}")
