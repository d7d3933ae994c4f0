"""The lines of a datafile's text, kept for the excerpts of error messages.

A 7 MB datafile has a quarter of a million lines; as a list of strings
they took 21 MB for the whole session (issue 24: load memory).
:class:`SourceLines` keeps the text itself and finds a line when asked
(``lines[k]``, ``len(lines)``, as for the list it replaces).
"""
from __future__ import annotations

import numpy as np


class SourceLines:
    """The ``\\n``-separated lines of ``text`` (``\\r\\n`` and ``\\r``
    count as ``\\n``), indexed like a list."""

    def __init__(self, text: str):
        if "\r" in text:
            text = text.replace("\r\n", "\n").replace("\r", "\n")
        self.text = text
        self._n = text.count("\n") + 1
        self._starts: np.ndarray | None = None
        self._list: list[str] | None = None

    def __len__(self) -> int:
        return self._n

    def __bool__(self) -> bool:
        return True                     # (a text has at least one line, maybe empty)

    def __getitem__(self, k):
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(self._n))]
        k = int(k)
        if k < 0:
            k += self._n
        if not 0 <= k < self._n:
            raise IndexError("line index out of range")
        if self._list is not None:
            return self._list[k]
        if self._starts is None:
            if not self.text.isascii():     # character offsets: the list itself
                self._list = self.text.split("\n")
                return self._list[k]
            nl = np.flatnonzero(np.frombuffer(self.text.encode("ascii"), np.uint8) == 10)
            self._starts = np.concatenate(([0], nl + 1))
        a = int(self._starts[k])
        b = int(self._starts[k + 1]) - 1 if k + 1 < self._n else len(self.text)
        return self.text[a:b]

    def __iter__(self):
        return (self[k] for k in range(self._n))

    def __eq__(self, other):
        return list(self) == list(other)

    def __repr__(self) -> str:
        return f"SourceLines({self._n} lines)"
