"""The registry of quantity methods: one entry per method name, holding its
value, gradient and Hessian together.

A method computes one value per element it applies to; a quantity's value
is ``modulus * sum``.  :func:`register_method` is public, so a user can add
methods::

    from pyevolver.methods import register_method
    register_method("my_area", "facet", lambda ctx, m, idx: ctx.facet_area[idx])

``value(ctx, method, idx)`` gets the evaluation context (the cached geometry
of :class:`pyevolver.methods.totals.Totals`), the
:class:`pyevolver.model.scene.MethodDecl` and the element indices, and returns
an array of per-element values (orientation signs are applied by the caller).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Callable, Iterator

from ..errors import UnsupportedError
from ..model.surface import HOOKS


@dataclass(frozen=True)
class Method:
    """One quantity method.

    Attributes
    ----------
    name : str
        The Evolver's name (lower case).
    etype : str
        ``"vertex"``, ``"edge"`` or ``"facet"``: the elements it sums over.
    value : callable
        ``value(totals, decl, idx) -> (n,)`` per-element values.
    gradient : callable or None
        ``gradient(totals, decl, idx, w) -> (nv, 3)``: gradient of
        ``Σ_i w_i value_i``; None when ``g`` cannot use the method.
    hessian : callable or None
        ``hessian(totals, decl, idx, w, basis=None) -> sparse (3nv, 3nv)``
        (or ``Tᵀ H T`` on a basis); None: the Hessian is taken by finite
        differences of the gradient.
    no_hessian : str or None
        Why ``hessian`` refuses the method (no finite differences either).
    hessian_applies : callable or None
        ``hessian_applies(surface) -> bool``: False where ``hessian`` does not
        apply (finite differences instead); None: it always applies.
    """

    name: str
    etype: str
    value: Callable[..., Any]
    gradient: Callable[..., Any] | None = None
    hessian: Callable[..., Any] | None = None
    no_hessian: str | None = None
    hessian_applies: Callable[[Any], bool] | None = None


REGISTRY: dict[str, Method] = {}
# the variants of the quadratic model (:mod:`pyevolver.methods.quadratic`);
# a method missing here is refused by name in that model
QUADRATIC: dict[str, Method] = {}

# Evolver methods pyevolver knows by name but does not implement (yet).
CURVATURE_METHODS = {
    "sq_mean_curvature", "eff_area_sq_mean_curvature", "normal_sq_mean_curvature",
    "star_sq_mean_curvature", "star_eff_area_sq_mean_curvature",
    "star_normal_sq_mean_curvature", "star_perp_sq_mean_curvature",
    "mix_sq_mean_curvature", "mean_curvature_integral", "mean_curvature_integral_a",
    "sq_gauss_curvature", "star_gauss_curvature", "gauss_curvature_integral",
    "sqcurve_string",
}


_NOT_YET = {
    "mix_sq_mean_curvature": "the Evolver 2.70 has no such method (DATAFILE ERROR 1559), "
                             "so there is no reference for its formula",
}


def register_method(name: str, etype: str, fn: Callable, gradient: Callable | None = None,
                    hessian: Callable | None = None, *, no_hessian: str | None = None,
                    hessian_applies: Callable | None = None, model: str = "linear") -> Method:
    """Register method ``name`` on elements ``etype`` (see :class:`Method`);
    ``model="quadratic"`` registers its variant for the quadratic model.

    Returns
    -------
    Method
        The registry entry (replacing any earlier one of that name).
    """
    key = name.lower()
    entry = Method(key, etype, fn, gradient, hessian, no_hessian, hessian_applies)
    if model == "quadratic":
        QUADRATIC[key] = entry
        return entry
    REGISTRY[key] = entry
    CURVATURE_METHODS.discard(key)
    return entry


def lookup(name: str, model: str = "linear") -> Method:
    """The registry entry of method ``name`` (its variant of the quadratic
    model with ``model="quadratic"``).

    Raises
    ------
    UnsupportedError
        For a method pyevolver does not implement (in that model).
    """
    if model == "quadratic":
        if name in QUADRATIC:
            return QUADRATIC[name]
        lookup(name)
        raise UnsupportedError(f"method {name} in the quadratic model",
                               "pyevolver has not matched the Evolver's quadratic version")
    try:
        return REGISTRY[name]
    except KeyError:
        if name in CURVATURE_METHODS:
            raise UnsupportedError(f"method {name}", _NOT_YET.get(
                name, "this curvature energy is not implemented")) from None
        raise UnsupportedError(f"method {name}") from None


def method_info(name: str) -> tuple[str, Callable]:
    """``(etype, value function)`` of method ``name`` (see :func:`lookup`)."""
    m = lookup(name)
    return m.etype, m.value


class _View(Mapping):
    """A read-only view of one field of the registry (the entries that have it)."""

    def __init__(self, get: Callable[[Method], Any]):
        self._get = get

    def __getitem__(self, name: str) -> Any:
        v = self._get(REGISTRY[name])
        if v is None:
            raise KeyError(name)
        return v

    def __iter__(self) -> Iterator[str]:
        return (k for k, m in REGISTRY.items() if self._get(m) is not None)

    def __len__(self) -> int:
        return sum(1 for _ in self)


METHODS = _View(lambda m: (m.etype, m.value))      # name -> (etype, value)
GRADIENTS = _View(lambda m: m.gradient)            # name -> gradient
HESSIANS = _View(lambda m: m.hessian)              # name -> hessian
NO_HESSIAN = _View(lambda m: m.no_hessian)         # name -> why hessian refuses it

HOOKS.method_etype = lambda name: lookup(name).etype
