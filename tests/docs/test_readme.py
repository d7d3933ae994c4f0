"""The README's path is CI's path: the lines of "Two commands on a fresh
machine" (virtual environment, install, tests) are the lines ``.ci/run``
runs after the system packages, in the same order; the licence it names is
there."""
import os
import re

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _read(name):
    with open(os.path.join(ROOT, name), encoding="utf-8") as fh:
        return fh.read()


def readme_commands():
    """The shell lines of the README's fresh-machine section (its ``sh``
    blocks before the note on slow tests)."""
    text = _read("README.md")
    start = text.index("## Two commands on a fresh machine")
    end = text.index("\n## ", start + 1)
    section = text[start:end]
    section = section[:section.index("apt-get")]      # the system packages come after
    blocks = re.findall(r"```sh\n(.*?)```", section, re.S)
    return [ln for b in blocks for ln in b.splitlines() if ln.strip()]


def test_ci_runs_the_readme_lines_in_order():
    cmds = readme_commands()
    assert any("venv" in c for c in cmds) and any("pip install" in c for c in cmds)
    assert any("pytest" in c for c in cmds), cmds
    ci = [ln.strip() for ln in _read(".ci/run").splitlines()]
    at = [ci.index(c) if c in ci else -1 for c in cmds]
    assert -1 not in at, [c for c, i in zip(cmds, at) if i < 0]
    assert at == sorted(at), "the README's lines in another order in .ci/run"
    assert at[-1] == max(i for i, ln in enumerate(ci) if ln and not ln.startswith("#")), \
        ".ci/run must end with the README's test command"


def test_the_install_command_installs_what_the_test_command_runs():
    """The README installs the ``test`` extra; the test command's pytest-xdist
    (``-n 2``) comes with it."""
    cmds = readme_commands()
    install = next(c for c in cmds if "pip install" in c)
    assert '".[test]"' in install
    try:
        import tomllib
    except ImportError:                      # Python < 3.11
        import tomli as tomllib
    extras = tomllib.loads(_read("pyproject.toml"))["project"]["optional-dependencies"]
    assert any(r.startswith("pytest-xdist") for r in extras["test"]), extras["test"]
    assert any("-n 2" in c for c in cmds if "pytest" in c)


def test_license_is_present_and_named_in_the_readme():
    lic = _read("LICENSE")
    assert lic.startswith("MIT License")
    assert "MIT license (`LICENSE`)" in _read("README.md")
