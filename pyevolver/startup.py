"""Start-up time: numpy's optional submodules imported when first used.

scipy (1.15 and later) builds an array-API copy of the numpy namespace when
``scipy.sparse`` is first imported: it reads every public attribute of
``numpy``, and numpy imports its lazily loaded submodules on such a read
(``numpy.f2py``, ``numpy.testing``, ``numpy.random``...).  Those imports
were most of ``import scipy.sparse`` and a fifth of pyevolver's start-up
(``printf 'q\\n' | pyevolver cube.fe``: about 80 ms of CPU time of 400),
for modules that pyevolver never uses at start-up.

:func:`lazy_numpy_submodules` (run first thing at ``import pyevolver``)
registers those submodules that are not imported yet as
:class:`importlib.util.LazyLoader` modules: each is imported in full when
one of its attributes is first read (``np.random.default_rng``,
``numpy.testing.assert_allclose``), so code that uses them sees no
difference.  ``PYEVOLVER_LAZY_NUMPY=0`` in the environment turns this off.

:func:`lazy_scipy_sparse` likewise stands a placeholder for
``scipy.sparse`` (45 ms and 8 MB: pyevolver's modules import it at their
top, but loading a datafile and evaluating it need no sparse matrix,
pyevolver.model.facet_csr): the first read of one of its attributes (or
the import of one of its submodules) imports it, and the placeholder then
holds the same attributes as the module.  ``PYEVOLVER_LAZY_SCIPY=0`` turns
this off.

:func:`lark_without_regex`: lark imports the third-party ``regex`` module
when it is installed (7 ms), for grammars that ask for it; pyevolver's use
``re``.  lark is imported with ``regex`` hidden, and then given ``regex``
as a lazily loaded module, so that ``Lark(..., regex=True)`` works as
before and imports it when used.
"""
from __future__ import annotations

import importlib
import importlib.machinery
import importlib.util
import os
import sys
import types

import numpy

#: numpy's submodules that numpy itself imports on first attribute access
#: and that pyevolver needs at most in a few commands (``jiggle``'s random).
LAZY_SUBMODULES = ("f2py", "testing", "random", "fft", "ma", "ctypeslib", "polynomial")

_done = False


def lazy_numpy_submodules() -> list[str]:
    """Register numpy's optional submodules as lazily loaded modules.

    Returns
    -------
    list of str
        The submodules registered now (none when numpy's own ``__getattr__``
        already imported them, on a second call, or when
        ``PYEVOLVER_LAZY_NUMPY=0``).
    """
    global _done
    if _done or os.environ.get("PYEVOLVER_LAZY_NUMPY", "1") == "0":
        return []
    _done = True
    done = []
    for short in LAZY_SUBMODULES:
        name = "numpy." + short
        if name in sys.modules:
            continue
        spec = importlib.util.find_spec(name)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            continue
        loader = importlib.util.LazyLoader(spec.loader)
        spec.loader = loader
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        loader.exec_module(module)
        # as the import system does for a loaded submodule: numpy's
        # __getattr__ is not asked for it (it would import it again)
        setattr(numpy, short, module)
        done.append(name)
    return done


class _Placeholder(types.ModuleType):
    """A module (``scipy``, ``scipy.sparse``) until one of its attributes
    is read, then a copy of the real module's attributes."""

    def __getattr__(self, name: str):
        real = _import_real(self)
        return getattr(real, name)

    def __setattr__(self, name: str, value) -> None:
        super().__setattr__(name, value)
        real = sys.modules.get(self.__name__)
        if real is not None and real is not self and not name.startswith("__"):
            setattr(real, name, value)      # (a submodule imported through the placeholder)


def _import_real(placeholder: types.ModuleType) -> types.ModuleType:
    name = placeholder.__name__
    if sys.modules.get(name) is placeholder:
        del sys.modules[name]
    try:
        real = importlib.import_module(name)
    except BaseException:
        sys.modules.setdefault(name, placeholder)
        raise
    parent, _, short = name.rpartition(".")
    if parent:
        setattr(sys.modules[parent], short, real)
    for key, value in list(real.__dict__.items()):
        if key not in ("__getattr__", "__dir__"):
            types.ModuleType.__setattr__(placeholder, key, value)
    return real


def _placeholder(name: str, spec) -> types.ModuleType:
    p = _Placeholder(name)
    types.ModuleType.__setattr__(p, "__spec__", spec)
    types.ModuleType.__setattr__(p, "__package__", name)
    sys.modules[name] = p
    return p


_sparse_done = False


def lazy_scipy_sparse() -> bool:
    """Stand placeholders for ``scipy.sparse`` (and for ``scipy`` when it is
    not imported yet) in ``sys.modules`` until they are used (see the
    module docstring).

    Returns
    -------
    bool
        True when the placeholder was registered now (not when scipy.sparse
        is imported already, on a second call, or with ``PYEVOLVER_LAZY_SCIPY=0``).
    """
    global _sparse_done
    if _sparse_done or os.environ.get("PYEVOLVER_LAZY_SCIPY", "1") == "0" \
            or "scipy.sparse" in sys.modules:
        return False
    _sparse_done = True
    try:
        if "scipy" in sys.modules:
            scipy = sys.modules["scipy"]
            spec = importlib.util.find_spec("scipy.sparse")
        else:   # (found without importing scipy: its __init__ costs 10 ms)
            top = importlib.util.find_spec("scipy")
            if top is None or not top.submodule_search_locations:
                return False
            spec = importlib.machinery.PathFinder.find_spec(
                "scipy.sparse", list(top.submodule_search_locations))
            if spec is None:
                return False
            scipy = _placeholder("scipy", top)
    except ImportError:
        return False
    if spec is None:
        return False
    types.ModuleType.__setattr__(scipy, "sparse", _placeholder("scipy.sparse", spec))
    return True


def lark_without_regex() -> bool:
    """Import lark without importing ``regex`` (see the module docstring).

    Returns
    -------
    bool
        True when lark was imported so now (not when lark or regex is
        imported already, or regex is not installed).
    """
    if "lark" in sys.modules or "regex" in sys.modules:
        return False
    spec = importlib.util.find_spec("regex")
    if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
        return False
    sys.modules["regex"] = None         # type: ignore[assignment]  (lark: "not installed")
    try:
        import lark.lark
        import lark.utils
    finally:
        del sys.modules["regex"]
    loader = importlib.util.LazyLoader(spec.loader)
    spec.loader = loader
    regex = importlib.util.module_from_spec(spec)
    sys.modules["regex"] = regex
    loader.exec_module(regex)
    for mod in (lark.utils, lark.lark):
        if hasattr(mod, "_has_regex"):
            mod.regex = regex           # type: ignore[attr-defined]
            mod._has_regex = True       # type: ignore[attr-defined]
    return True
