"""``fix``/``unfix`` of elements (their ``fixed`` attribute) and of
quantities (a quantity fixed at its current value)."""
from __future__ import annotations

from ..errors import CommandError, UnsupportedError
from . import element_attrs, elements
from .registry import register
from .values import ElemRef, SessionLike


def fix_elements(session: SessionLike, els, on):
    """``fix``/``unfix`` elements; returns how many changed."""
    n = 0
    for el in els:
        if el.kind == "body":
            raise CommandError("cannot fix or unfix bodies; to fix a volume use "
                               "'set body target expr', to free it 'unset body target'")
        old = element_attrs.get_attr(session, el, "fixed", None)
        if bool(old) != bool(on):
            element_attrs.set_attr(session, el, "fixed", None, 1.0 if on else 0.0)
            n += 1
    return n


def fix_name(session: SessionLike, name, on):
    """``fix quantity`` / ``unfix quantity``."""
    s = session.surface
    if name in s.quantities:
        q = s.quantities[name]
        if on:
            q.target = float(session.totals.quantity_values[name])
            q.kind = "fixed"
        else:
            q.kind = "info_only" if q.kind == "fixed" else q.kind
        return
    if name in session.variables and isinstance(session.variables[name], (int, float)):
        # manual: "unfix radius" makes a parameter optimizing, "fix radius" plain
        # again; its PDELTA / PSCALE are kept (pyevolver.evolve.optparams)
        opt = s.__dict__.setdefault("optimizing", {})
        keep = s.__dict__.setdefault("param_deltas", {})
        if on and name in opt:
            keep[name] = opt.pop(name)
        elif not on and name not in opt:
            opt[name] = keep.pop(name, (1e-4, 1.0))
        return
    if name in session.variables:
        raise UnsupportedError(f"{'fix' if on else 'unfix'} {name} (a string variable)")
    raise CommandError(f"{'fix' if on else 'unfix'}: '{name}' is not a quantity "
                       f"(expected: fix element_generator or fix quantity_name)")


# -- the commands -----------------------------------------------------------------------
@register("fix", "unfix", usage="fix gen | fix QUANTITY (unfix alike)", statement="fix",
          help="fix or free elements, or fix a quantity at its value", family="fixing")
def _x_fix(interp, node):
    gen, on = node[1], node[2]
    s = interp.session
    if gen.base[0] == "var" and gen.where is None and \
            not isinstance(interp.var_elem(gen.base[1]), ElemRef):
        fix_name(s, gen.base[1], on)
        return
    els = elements.generate(s, gen, interp.env)
    n = fix_elements(s, els, on)
    # REF reports the elements fixed and unfixed by a whole command at
    # its end ("Fixed: N" then "Unfixed: M", nonzero counts only)
    s.report("Fixed" if on else "Unfixed", n)


@register("fix", "unfix", usage="fix QUANTITY | unfix QUANTITY", statement="fix_name",
          help="fix a quantity at its value, or free it", family="fixing")
def _x_fix_name(interp, node):
    fix_name(interp.session, node[1], node[2])
