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
"""
from __future__ import annotations

import importlib.util
import os
import sys

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
