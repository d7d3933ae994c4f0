"""Resource limits: absurd inputs are refused with a message, not run until
memory or the stack runs out.

The values are far above what any real datafile or script needs (the
Evolver's own examples stay below a tenth of each) and low enough that the
largest thing they allow fits in a few hundred megabytes.
"""
from __future__ import annotations

from typing import Any

import numpy as np

#: largest element id (the Evolver keeps ids in a C ``int``; it allocates by
#: id, pyevolver does not, but an id beyond this is a corrupted file)
MAX_ID = 2**31 - 1

#: most edges around one face of a datafile (it is triangulated around a
#: centre vertex; the Evolver's examples use at most a few dozen)
MAX_FACE_EDGES = 100_000

#: most nested levels of one expression or command (parentheses, operators,
#: braces, ``if``/``while`` bodies): evaluation is recursive
MAX_NESTING = 200

#: most entries of one array: an element attribute over all elements, a
#: command-language array, the arrays a refinement would build
MAX_ARRAY_ENTRIES = 50_000_000

#: most elements (vertices, edges or facets) a command may create
MAX_ELEMENTS = 5_000_000

#: widest field (or precision) of a ``printf`` conversion
MAX_FORMAT_WIDTH = 10_000

#: longest string ``printf``/``sprintf`` may produce
MAX_STRING = 10_000_000

#: longest line a ``#define`` expansion may produce
MAX_EXPANDED_LINE = 100_000


#: longest piece of user text an error message quotes
MAX_QUOTE = 60


def clip(text: str, limit: int = MAX_QUOTE) -> str:
    """``text`` cut to ``limit`` characters with ``...`` (a 200,000-digit
    token is named in a message by its first characters)."""
    text = str(text)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def nesting_depth(tree: Any, limit: int = MAX_NESTING, flat: Any = None) -> int:
    """Depth of a parsed expression or command (an iterative walk: a tree
    too deep for Python's recursion is measured without recursing).

    ``tree`` may mix expression nodes (anything with ``children()``),
    tuples, lists and objects with ``_nested()``; strings and numbers are
    leaves.  The walk stops at ``limit + 1``.  ``flat``: a node class whose
    left operand (``.a``) counts at the node's own depth (a binary operator
    evaluated iteratively along left-deep chains: ``1+2+...+n`` is flat).
    """
    deepest = 0
    stack = [(tree, 1)]
    while stack:
        obj, d = stack.pop()
        if d > deepest:
            deepest = d
            if deepest > limit:
                return deepest
        if flat is not None and isinstance(obj, flat):
            stack.append((obj.a, d))
            kids = (obj.b,)
        elif isinstance(obj, (tuple, list)):
            kids = obj
        elif hasattr(obj, "children") and callable(obj.children):
            try:
                kids = obj.children()
            except TypeError:
                kids = ()
        elif hasattr(obj, "_nested"):
            kids = obj._nested()
        else:
            continue
        for k in kids:
            if isinstance(k, (str, bytes, int, float, np.generic)) or k is None:
                continue
            stack.append((k, d + 1))
    return deepest
