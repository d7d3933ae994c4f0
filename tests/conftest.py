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


def pytest_addoption(parser):
    parser.addoption("--runslow", action="store_true", default=False,
                     help="also run the tests marked slow (long studies); the same as -m ''")


def pytest_configure(config):
    """pyproject's addopts deselect the ``slow`` tests (``-m 'not slow'``);
    ``--runslow`` (or ``-m slow`` / ``-m ''`` on the command line) runs them."""
    if config.getoption("--runslow"):
        config.option.markexpr = ""
