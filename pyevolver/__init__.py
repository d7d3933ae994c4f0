"""pyevolver: Surface Evolver datafiles and command scripts in Python.

Data flows one way: text -> Scene -> Surface -> (methods, constraints) ->
evolve / remesh -> outputs.  :class:`Session` is shared by the REPL, the CLI
and the Python API.
"""
__version__ = "0.1.0"

from typing import Any  # noqa: E402

import gc as _gc  # noqa: E402

from .threads import program_start as _program_start  # noqa: E402

_program_start()            # the pyevolver program: one BLAS thread (pyevolver.threads)

_gc_enabled = _gc.isenabled()
_gc.disable()               # importing creates ~10^5 objects: no collections meanwhile (start-up)
try:
    from .startup import lazy_numpy_submodules as _lazy_numpy, lazy_scipy_sparse  # noqa: E402
    from .startup import lark_without_regex  # noqa: E402

    _lazy_numpy()               # numpy.f2py, numpy.testing... when first used (pyevolver.startup)
    lazy_scipy_sparse()         # scipy.sparse likewise
    lark_without_regex()        # and the regex module that lark imports

    from .errors import (PyEvolverError, DatafileError, CommandError, UnsupportedError,  # noqa: E402
                         ExpressionError, ConstraintError, ConvergenceWarning)
    from .datafile.reader import read_datafile  # noqa: E402
    from .model.surface import Surface  # noqa: E402
    from .model.build import build_surface  # noqa: E402
    from . import methods as _methods  # noqa: E402,F401  (installs the model's evaluate/method hooks)
    from .session.core import Session  # noqa: E402
    from .io.meshio_plugin import register_when_imported as _register_meshio  # noqa: E402
    from .memory import tune_allocator as _tune_allocator  # noqa: E402

    _register_meshio()          # meshio.read("cube.fe") / meshio.write("out.fe", mesh)
    _tune_allocator()           # large numpy temporaries stay in the heap (pyevolver.memory)
finally:
    if hasattr(_gc, "freeze"):
        _gc.freeze()            # the modules' objects go to the oldest generation at once,
        _gc.unfreeze()          # (not scanned as young objects at the next allocation)
    if _gc_enabled:
        _gc.enable()


def load(filename: str, **kwargs: Any) -> Session:
    """Load a datafile into a :class:`Session` (runs its ``read`` section).

    Parameters
    ----------
    filename : str
        The ``.fe`` datafile.
    **kwargs
        Passed to :meth:`Session.load` (``out``, ``err``, ``run_read``, ``text``).
    """
    return Session.load(filename, **kwargs)


__all__ = ["Session", "Surface", "load", "read_datafile", "build_surface", "PyEvolverError",
           "DatafileError", "CommandError", "UnsupportedError", "ExpressionError",
           "ConstraintError", "ConvergenceWarning", "__version__"]
