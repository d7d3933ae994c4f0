"""SuperLU in symmetric mode without importing ``scipy.sparse.linalg``.

``import scipy.sparse.linalg`` costs about 0.1 s of CPU (it imports
``scipy.linalg``, the iterative solvers and parses their docstrings): as
much as a third of a ``hessian`` step on an 81,920-facet surface, paid by
every first step in a process.  The factorization itself lives in one
compiled module, ``scipy/sparse/linalg/_dsolve/_superlu``, which loads in
2 ms.  :func:`factor` loads that module by its file when the package is
not imported yet and calls its ``gstrf`` with the options ``splu`` would
pass; on any surprise (another scipy whose module or call differs) it falls
back to ``scipy.sparse.linalg.splu`` with the same options, so the result
never depends on which path ran.

The factors ``L`` and ``U`` are not built as scipy matrices: SuperLU
objects made by :func:`factor` give only their diagonals (:class:`Diagonal`),
all :func:`pivots` needs.
"""
from __future__ import annotations

import importlib.machinery
import importlib.util
import os
import sys

import numpy as np
import scipy

_MODULE = "scipy.sparse.linalg._dsolve._superlu"
_direct: list = []          # [module] once loaded, [None] when it cannot be


class Diagonal:
    """What :func:`factor`'s SuperLU returns for ``L`` and ``U``: only the
    diagonal of the CSC arrays SuperLU hands over (SuperLU builds both
    factors at the first access to either; keeping only the diagonals frees
    their copies at once)."""

    def __init__(self, arg, shape=None, **_):
        data, indices, indptr = arg
        ptr = np.asarray(indptr)
        n = len(ptr) - 1
        self.shape = shape
        if n and np.all(ptr[1:] > ptr[:-1]):
            for at in (ptr[1:] - 1, ptr[:-1]):    # U: the diagonal last; L: first
                if np.array_equal(indices[at], np.arange(n)):
                    self._d = np.array(data[at], float)
                    return
        nnz = int(ptr[-1])                        # (the arrays may be longer)
        cols = np.repeat(np.arange(n), np.diff(ptr))
        on = indices[:nnz] == cols
        self._d = np.zeros(n)
        self._d[cols[on]] = data[:nnz][on]

    def diagonal(self):
        return self._d


def _load():
    """The compiled ``_superlu`` module, or None."""
    if not _direct:
        mod = sys.modules.get(_MODULE)
        if mod is None:
            try:
                folder = os.path.join(os.path.dirname(scipy.__file__), "sparse", "linalg",
                                      "_dsolve")
                name = next(f for f in sorted(os.listdir(folder))
                            if f.startswith("_superlu") and
                            f.endswith(tuple(importlib.machinery.EXTENSION_SUFFIXES)))
                path = os.path.join(folder, name)
                loader = importlib.machinery.ExtensionFileLoader(_MODULE, path)
                spec = importlib.util.spec_from_file_location(_MODULE, path, loader=loader)
                mod = importlib.util.module_from_spec(spec)
                loader.exec_module(mod)
                if not callable(getattr(mod, "gstrf", None)):
                    mod = None
            except Exception:            # noqa: BLE001 (any layout: the public path)
                mod = None
        _direct.append(mod)
    return _direct[0]


def _options(natural: bool) -> dict:
    return {"DiagPivotThresh": 0.0, "ColPerm": "NATURAL" if natural else "MMD_AT_PLUS_A",
            "PanelSize": None, "Relax": None, "SymmetricMode": True}


def factor(A, natural: bool = True):
    """SuperLU of the CSC matrix ``A`` (canonical: sorted indices, no
    duplicates) in symmetric mode (no pivoting off the diagonal), in its
    own order (``natural``) or SuperLU's minimum degree on ``A + Aᵀ``.
    Returns the SuperLU object (``solve``, ``perm_r``, ``perm_c``, ``U``);
    raises RuntimeError when ``A`` is exactly singular."""
    mod = None if "scipy.sparse.linalg" in sys.modules else _load()
    n = A.shape[0]
    A.sum_duplicates()                   # (nothing to do on a canonical matrix)
    if mod is not None:
        try:
            indices = np.asarray(A.indices, np.intc)
            indptr = np.asarray(A.indptr, np.intc)
            data = np.asarray(A.data, np.float64)
            return mod.gstrf(n, len(data), data, indices, indptr, csc_construct_func=Diagonal,
                             ilu=False, options=_options(natural))
        except (TypeError, ValueError, AttributeError):
            pass                         # another scipy's call: the public path
    import scipy.sparse.linalg as spla
    opts = _options(natural)
    return spla.splu(A, permc_spec=opts.pop("ColPerm"), diag_pivot_thresh=0.0,
                     options={"SymmetricMode": True})


def pivots(lu):
    """The diagonal of ``U`` (the D of ``L D Lᵀ`` in symmetric mode), or None
    when SuperLU pivoted rows off the diagonal."""
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return None
    return np.asarray(lu.U.diagonal(), float)
