"""What ``g`` does after each move when ``autopop`` / ``autochop`` are on
(manual: the toggles ``autopop``, ``autochop``; measured on evolver-nox-d).

After the move (and the restoring), in this order:

- autopop (string model): the edges whose length is now below the critical
  length ``sqrt(2 * scale)`` and that the motion does not lengthen,
  ``e . (v_head - v_tail) <= 0`` with ``e`` the edge after the move (found
  per edge on 100grain.fe ``r; r; g 1``: the still edges inside straight
  chains go, the growing tiny edges stay), are deleted (their ends merged,
  id order), cells left with two sides dissolved, then every vertex with
  more than three edges is popped as by ``o``
  (:mod:`pyevolver.remesh.string_pop`); REF prints
  ``Autopopped N edges, M vertices.`` when N > 0.
- autochop: the edges whose predicted length after one more move with the
  same velocity, ``|e| + scale * (e/|e|) . (v_head - v_tail)``, exceeds
  ``autochop_length`` are bisected ("Autochopped N edges.").  The predicted
  form was measured on a triple junction whose two edges grow (the
  threshold is that first-order length to 8 digits, neither the current
  length nor the exact next one).  The count printed is that of the
  chosen edges, those autopop deleted included; after a step that
  dissolved a cell the new elements take the freed ids as REF's
  (:func:`_chop_reusing_ids`).

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


def _chop_reusing_ids(s, chop_ids, session):
    """Autochop as REF after a step whose autopop dissolved a cell (100grain.fe
    ``m 0.05; g 2``): REF's new halves and midpoints take the freed ids,
    largest first (then new ones), and its list of chosen edge ids, visited
    in increasing order, bisects a half that took a chosen id not yet
    visited a second time.  The new elements get REF's ids."""
    pool = sorted(session._freed_edge_ids, reverse=True)
    vpool = sorted(getattr(session, "_freed_vertex_ids", set()), reverse=True)
    alive = set(s.ids("edge").tolist())
    e0, v0 = int(s.ids("edge").max()) + 1, int(s.ids("vertex").max()) + 1
    virt = {}                       # REF's id of a new half -> pyevolver's id
    order = []
    nxt = e0
    for c in sorted(int(x) for x in chop_ids):
        if c in alive:
            order.append(c)
        elif c in virt:
            order.append(virt.pop(c))
        else:
            continue
        if pool:
            virt[pool.pop(0)] = nxt
        nxt += 1
    # bisect in REF's order, a batch at a time (a half exists once made)
    k = 0
    while k < len(order):
        have = set(s.ids("edge").tolist())
        j = k
        while j < len(order) and order[j] in have:
            j += 1
        pos = {int(i): n for n, i in enumerate(s.ids("edge").tolist())}
        s = split_edges(s, np.array([pos[i] for i in order[k:j]], np.int64))
        k = j
    n = len(order)
    ep = sorted(session._freed_edge_ids, reverse=True)[:n]
    vp = vpool[:n]
    eid = s.eattr["id"] = s.ids("edge").copy()
    vid = s.vattr["id"] = s.ids("vertex").copy()
    eid[-n:] = ep + list(range(e0, e0 + n - len(ep)))
    vid[-n:] = vp + list(range(v0, v0 + n - len(vp)))
    session._freed_edge_ids = set(sorted(session._freed_edge_ids, reverse=True)[n:])
    session._freed_vertex_ids = set(vpool[n:])
    return s


def after_move(session, r) -> None:
    """Autopop, then autochop, on the surface after the step ``r``.  The
    edges to chop are chosen before the deletions (100grain.fe ``r; g 10``:
    an edge made long by a merge waits for the next step); those deleted
    are passed over."""
    scale = float(r.scale)
    vel = _velocity(r, session.surface)
    chop_ids = _chop_candidates(session, vel, scale)
    stale_vals = None
    reuse = False
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
                freed = set(s.ids("edge").tolist()) - set(t.ids("edge").tolist())
                session._freed_edge_ids = getattr(session, "_freed_edge_ids", set()) | freed
                vfreed = set(s.ids("vertex").tolist()) - set(t.ids("vertex").tolist())
                session._freed_vertex_ids = getattr(session, "_freed_vertex_ids", set()) | vfreed
                reuse = t.n_facets < s.n_facets
                old = session.totals
                stale = (old.energy, old.total_area, old.total_length)
                t, npop = SP.pop_vertices(t)
                if npop:
                    # REF's new ids go on from the largest ever used (a deleted
                    # largest id is not taken again in the step)
                    for key, n0 in (("vertex", int(s.ids("vertex").max())),
                                    ("edge", int(s.ids("edge").max()))):
                        attrs = t.vattr if key == "vertex" else t.eattr
                        ids = attrs["id"] = t.ids(key).copy()
                        ids[-npop:] = np.arange(n0 + 1, n0 + 1 + npop)
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
            if s.string and reuse:
                session._replace_surface(_chop_reusing_ids(s, chop_ids, session))
                nch = len(chop_ids)
            elif s.string:
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
