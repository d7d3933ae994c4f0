"""Element sections that are plain tables of numbers, read at once (issue 24).

A large datafile's element sections are usually tables: every line an id and
the same count of plain numbers (``make_icosphere.py``'s 81,920-facet sphere,
dumps of evolved surfaces).  :func:`numeric_table` recognises such a section
from the bytes of its text with a few array operations and converts it with
one ``np.fromstring``; the reader then stores it exactly as it stores the
lines it converts one by one (:meth:`ElementSections._bulk`).  Whenever the
section is anything else (a word, an expression, a ``+`` that continues a
value, a blank-separated irregular line, a non-ASCII character, a line
longer than the long-line limit, a small section) it returns None and the
line-by-line reader runs: what is accepted, and every message, is the same.
"""
from __future__ import annotations

import re
import warnings

import numpy as np

#: sections shorter than this go through the general line loop
MIN_CHARS = 4096

# byte classes: 0 other, 1 digit, 2 '.', 3 'e'/'E', 4 '+', 5 '-', 6 blank, 7 newline
_CLASS = np.zeros(256, np.uint8)
_CLASS[np.frombuffer(b"0123456789", np.uint8)] = 1
_CLASS[ord(".")] = 2
_CLASS[ord("e")] = _CLASS[ord("E")] = 3
_CLASS[ord("+")] = 4
_CLASS[ord("-")] = 5
_CLASS[ord(" ")] = _CLASS[ord("\t")] = 6
_CLASS[ord("\n")] = 7

# a line whose first token has a byte other than a digit (the section's
# bytes being of the classes above)
# (a line after a newline: a literal first character, which re searches fast)
_ID_NOT_DIGITS = re.compile(r"\n[ \t]*[0-9]*[^0-9 \t\n]")
_FIRST_ID_NOT_DIGITS = re.compile(r"[ \t]*[0-9]*[^0-9 \t\n]")


def numeric_table(text: str, first_line: int, line_map, long_line: int):
    """``(values, lens, src_lines)`` of a section whose non-blank lines each
    match the reader's plain-number line (an id of digits, then numbers
    separated by blanks) with the same count of numbers, or None.

    Parameters
    ----------
    text : str
        The section's text (lines separated by ``\\n``).
    first_line, line_map
        The source line of text line ``k``: ``line_map[k]`` when
        ``line_map`` is not empty, else ``first_line + k``.
    long_line : int
        Lines longer than this are left to the line-by-line reader.

    Returns
    -------
    values : (n * m,) float array, all numbers in reading order
    lens : (n,) int array, m numbers on each of the n lines
    src_lines : (n,) int array, the source line of each
    """
    if len(text) < MIN_CHARS or not text.isascii() or long_line >= 2 ** 16:
        return None
    raw = text.encode("ascii")
    cls = _CLASS[np.frombuffer(raw, np.uint8)]
    del raw                                            # (memory: one byte array at a time)
    if not cls.all():                                  # a byte of class 0: a letter etc.
        return None
    plus = np.flatnonzero(cls == 4)
    if len(plus) and (plus[0] == 0 or (cls[plus - 1] != 3).any()):
        return None                                    # a '+' outside an exponent
    start = cls < 6                                    # token starts: a non-blank after a blank
    start[1:] &= cls[:-1] >= 6
    newlines = np.flatnonzero(cls == 7)
    del cls
    bounds = np.concatenate((newlines, [len(start)]))
    if np.diff(bounds, prepend=-1).max() - 1 > long_line:
        return None
    begins = np.concatenate(([0], newlines + 1))       # the first byte of each text line
    counts = np.zeros(len(begins), np.int64)           # tokens on each line
    inside = begins < len(start)                       # (a last empty line has no byte)
    # (16 bits: a line has at most long_line bytes, so fewer than 2^16 tokens)
    counts[inside] = np.add.reduceat(start.view(np.uint8), begins[inside], dtype=np.uint16)
    del start, begins, inside
    used = np.flatnonzero(counts)
    if not len(used):
        return None
    m = counts[used[0]]
    if not (counts[used] == m).all():
        return None
    # the first token of each line (an id): digits only, so no '.', 'e', '+'
    # or '-' in it
    if _FIRST_ID_NOT_DIGITS.match(text) or _ID_NOT_DIGITS.search(text):
        return None
    try:
        values = floats_of(text)
    except ValueError:                                 # a token that is not a number
        return None
    if values.size != int(counts.sum()):               # a token that is not one number
        return None
    lens = np.full(len(used), m, np.int64)
    if line_map:
        src = np.asarray(line_map, np.int64)[used]
    else:
        src = first_line + used.astype(np.int64)
    return values, lens, src



def floats_of(text: str) -> np.ndarray:
    """``np.fromstring(text, dtype=float, sep=" ")``, the same numbers
    (ValueError for a token that is not one), faster for a text of integers:
    without '.', 'e', 'E' or "-0" it is read as integers (ten times faster)
    and converted, exact below 2^53 (else read again as floats)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                 # (older numpy: a warning, not an error)
        if "." not in text and "e" not in text and "E" not in text and "-0" not in text:
            try:
                ints = np.fromstring(text, dtype=np.int64, sep=" ")
            except ValueError:
                ints = None
            if ints is not None and (not ints.size or np.abs(ints).max() < 2 ** 53):
                return ints.astype(float)
        return np.fromstring(text, dtype=float, sep=" ")
