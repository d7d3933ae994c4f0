"""Quantity methods, registered under their Evolver names, and the energy
assembly (:mod:`pyevolver.methods.totals`).

One entry per method in :mod:`pyevolver.methods.registry` holds its value,
gradient and Hessian; one module per method family registers its entries
at import: :mod:`~pyevolver.methods.basic` (areas, volumes, lengths,
integrals), :mod:`~pyevolver.methods.curvature` (+ ``curvature_hessian``),
:mod:`~pyevolver.methods.harmonic`, :mod:`~pyevolver.methods.loop`,
:mod:`~pyevolver.methods.elastic` (stretching energies of facets),
:mod:`~pyevolver.methods.springs` (``hooke_energy`` and relatives, ``dihedral_hooke``),
:mod:`~pyevolver.methods.knots` (knot energies),
:mod:`~pyevolver.methods.string_curvature` (``sqcurve_string`` and relatives).
:func:`register_method` is public, so a user can add methods::

    from pyevolver.methods import register_method
    register_method("my_area", "facet", lambda ctx, m, idx: ctx.facet_area[idx])
"""
from __future__ import annotations

from . import (basic, curvature_hessian, elastic, gauss_integral, harmonic,  # noqa: F401
               knots, loop, springs, string_curvature)  # (they register)
from . import quadratic as _quadratic  # noqa: F401  (the quadratic model's totals and methods)
from . import string as _string  # noqa: F401  (registers the string model's totals)
from . import ndim as _ndim  # noqa: F401  (the totals of SPACE_DIMENSION > 3)
from . import simplex as _simplex  # noqa: F401  (the simplex model's totals)
from .registry import (CURVATURE_METHODS, GRADIENTS, HESSIANS, METHODS, NO_HESSIAN, REGISTRY,
                       Method, lookup, method_info, register_method)
from .totals import Totals, evaluate

__all__ = ["CURVATURE_METHODS", "GRADIENTS", "HESSIANS", "METHODS", "NO_HESSIAN", "REGISTRY",
           "Method", "lookup", "method_info", "register_method", "Totals", "evaluate"]
