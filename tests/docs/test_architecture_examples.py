"""docs/architecture.md's worked examples run: its python blocks are executed in
order in one namespace, in a fresh folder; what they register (a method, a
command, a meshio format) is removed afterwards."""
import os
import re

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DOC = os.path.join(ROOT, "docs", "architecture.md")
DATAFILES = os.path.join(ROOT, "datafiles")


def blocks(path):
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    return [(text.count("\n", 0, m.start()) + 2, m.group(1))
            for m in re.finditer(r"^```python\n(.*?)^```", text, re.S | re.M)]


@pytest.fixture
def registries():
    import meshio
    from pyevolver.commands import registry as CR
    from pyevolver.methods import REGISTRY
    before = (set(REGISTRY), set(CR.COMMANDS), set(meshio.extension_to_filetypes))
    yield
    for k in set(REGISTRY) - before[0]:
        del REGISTRY[k]
    for k in set(CR.COMMANDS) - before[1]:
        del CR.COMMANDS[k]
    for k in set(meshio.extension_to_filetypes) - before[2]:
        meshio.deregister_format(meshio.extension_to_filetypes[k][0])


def test_where_a_change_goes_examples_run(tmp_path, monkeypatch, registries):
    code = blocks(DOC)
    assert len(code) == 3            # a method, a command, a format
    monkeypatch.chdir(tmp_path)
    ns = {"__name__": "__architecture__", "DATAFILES": DATAFILES}
    for line, src in code:
        exec(compile("\n" * (line - 1) + src, DOC, "exec"), ns)
    assert os.path.getsize(tmp_path / "cube.tri") > 0
