"""The house rules of the package layout (issue 21), checked on the code itself.

- no import cycle between pyevolver's modules (grimp's import graph, Tarjan's
  strongly connected components);
- the import-linter layers contract of pyproject.toml is kept (``lint-imports``);
- the public API type-checks (mypy, configured in pyproject.toml) and is annotated;
- no module over about 800 lines;
- imports inside functions only for optional heavy dependencies;
- docs/architecture.md's generated picture is current.
"""
from __future__ import annotations

import ast
import importlib.util
import inspect
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
PKG = ROOT / "pyevolver"

# the optional dependencies a function may import lazily (extras in pyproject.toml),
# and the heavy corners of required ones that few runs use (at start-up scipy.special
# costs 0.4 s and 11 MB, for the elliptic functions and one quadrature rule;
# scipy.sparse.linalg 0.1 s and 8 MB, for the hessian's and newton's solves)
OPTIONAL = {"matplotlib", "tqdm", "prompt_toolkit", "sksparse", "dask", "distributed",
            "h5py", "PIL", "threadpoolctl", "tomli", "tomllib", "readline", "pexpect",
            "pyvista", "vtk", "imageio_ffmpeg"}
HEAVY = {"scipy.special", "scipy.sparse.linalg", "scipy.sparse.csgraph",
         "meshio",             # (imported where used: start-up time, issue 24)
         "lark.lark", "lark.utils"}    # (pyevolver.startup: lark imported without regex)
#: pyevolver's own modules that are imported where first used, to keep them
#: out of the start-up (issue 24): the Hessian's and eigenvalue commands'
#: modules, pictures, movies and the HTML viewer
DEFERRED = {"..evolve.bfgs", "..evolve.eigen", "..evolve.newton", "..evolve.hessian",
            "..io.render", "..io.movie", "..io.viewer"}
MAX_LINES = 800


def _graph():
    grimp = pytest.importorskip("grimp")
    return grimp.build_graph("pyevolver", cache_dir=None)


def strongly_connected(edges: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components, iteratively (no recursion limit)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = 0
    for root in sorted(edges):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(edges.get(w, ())))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = []
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.append(w)
                    if w == v:
                        break
                out.append(sorted(comp))
    return out


def test_cycle_finder_finds_a_planted_cycle():
    edges = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert [c for c in strongly_connected(edges) if len(c) > 1] == [["a", "b", "c"]]
    assert all(len(c) == 1 for c in strongly_connected({"a": {"b"}, "b": set()}))


def test_no_import_cycle():
    g = _graph()
    edges = {m: set(g.find_modules_directly_imported_by(m)) for m in g.modules}
    cycles = [c for c in strongly_connected(edges) if len(c) > 1]
    assert not cycles, f"import cycles: {cycles}"


def test_import_contracts_are_kept():
    pytest.importorskip("importlinter")
    proc = subprocess.run([sys.executable, "-c",
                           "import sys; from importlinter.cli import lint_imports_command; "
                           "sys.argv = ['lint-imports', '--no-cache', '--no-logo']; "
                           "lint_imports_command()"],
                          cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-4000:] + proc.stderr[-2000:]
    assert "BROKEN" not in proc.stdout and "KEPT" in proc.stdout


def test_type_check_of_the_public_api():
    if importlib.util.find_spec("mypy") is None:
        pytest.skip("mypy is not installed (pip install -e '.[test]')")
    from mypy import api
    out, err, status = api.run(["--config-file", str(ROOT / "pyproject.toml"),
                               "--cache-dir", "/dev/null"])
    assert status == 0, out + err


def test_modules_are_at_most_about_800_lines():
    big = {str(p.relative_to(ROOT)): n for p in PKG.rglob("*.py")
           if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert not big, big


def _function_imports(path: pathlib.Path):
    tree = ast.parse(path.read_text())
    for fn in ast.walk(tree):
        if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for node in ast.walk(fn):
            if isinstance(node, ast.Import):
                for a in node.names:
                    yield node.lineno, a.name, ()
            elif isinstance(node, ast.ImportFrom):
                yield (node.lineno, "." * node.level + (node.module or ""),
                       tuple(a.name for a in node.names))


def _deferred(mod, names):
    """Whether ``from mod import names`` imports only :data:`DEFERRED` modules."""
    return mod in DEFERRED or bool(names) and all(f"{mod}.{n}" in DEFERRED for n in names)


def test_imports_inside_functions_only_for_optional_dependencies():
    bad = []
    for path in sorted(PKG.rglob("*.py")):
        for line, mod, names in _function_imports(path):
            if mod.split(".")[0] not in OPTIONAL and mod not in HEAVY \
                    and not _deferred(mod, names):
                bad.append(f"{path.relative_to(ROOT)}:{line}: {mod}")
    assert not bad, "\n".join(bad)


def _public_callables():
    import pyevolver
    for name in pyevolver.__all__:
        obj = getattr(pyevolver, name)
        if inspect.isclass(obj) and issubclass(obj, BaseException):
            continue
        if inspect.isclass(obj):
            seen = set()
            for klass in inspect.getmro(obj):          # inherited methods too (Session's mixin)
                if not klass.__module__.startswith("pyevolver"):
                    continue
                for mname, meth in vars(klass).items():
                    if (mname.startswith("_") and mname not in ("__init__", "__repr__",
                                                                 "_repr_html_")) \
                            or mname in seen:
                        continue
                    seen.add(mname)
                    fn = meth.__func__ if isinstance(meth, (classmethod, staticmethod)) else meth
                    if inspect.isfunction(fn):
                        yield f"{name}.{mname}", fn
        elif inspect.isfunction(obj):
            yield name, obj


def test_public_api_is_annotated():
    missing = []
    for name, fn in _public_callables():
        sig = inspect.signature(fn)
        params = [p for p in sig.parameters.values()
                  if p.name not in ("self", "cls") and p.annotation is inspect.Parameter.empty]
        if params or (sig.return_annotation is inspect.Signature.empty
                      and fn.__name__ != "__init__"):
            missing.append(name)
    assert not missing, missing


def test_architecture_doc_is_current():
    spec = importlib.util.spec_from_file_location("make_architecture",
                                                  ROOT / "docs" / "make_architecture.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    text = (ROOT / "docs" / "architecture.md").read_text()
    assert mod.updated(text) == text, "run python docs/make_architecture.py"


def _test_imports() -> dict[str, set[pathlib.Path]]:
    """module -> the test files that import it by name."""
    mods = _module_names()
    out: dict[str, set[pathlib.Path]] = {}
    for t in (ROOT / "tests").rglob("test_*.py"):
        for node in ast.walk(ast.parse(t.read_text())):
            names = []
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("pyevolver"):
                names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            for n in names:
                if n in mods:
                    out.setdefault(n, set()).add(t)
    return out


def _bare_packages() -> set[str]:
    """Packages whose ``__init__`` defines no function or class (nothing to test)."""
    out = set()
    for p in PKG.rglob("__init__.py"):
        tree = ast.parse(p.read_text())
        if not any(isinstance(n, (ast.FunctionDef, ast.ClassDef)) for n in tree.body):
            out.add(".".join(p.parent.relative_to(ROOT).parts))
    return out


def _module_names() -> set[str]:
    out = set()
    for p in PKG.rglob("*.py"):
        name = ".".join(p.relative_to(ROOT).with_suffix("").parts)
        out.add(name[: -len(".__init__")] if name.endswith(".__init__") else name)
    return out


def test_tests_mirror_the_package_and_every_module_has_direct_tests():
    """Each module pyevolver.PKG.x is imported by a test in tests/PKG/ (the
    leaf modules pyevolver.x by one in tests/): tests/ mirrors the package."""
    imports = _test_imports()
    missing = []
    for m in sorted(_module_names() - {"pyevolver", "pyevolver.__main__"} - _bare_packages()):
        parts = m.split(".")
        package = (PKG / parts[1]).is_dir()
        folder = ROOT / "tests" / parts[1] if package else ROOT / "tests"
        if not any(f.parent == folder or folder in f.parents and package
                   for f in imports.get(m, ())):
            missing.append(m)
    assert not missing, missing
