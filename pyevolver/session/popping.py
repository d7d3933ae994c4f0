"""What ``g`` does after each move when ``autopop`` / ``autochop`` are on
(manual: the toggles ``autopop``, ``autochop``; measured on evolver-nox-d).

After the move (and the restoring), in this order:

- autopop (string model): the edges whose length is now below the critical
  length ``sqrt(2 * scale)`` are deleted (their ends merged, edge order),
  then every vertex with more than three edges is popped as by ``o``
  (:mod:`pyevolver.remesh.string_pop`); REF prints
  ``Autopopped N edges, M vertices.`` when N > 0.  The threshold was
  measured on a symmetric junction pair: the length after the move, not a
  further prediction; only edges the motion shortens (first order in the
  velocity) are deleted: 100grain.fe's tiny growing edges stay.
- autochop: the edges whose predicted length after one more move with the
  same velocity, ``|e| + scale * (e/|e|) . (v_head - v_tail)``, exceeds
  ``autochop_length`` are bisected ("Autochopped N edges.").  The predicted
  form was measured on a triple junction whose two edges grow (the
  threshold is that first-order length to 8 digits, neither the current
  length nor the exact next one).

The energies of the progress line are those after both.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import UnsupportedError
from ..remesh.edge_divide import edge_divide
from ..remesh.string import split_edges
from ..remesh import string_pop as SP


def check_supported(session) -> None:
    """Refuse by name the autopop cases not implemented (before any step)."""
    if not session.toggles.get("autopop"):
        return
    s = session.surface
    if s is not None and not s.string:
        raise UnsupportedError("g with autopop on in the soapfilm model",
                               "only the string model's edge deletion and vertex popping "
                               "are implemented")
    if session.toggles.get("autopop_quartic") or session.toggles.get("immediate_autopop"):
        raise UnsupportedError("autopop_quartic / immediate_autopop", "not implemented")


def _velocity(r, s):
    m = getattr(r, "motion", None)
    if m is None or len(m) < 4 or m[3] is None or len(m[3]) != s.nv:
        return None
    return m[3]


def keep_stale(session, stale) -> None:
    """Put back REF's stale totals after a recalc of the same surface
    (see :func:`after_move`); any change of the surface ends them."""
    if stale is None:
        return
    surf, X, vals = stale
    if surf is session.surface and surf.X.shape == X.shape and np.array_equal(surf.X, X):
        tt = session.totals
        tt.energy, tt.total_area, tt.total_length = vals
        session._stale_totals = stale


def _chop_candidates(session, vel, scale):
    """Ids of the edges autochop will bisect (None when autochop is off)."""
    L = session.settings.get("autochop_length", 0.0)
    if not (session.toggles.get("autochop") and L > 0):
        return None
    s = session.surface
    if vel is not None and len(vel) == s.nv:
        pred = SP.predicted_lengths(s, vel, scale)
    else:
        pred = SP.after_move_lengths(s)
    return s.ids("edge")[pred > L]


def after_move(session, r) -> None:
    """Autopop, then autochop, on the surface after the step ``r``.  The
    edges to chop are chosen before the deletions (100grain.fe ``r; g 10``:
    an edge made long by a merge waits for the next step); those deleted
    are passed over."""
    scale = float(r.scale)
    vel = _velocity(r, session.surface)
    chop_ids = _chop_candidates(session, vel, scale)
    stale_vals = None
    if session.toggles.get("autopop") and session.surface.string and scale > 0:
        s = session.surface
        crit = math.sqrt(2.0 * scale)
        now = SP.after_move_lengths(s)
        short = now < crit
        if vel is not None and short.any():
            # only the edges the motion does not lengthen: e . (v_head - v_tail)
            # <= 0 with e the edge after the move (100grain.fe: its growing
            # tiny edges stay, its still ones inside a straight chain go)
            short &= SP.stretch_rates(s, vel) <= 0.0
        if short.any():
            t, ned, _vmap = SP.delete_short_edges(s, crit, np.nonzero(short)[0])
            if ned:
                old = session.totals
                stale = (old.energy, old.total_area, old.total_length)
                t, npop = SP.pop_vertices(t)
                session._replace_surface(t)
                if not npop:
                    # REF recomputes its totals after the deletions only when a
                    # vertex was popped: until the next step (or recalc) its
                    # total_energy / total_area / total_length are those from
                    # before them (100grain.fe r; g 10, measured)
                    stale_vals = stale
                r.warnings.append(f"Autopopped {ned} edges, {npop} vertices.")
                if npop and r.printed:
                    # REF's line shows the energy after the deletions only when
                    # vertices were popped too (100grain.fe r; g 10: steps 7 and 6)
                    r.energy, r.area = session.totals.energy, session.totals.total_area
                    if session.history:
                        session.history[-1] = (session.history[-1][0], r.energy, r.area)
    if chop_ids is not None and len(chop_ids):
        s = session.surface
        chop = np.nonzero(np.isin(s.ids("edge"), chop_ids))[0]
        if len(chop):
            if s.string:
                session._replace_surface(split_edges(s, chop))
                # REF's count includes the chosen edges autopop deleted
                # (100grain.fe m 0.05; g 1: "Autochopped 300 edges.", 299 new vertices)
                nch = len(chop_ids)
            else:
                new, nch = edge_divide(s, chop)
                session._replace_surface(new)
            r.warnings.append(f"Autochopped {nch} edges.")
    if stale_vals is not None:
        keep_stale(session, (session.surface, session.surface.X.copy(), stale_vals))
