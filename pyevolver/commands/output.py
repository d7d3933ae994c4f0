"""Output commands: ``print``, ``printf``, ``errprintf``, ``list``,
``histogram``/``loghistogram``, ``v`` (``show_vol``), ``history`` and
``quit`` (``q``, ``bye``, ``exit``).
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import CommandError, UnsupportedError
from ..expr import nodes as N
from . import elements, listing
from .cformat import c_format, print_array, print_value
from .registry import register
from .values import Quit, as_float, as_int

FAMILY = "output"


@register("print", usage="print expr", statement="print", help="print a value",
          family=FAMILY)
def _x_print(interp, node):
    e = node[1]
    s = interp.session
    if isinstance(e, N.Var) and e.name in s.arrays and \
            not (interp.env.scopes and e.name in interp.env.scopes[-1]):
        s.write(print_array(s.arrays[e.name]) + "\n")
        return
    v = interp.value(e)
    if isinstance(v, N.ArrayValue):
        s.write(print_array(np.asarray(v)) + "\n")
        return
    s.write(print_value(v) + "\n")


@register("printf", "errprintf", usage='printf "format", expr, ...', statement="printf",
          help="print formatted (errprintf: to stderr)", family=FAMILY)
def _x_printf(interp, node):
    args = [interp.value(a) for a in node[1]]
    if not args or not isinstance(args[0], str):
        raise CommandError("printf needs a format string first")
    # REF prints a lone format string as it is ("%%" stays "%%": xray.cmd)
    if len(args) == 1 and "%" in args[0].replace("%%", ""):
        raise CommandError(f"{'ERR' if node[2] else ''}PRINTF string has formats, but "
                           "there are no arguments.")          # REF's ERROR 1928
    text = c_format(args[0], args[1:]) if len(args) > 1 else args[0]
    if node[2]:
        interp.session.write_err(text)
    else:
        interp.session.write(text)


@register("list", usage="list gen", statement="list",
          help="list elements in datafile format", family=FAMILY)
def _x_list(interp, node):
    gen = node[1]
    if gen.base[0] == "var" and interp.var_elem(gen.base[1]) is None:
        what = gen.base[1]
        if what in ("topinfo", "bottominfo", "procedures", "attributes", "quantities",
                    "method_instances", "constraints", "boundaries"):
            raise UnsupportedError(f"list {what}")
        raise CommandError(f"list: '{what}' is not an element (expected for example "
                           f"list vertex[3] or list facets where area > 0.1)")
    listing.list_elements(interp.session, node[1], interp.env)


@register("histogram", "loghistogram", usage="histogram(gen, expr)", statement="histogram",
          help="a histogram of values over elements", family=FAMILY)
def _x_histogram(interp, node):
    gen, expr, log = node[1], node[2], node[3]
    vals = []
    for el in elements.generate(interp.session, gen, interp.env):
        with interp.env.element(el, gen.var):
            v = interp.value(expr)
        vals.append(as_float(v, "a histogram value"))
    interp.session.write(histogram_text(vals, log))


@register("v", "show_vol", usage="v", help="bodies and quantities: targets, values, pressures",
          family=FAMILY)
def _v(interp, raw, arg):
    s = interp.session
    s.note(listing.show_vol(s))


@register("history", usage="history", arg="none", help="the saved commands",
          family=FAMILY)
def _history(interp, raw, arg):
    interp.session.show_history()


@register("q", "quit", "bye", "exit", usage="q [status]", help="leave pyevolver",
          family=FAMILY)
def _quit(interp, raw, arg):
    raise Quit(0 if arg is None else as_int(interp.value(arg), "the exit status") & 255)


def histogram_text(vals, log=False):
    """The ``histogram``/``loghistogram`` report: the Evolver's bins (21 equal
    bins from the least to the greatest value; 20 logarithmic bins over the
    positive values, with a ``<= 0.0`` line counting the others).  NaN
    values are counted on a last line ``NaN  n``, as REF does; with nothing
    else, REF's empty bins (from its initial bounds 1e38 and -1e38, which
    its logarithmic bins print as ``inf``).  Infinities are left out (REF
    stops on them)."""
    nan = sum(1 for v in vals if v != v)
    vals = [v for v in vals if math.isfinite(v)]
    if not vals and not nan:
        return "No qualifying values.\n"
    out = []
    tail = ["NaN          %d" % nan] if nan else []
    if log:
        nonpos = sum(1 for v in vals if v <= 0)
        vals = [v for v in vals if v > 0]
        if nonpos:
            out.append("          <= 0.0           %d" % nonpos)
        if not vals:
            if nan:
                out += ["%10.5g - %10.5g     0" % (math.inf, math.inf)] * 20
            return "\n".join(out + tail) + "\n"
    lo, hi = (min(vals), max(vals)) if vals else (1e38, -1e38)
    if vals and hi <= lo:
        out.append("%10.5g - %10.5g     %d" % (lo, hi, len(vals)))
        return "\n".join(out + tail) + "\n"
    nbins = 20 if log else 21
    if log:
        a, b = np.log(lo), np.log(hi)
        edges = [float(np.exp(a + (b - a) * k / nbins)) for k in range(nbins + 1)]
    else:
        edges = [lo + (hi - lo) * k / nbins for k in range(nbins + 1)]
    # a value on an edge counts in the bin below it (REF: 6 in 5.4286 - 6
    # when the values are 2..14)
    keys = np.searchsorted(np.array(edges[1:]), np.array(vals, dtype=float), side="left")
    counts = np.bincount(np.minimum(keys, nbins - 1), minlength=nbins).tolist()
    for k in range(nbins):
        out.append("%10.5g - %10.5g     %d" % (edges[k], edges[k + 1], counts[k]))
    return "\n".join(out + tail) + "\n"



@register("suppress_warning", "unsuppress_warning", usage="suppress_warning n",
          help="do not print (print again) the Evolver's warning number n", family=FAMILY)
def _suppress_warning(interp, raw, arg):
    if arg is None:
        raise CommandError(f"{raw} needs a warning number")
    n = interp.count(arg)
    off = interp.session.__dict__.setdefault("suppressed_warnings", set())
    if raw.lower() == "suppress_warning":
        off.add(n)
    else:
        off.discard(n)
