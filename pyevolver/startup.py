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
"""
from __future__ import annotations

import importlib
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


class _LazySparse(types.ModuleType):
    """``scipy.sparse`` until one of its attributes is read."""

    def __getattr__(self, name: str):
        real = _import_sparse(self)
        return getattr(real, name)

    def __setattr__(self, name: str, value) -> None:
        super().__setattr__(name, value)
        real = sys.modules.get(self.__name__)
        if real is not None and real is not self and not name.startswith("__"):
            setattr(real, name, value)      # (a submodule imported through the placeholder)


def _import_sparse(placeholder: types.ModuleType) -> types.ModuleType:
    name = placeholder.__name__
    if sys.modules.get(name) is placeholder:
        del sys.modules[name]
    try:
        real = importlib.import_module(name)
    except BaseException:
        sys.modules.setdefault(name, placeholder)
        raise
    parent, _, short = name.rpartition(".")
    setattr(sys.modules[parent], short, real)
    for key, value in real.__dict__.items():
        if key not in ("__getattr__", "__dir__"):
            types.ModuleType.__setattr__(placeholder, key, value)
    return real


_sparse_done = False


def lazy_scipy_sparse() -> bool:
    """Stand a placeholder for ``scipy.sparse`` in ``sys.modules`` until it
    is used (see the module docstring).

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
        import scipy
        spec = importlib.util.find_spec("scipy.sparse")
    except ImportError:
        return False
    if spec is None:
        return False
    placeholder = _LazySparse("scipy.sparse")
    types.ModuleType.__setattr__(placeholder, "__spec__", spec)
    types.ModuleType.__setattr__(placeholder, "__package__", "scipy.sparse")
    sys.modules["scipy.sparse"] = placeholder
    types.ModuleType.__setattr__(scipy, "sparse", placeholder)
    return True
