"""Datafile element ids -> array positions (elements are renumbered in
reading order), for :mod:`pyevolver.model.build`."""
from __future__ import annotations

import numpy as np

from ..errors import DatafileError


class Lazy:
    """Index-computed sequence (line numbers for error messages only)."""

    def __init__(self, fn):
        self.fn = fn

    def __getitem__(self, j):
        return self.fn(int(j))


class IdMap:
    """Datafile ids -> positions (elements are renumbered in reading order)."""

    def __init__(self, ids, what, filename, lines):
        self.ids = np.asarray(ids, dtype=np.int64)
        self.what = what
        self.filename = filename
        n = len(self.ids)
        if n and self.ids[0] == 1 and self.ids[-1] == n and \
                np.array_equal(self.ids, np.arange(1, n + 1)):
            self.sorted = self.order = None     # ids 1..n in order: position = id - 1
            return
        order = np.argsort(self.ids, kind="stable")
        self.sorted = self.ids[order]
        self.order = order
        dup = np.nonzero(self.sorted[1:] == self.sorted[:-1])[0]
        if len(dup):
            k = order[dup[0] + 1]
            raise DatafileError(f"{what} {self.ids[k]} is defined twice", filename, lines[k])

    def lookup(self, raw, lines, user, user_ids):
        raw = np.asarray(raw, dtype=np.int64)
        if not len(self.ids):
            if raw.size:
                raise DatafileError(f"{user} {user_ids[0]} refers to {self.what} "
                                    f"{int(raw.flat[0])}, but there are no {self.what}s",
                                    self.filename, lines[0])
            return raw
        if self.order is None:
            ok = (raw >= 1) & (raw <= len(self.ids))
        else:
            pos_c = np.searchsorted(self.sorted, raw)
            np.minimum(pos_c, len(self.sorted) - 1, out=pos_c)  # (in place: load memory)
            ok = self.sorted[pos_c] == raw
        if not ok.all():
            flat = np.nonzero(~ok.reshape(len(ok), -1).all(axis=-1) if ok.ndim > 1 else ~ok)[0][0]
            bad = raw[flat]
            bad = int(np.asarray(bad).flat[np.nonzero(~np.asarray(ok[flat]).reshape(-1))[0][0]]) \
                if np.ndim(bad) else int(bad)
            raise DatafileError(f"{user} {user_ids[flat]} refers to {self.what} {bad}, "
                                f"which is not defined", self.filename, lines[flat])
        return raw - 1 if self.order is None else self.order[pos_c]


def split_midpoints(data, vid: IdMap, lines, ids) -> tuple[list, np.ndarray]:
    """The edge rows of a QUADRATIC datafile: an edge may list its midpoint
    vertex third (manual, "Quadratic declaration").

    Returns
    -------
    rows : list of the (tail, head) ids of each edge
    mids : (ne,) int array, the midpoint's vertex index, -1 where none is listed
    """
    rows = [list(d) for d in data]
    raw = np.array([d[2] if len(d) == 3 else 0 for d in rows], np.int64)
    mids = np.full(len(rows), -1, np.int64)
    has = np.nonzero(raw)[0]
    if len(has):
        mids[has] = vid.lookup(raw[has], [lines[k] for k in has], "edge", [ids[k] for k in has])
    return [d[:2] if len(d) == 3 else d for d in rows], mids
