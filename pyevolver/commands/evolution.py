"""Evolution commands: ``g``, ``m``, ``optimize``, ``bfgs``, ``newton``,
``hessian``, ``hessian_seek``, ``U``, ``G``, ``recalc`` and
``convert_to_quantities``.  The steps themselves are the session's
(:meth:`Session.go`, :meth:`Session.bfgs`, ...); these handlers read the
arguments and print REF's messages.
"""
from __future__ import annotations

from ..errors import CommandError
from ..evolve import optparams as OP
from ..model.groups import group_of
from . import fresh
from .registry import register
from .values import as_float

FAMILY = "evolution"


@register("g", usage="g [n] | gN", help="n iteration steps (default 1)", family=FAMILY)
def _g(interp, raw, arg):
    n = int(raw[1:]) if len(raw) > 1 else (1 if arg is None else interp.count(arg))
    s = interp.session
    before = s.totals
    s.go(n)
    if s.totals is not before and not (s.toggles.get("autopop") or s.toggles.get("autochop")):
        # the last step's evaluation of its final move is the surface's (the
        # same numbers as a new one): the check after the command need not
        # evaluate again, unless autopop or autochop changed the surface
        fresh.mark(s)


@register("m", usage="m scale", help="fix the scale factor of g", family=FAMILY)
def _m(interp, raw, arg):
    s = interp.session
    if arg is None:
        raise CommandError("m needs a scale value (for example: m 0.1)")
    v = as_float(interp.value(arg), f"the argument of {raw}")
    s.settings["scale"] = v
    s.toggles["_fixed_scale"] = 1
    s.note("Scale fixed at %g.\n" % v)


@register("optimize", "optimise", usage="optimize [bound]",
          help="optimize the scale factor of g (at most bound)", family=FAMILY)
def _optimize(interp, raw, arg):
    s = interp.session
    if arg is not None:
        s.settings["scale_limit"] = as_float(interp.value(arg), f"the argument of {raw}")
    s.toggles["_fixed_scale"] = 0
    s.note("Scale optimizing with bound %g.\n" % s.settings["scale_limit"])


@register("bfgs", usage="bfgs [n]", help="n BFGS iterations (nonsmooth energies)",
          family=FAMILY)
def _bfgs(interp, raw, arg):
    OP.refuse(interp.session.surface, "bfgs")
    interp.session.bfgs(1 if arg is None else interp.count(arg))


@register("newton", usage="newton [n]", help="n damped Newton steps", family=FAMILY)
def _newton(interp, raw, arg):
    OP.refuse(interp.session.surface, "newton")
    interp.session.newton(1 if arg is None else interp.count(arg))


@register("hessian", "hessian_seek", usage="hessian | hessian_seek [max]",
          help="one Newton step; with _seek, a line search along it", family=FAMILY)
def _hessian(interp, raw, arg):
    s = interp.session
    name = raw.lower()
    OP.refuse(s.surface, name)
    if name == "hessian_seek" and arg is not None:
        s.hessian(seek=True, max_scale=as_float(interp.value(arg), f"the argument of {raw}"))
    else:
        s.hessian(seek=name == "hessian_seek")


@register("U", usage="U", help="toggle conjugate gradient", family=FAMILY)
def _conj_grad(interp, raw, arg):
    s = interp.session
    old = s.toggles.get("conj_grad", 0)
    s.toggles["conj_grad"] = 0 if old else 1
    s.reset_cg()
    s.note(f"Conjugate gradient now {'OFF' if old else 'ON'}. (was {'on' if old else 'off'})\n")


@register("G", usage="G [constant]", help="gravity on (with a constant) or off",
          family=FAMILY)
def _gravity(interp, raw, arg):
    s = interp.session
    old_on = s.toggles.get("gravity", 0)
    if arg is not None:
        s.surface.gravity_constant = as_float(interp.value(arg), f"the argument of {raw}")
    g = s.surface.gravity_constant
    s.toggles["gravity"] = int(g != 0)
    was = "on" if old_on else "off"
    if g != 0:
        s.note(f"Gravity is now ON with gravitational constant {g:g}. (was {was})\n")
    else:
        s.note(f"Gravity is now OFF. (was {was})\n")
    s.recalc()


@register("recalc", usage="recalc", help="recompute energies (vertices repositioned)",
          family=FAMILY)
def _recalc(interp, raw, arg):
    interp.session.recalc(reposition=True)


@register("convert_to_quantities", usage="convert_to_quantities", arg="none",
          help="compute energies as named quantities (the numbers are the same)",
          family=FAMILY)
def _convert(interp, raw, arg):
    # REF's dump writes it in the read section of files that used
    # named-quantity energies; pyevolver computes the same numbers
    # either way, so only the message is kept.
    # REF converts at load a surface whose boundaries carry integrals
    s = interp.session
    bnd = getattr(s.surface, "boundaries", None) or {}
    # and, in a symmetry group other than the torus (model.groups), every surface
    if s.toggles.get("_all_quantities") or any(b.energy or b.content for b in bnd.values()) \
            or group_of(s.surface) is not None:
        s.note("Everything already quantities.\n")
    else:
        s.toggles["_all_quantities"] = 1
        s.note("Converting to all named quantities...Done.\n")
