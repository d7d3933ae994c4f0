"""Undo of one command: :func:`snapshot` before it runs, :func:`restore`
when it fails, so that a failing command leaves the session as it was."""
from __future__ import annotations


def snapshot(session) -> tuple:
    """Copies of everything a command can change: variables, commands,
    arrays, toggles, settings, coordinates (shape (nv, 3)), body and quantity
    state, attributes, constraint memberships, the surface object itself."""
    s = session.surface
    b = s.bodies if s is not None else None
    return (dict(session.variables), dict(session.commands), dict(session.letters),
            {k: v.copy() for k, v in session.arrays.items()}, dict(session.toggles),
            dict(session.settings),
            None if s is None else s.X.copy(),
            None if b is None or not b.n else (b.target.copy(), b.pressure.copy(),
                                                b.volconst.copy(), b.density.copy(),
                                                b.lagrange.copy()),
            None if s is None else {k: (q.target, q.modulus, q.kind, q.pressure,
                                        q.tolerance, list(q.methods))
                                    for k, q in s.quantities.items()},
            None if s is None else {k: v.copy() for k, v in s.extra.items()},
            None if s is None else {k: v.copy() for k, v in s.vattr.items()},
            None if s is None else {k: v.copy() for k, v in s.eattr.items()},
            None if s is None else {k: v.copy() for k, v in s.fattr.items()},
            None if s is None else {k: m.copy() for k, m in s.vcon.items()},
            s, session.totals, session._iterator_state(),
            None if s is None else ({k: m.copy() for k, m in s.econ.items()},
                                    {k: m.copy() for k, m in s.fcon.items()},
                                    s.gravity_constant, s.sq_curvature_modulus),
            session.filename,
            {k: dict(v) for k, v in session.__dict__.get("_attr_store", {}).items()},
            _counters(session))


def _counters(session) -> tuple:
    """The session's own records a command changes: the history of ``g``
    steps, the counts (``equi_count``, ...), the iteration counter and
    total time, the random generator's state, the CG iterator object."""
    return (list(session.history), dict(session.counts), session.iteration_counter,
            session.total_time,
            None if session._rng is None else session._rng.bit_generator.state, session._iterator,
            session.__dict__.get("_last_motion"))


def restore(session, snap: tuple) -> None:
    """Put back the state of :func:`snapshot` (a failing or interrupted
    command leaves the session as it was)."""
    (vars_, cmds, letters, arrays, toggles, settings, X, bod, qs, extra, vattr, eattr,
     fattr, vcon, surface, totals, it_state, more, filename, attr_store, counters) = snap
    (history, counts, session.iteration_counter, session.total_time, rng_state,
     session._iterator, motion) = counters
    if motion is not None:
        session._last_motion = motion
    else:
        session.__dict__.pop("_last_motion", None)
    session.history[:] = history
    session.counts.clear()
    session.counts.update(counts)
    if rng_state is None:
        session._rng = None
    else:
        session.rng.bit_generator.state = rng_state
    session.filename = filename
    session._attr_store = attr_store          # graphics-only attributes (commands.attributes)
    session.surface = surface
    session.totals = totals            # the energies of the restored coordinates
    if session._iterator is not None:
        if it_state is None:
            session._iterator = None
        else:
            (session._iterator.cg_history, session._iterator.cg_S_old, session._iterator.cg_f_old,
             session._iterator.pressures_valid) = it_state
    session.variables.clear()
    session.variables.update(vars_)
    session.commands = cmds
    session.letters = letters
    session.arrays = arrays
    session.toggles = toggles
    session.settings = settings
    s = session.surface
    if s is not None:
        s.X = X
        if bod is not None:
            b = s.bodies
            b.target, b.pressure, b.volconst, b.density, b.lagrange = bod
        for k, (t, m, kind, p, tol, methods) in qs.items():
            q = s.quantities[k]
            q.target, q.modulus, q.kind, q.pressure, q.tolerance = t, m, kind, p, tol
            q.methods[:] = methods          # set/unset element membership
        s.extra = extra
        s.vattr = vattr
        s.eattr = eattr
        s.fattr = fattr
        s.vcon = vcon
        s.econ, s.fcon, s.gravity_constant, s.sq_curvature_modulus = more

# -- evaluation ------------------------------------------------------------------
