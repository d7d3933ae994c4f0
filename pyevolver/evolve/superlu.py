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
all :func:`pivots` needs.  Even so, scipy copies both whole factors into new
arrays at the first access to ``L`` or ``U`` (on the 81,920-facet spheres
50–110 MB and 0.05–0.08 s, a fifth of the ``hessian`` step's peak), so
:func:`pivots` first reads the diagonal where SuperLU keeps it, in the
supernodes of ``L`` (:func:`_stored_diagonal`, through ctypes, after
checking the object's layout against what scipy reports of it); any
mismatch takes the copying path.
"""
from __future__ import annotations

import ctypes
import importlib.machinery
import importlib.util
import os
import sys

import numpy as np
import scipy

from .. import threads

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
            else:
                threads.libraries_loaded()      # (scipy's OpenBLAS, limited in the steps)
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
    fresh = "scipy.sparse.linalg" not in sys.modules
    import scipy.sparse.linalg as spla
    if fresh:
        threads.libraries_loaded()
    opts = _options(natural)
    return spla.splu(A, permc_spec=opts.pop("ColPerm"), diag_pivot_thresh=0.0,
                     options={"SymmetricMode": True})


def pivots(lu):
    """The diagonal of ``U`` (the D of ``L D Lᵀ`` in symmetric mode), or None
    when SuperLU pivoted rows off the diagonal."""
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return None
    d = _stored_diagonal(lu)
    return np.asarray(lu.U.diagonal(), float) if d is None else d


class _SuperMatrix(ctypes.Structure):       # SuperLU's SuperMatrix
    _fields_ = [("Stype", ctypes.c_int), ("Dtype", ctypes.c_int), ("Mtype", ctypes.c_int),
                ("nrow", ctypes.c_int), ("ncol", ctypes.c_int), ("Store", ctypes.c_void_p)]


class _LUObject(ctypes.Structure):          # the head of scipy's SuperLU object
    _fields_ = [("refcnt", ctypes.c_ssize_t), ("type", ctypes.c_void_p),
                ("m", ctypes.c_ssize_t), ("n", ctypes.c_ssize_t),
                ("L", _SuperMatrix), ("U", _SuperMatrix),
                ("perm_r", ctypes.c_void_p), ("perm_c", ctypes.c_void_p)]


class _Supernodal(ctypes.Structure):        # SuperLU's SCformat (the store of L)
    _fields_ = [("nnz", ctypes.c_int), ("nsuper", ctypes.c_int), ("nzval", ctypes.c_void_p),
                ("nzval_colptr", ctypes.c_void_p), ("rowind", ctypes.c_void_p),
                ("rowind_colptr", ctypes.c_void_p), ("col_to_sup", ctypes.c_void_p),
                ("sup_to_col", ctypes.c_void_p)]


_SLU_SC, _SLU_D, _SLU_TRLU = 3, 1, 1      # Stype, Dtype and Mtype of a double L


def _ints(address, n, kind=ctypes.c_int):
    return np.ctypeslib.as_array(ctypes.cast(address, ctypes.POINTER(kind)), shape=(n,))


def _stored_diagonal(lu):
    """The diagonal of ``U`` read from SuperLU's supernodal ``L`` (U's
    diagonal is stored with L's columns: entry ``j − fsupc`` of column j,
    fsupc the first column of j's supernode), or None when the object does
    not look as expected: its type and size, its dimensions, its ``perm_r`` pointer (the very
    array ``lu.perm_r`` shows), the type of ``L`` and, after reading, that
    the rows of every entry read are the columns' own."""
    kind = type(lu)
    if kind.__name__ != "SuperLU" or kind.__basicsize__ < ctypes.sizeof(_LUObject):
        return None
    try:
        n = int(lu.shape[0])
        perm_r = lu.perm_r
        head = _LUObject.from_address(id(lu))
        L = head.L
        if (head.m, head.n) != (n, n) or lu.shape != (n, n) or not n \
                or head.perm_r != perm_r.ctypes.data or perm_r.dtype.itemsize != 4 \
                or (L.Stype, L.Dtype, L.Mtype) != (_SLU_SC, _SLU_D, _SLU_TRLU) \
                or (L.nrow, L.ncol) != (n, n) or not L.Store:
            return None
        store = _Supernodal.from_address(L.Store)
        if not 0 <= store.nsuper < n or not all((store.nzval, store.nzval_colptr, store.rowind,
                                                 store.rowind_colptr, store.col_to_sup,
                                                 store.sup_to_col)):
            return None
        colptr = _ints(store.nzval_colptr, n + 1)
        rowptr = _ints(store.rowind_colptr, n + 1)
        sup = _ints(store.col_to_sup, n)
        if colptr[0] != 0 or rowptr[0] != 0 or np.any(np.diff(colptr) <= 0) \
                or np.any(np.diff(rowptr) < 0) or sup.min() < 0 or sup.max() > store.nsuper:
            return None
        first = _ints(store.sup_to_col, store.nsuper + 2)[sup]
        j = np.arange(n)
        at = colptr[:-1] + (j - first)
        where = rowptr[first] + (j - first)
        if np.any(first > j) or np.any(at >= colptr[1:]) or np.any(where >= rowptr[-1]):
            return None
        if not np.array_equal(_ints(store.rowind, int(rowptr[-1]))[where], j):
            return None
        return np.array(_ints(store.nzval, int(colptr[-1]), ctypes.c_double)[at])
    except (AttributeError, TypeError, ValueError, OverflowError):
        return None
