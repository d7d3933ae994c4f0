"""C ``printf`` semantics for the Evolver's ``printf`` and ``print``."""
from __future__ import annotations

import numpy as np

import math
import re

from .. import limits
from ..errors import CommandError

_SPEC = re.compile(r"%([-+ #0]*)(\*|\d+)?(?:\.(\*|\d+))?(?:hh|h|ll|l|L|q|j|z|t)?([diouxXeEfFgGcs%])")


def _to_int(v):
    if isinstance(v, str):
        raise CommandError(f"printf: expected a number, got string {v!r}")
    v = float(v)
    if math.isnan(v) or math.isinf(v):
        return 0
    return int(v)  # C conversion truncates toward zero


def c_format(fmt, args):
    """Format ``args`` with the C format string ``fmt``."""
    out = []
    pos = 0
    ai = 0
    args = list(args)

    def take():
        nonlocal ai
        if ai >= len(args):
            raise CommandError(f"printf: not enough arguments for format {fmt!r}")
        v = args[ai]
        ai += 1
        if isinstance(v, np.ndarray):
            if v.size != 1:
                raise CommandError(f"printf: argument {ai} is an array of shape "
                                   f"{list(v.shape)}, not a number")
            v = v.reshape(()).item()
        return v

    for m in _SPEC.finditer(fmt):
        out.append(fmt[pos:m.start()])
        pos = m.end()
        flags, width, prec, conv = m.groups()
        if conv == "%":
            out.append("%")
            continue
        if width == "*":
            w = _to_int(take())
            if w < 0:                   # C: a negative width means left-justified
                flags += "-"
            width = str(abs(w))
        if prec == "*":
            p = _to_int(take())
            prec = None if p < 0 else str(p)      # C: as if the precision were omitted
        for part in (width, prec):
            if part is not None and abs(int(part)) > limits.MAX_FORMAT_WIDTH:
                raise CommandError(f"printf: field width or precision {part} is more than "
                                   f"the {limits.MAX_FORMAT_WIDTH} allowed")
        spec = "%" + flags + (width or "") + ("." + prec if prec is not None else "")
        v = take()
        if conv in "di":
            out.append((spec + "d") % _to_int(v))
        elif conv in "ouxX":
            n = _to_int(v)
            if n < 0:
                n &= (1 << 32) - 1
            out.append((spec + conv) % n)
        elif conv == "c":
            out.append((spec + "c") % chr(_to_int(v) & 0xFF))
        elif conv == "s":
            if not isinstance(v, str):
                v = "%g" % v
            out.append((spec + "s") % v)
        else:
            if isinstance(v, str):
                raise CommandError(f"printf: expected a number for %{conv}, got string {v!r}")
            out.append((spec + conv) % float(v))
    out.append(fmt[pos:])
    text = "".join(out)
    if len(text) > limits.MAX_STRING:
        raise CommandError(f"printf: the result has {len(text)} characters, more than the "
                           f"{limits.MAX_STRING} allowed")
    return text


def print_array(a):
    """``print array``: nested braces, numbers ``%2.15g`` (REF layout)."""
    fmt = "%d" if np.issubdtype(np.asarray(a).dtype, np.integer) else "%2.15g"

    def row(x, depth):
        if x.ndim == 1:       # integer arrays (v_constraint_list) as REF: %d
            return "{" + ",".join(v if isinstance(v, str) else fmt % v for v in x) + "}"
        return "{" + (",\n" + " " * (depth + 1)).join(row(y, depth + 1) for y in x) + "}"
    return row(a, 0)


def print_value(v):
    """``print expr``: numbers with ``%20.15g``, strings as they are."""
    if isinstance(v, str):
        return v
    if isinstance(v, int):              # integer-typed attributes print as integers (REF)
        return "%d" % v
    return "%20.15g" % float(v)
