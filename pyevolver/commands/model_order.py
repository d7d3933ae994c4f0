"""The model-order commands: ``M 1`` / ``linear``, ``M 2`` / ``quadratic``
(manual, "Model" chapter), and ``lagrange``, refused by name.

The messages are REF's: ``Changing to QUADRATIC model. (was LINEAR)``,
``Model already QUADRATIC.`` (``M 2``; ``quadratic`` and ``linear`` say
nothing when the model does not change).
"""
from __future__ import annotations

from ..errors import CommandError, UnsupportedError
from ..remesh.quadratic import to_linear, to_quadratic
from .registry import register
from .values import SessionLike

FAMILY = "model"
_NAMES = {1: "LINEAR", 2: "QUADRATIC"}
LAGRANGE_REASON = ("the Lagrange model (higher-order elements, named quantities only) is not "
                   "implemented; the quadratic model (M 2) is")


def set_order(session: SessionLike, order: int, quiet_same: bool = False) -> None:
    """Convert the session's surface to the linear (1) or quadratic (2) model."""
    s = session.surface
    if order not in (1, 2):
        raise UnsupportedError(f"M {order}", LAGRANGE_REASON)
    if s.order == order:
        if not quiet_same:
            session.note(f"Model already {_NAMES[order]}.\n")
        return
    new = to_quadratic(s) if order == 2 else to_linear(s)
    session.note(f"Changing to {_NAMES[order]} model. (was {_NAMES[s.order]})\n")
    session._replace_surface(new)


@register("M", usage="M 1 | M 2", help="the linear (1) or quadratic (2) model", family=FAMILY)
def _m(interp, raw, arg):
    if arg is None:
        raise CommandError("M needs the model order (for example: M 2)")
    set_order(interp.session, interp.count(arg))


@register("quadratic", usage="quadratic", help="the quadratic model (M 2)", family=FAMILY,
          arg="none")
def _quadratic(interp, raw, arg):
    set_order(interp.session, 2, quiet_same=True)


@register("linear", usage="linear", help="the linear model (M 1)", family=FAMILY, arg="none")
def _linear(interp, raw, arg):
    set_order(interp.session, 1, quiet_same=True)


@register("lagrange", usage="(refused)", help="the Lagrange model: refused by name",
          family=FAMILY)
def _lagrange(interp, raw, arg):
    raise UnsupportedError("lagrange", LAGRANGE_REASON)
