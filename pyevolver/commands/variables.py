"""Variables and internal names: assignment (:func:`set_variable`, with
the read-only names and numeric settings) and the value of a name that is
not a user variable (:func:`internal`: ``total_energy``, ``vertex_count``,
settings, toggles, named constraints, quantities).
"""
from __future__ import annotations

import time

import numpy as np

from ..errors import CommandError, ExpressionError, UnsupportedError, did_you_mean
from ..expr import nodes as N
from ..model import string as SM
from ..model.groups import group_of
from .toggles import TOGGLE_DEFAULTS, TOGGLES
from .values import QRef, SessionLike, as_float, as_int

READ_ONLY = {
    "total_energy", "total_area", "total_length", "vertex_count", "edge_count",
    "facet_count", "body_count", "facetedge_count", "space_dimension",
    "surface_dimension", "torus", "datafilename", "equi_count", "edge_delete_count",
    "facet_delete_count", "delete_count", "edge_refine_count", "facet_refine_count",
    "vertex_pop_count", "edge_pop_count", "pop_count", "notch_count", "refine_count", "where_count",
    "iteration_counter", "total_time", "random", "quantity_count", "symmetry_group",
    "simplex_representation", "lagrange_order", "date_and_time", "linear", "quadratic",
    "clock", "last_eigenvalue",
}
DEFAULTS = {
    "scale": 0.1, "scale_limit": 1.0, "scale_scale": 1.0, "target_tolerance": 1e-4,
    "constraint_tolerance": 1e-12, "jiggle_temperature": 0.05, "random_seed": 1.0,
    "autochop_length": 0.0, "integral_order_1d": 3.0, "integral_order_2d": 6.0,
    "hessian_epsilon": 1e-10, "sq_mean_mix": 0.0,
    "last_eigenvalue": 0.0, "linear_metric_mix": 0.5, "diffusion_coeff": 0.0,
}


def set_variable(session: SessionLike, name, value):
    """``name := value``: settings, the gravity constant, parameters and
    user variables (ON_ASSIGN_CALL procedures run after)."""
    if name in READ_ONLY:
        raise CommandError(f"'{name}' is read-only")
    if name in session.commands:
        del session.commands[name]
    if name in session.settings or name in ("gravity_constant", "sq_curvature_modulus"):
        value = as_float(value, f"'{name}'")     # settings are numbers
    if name in session.settings:
        if name.startswith("integral_order") and getattr(session.surface, "metric", None):
            raise UnsupportedError(f"{name} := ... with a metric",
                                   "the metric keeps the datafile's quadrature orders")
        if name == "random_seed":
            session.rng = np.random.default_rng(as_int(value, "random_seed") & (2**63 - 1))
        session.settings[name] = value
        return
    if name == "gravity_constant":
        session.surface.gravity_constant = float(value)
    if name == "sq_curvature_modulus" and session.surface is not None:
        session.surface.sq_curvature_modulus = float(value)
        return
    if session.surface is not None and name in session.surface.quantities:
        raise CommandError(f"'{name}' is a quantity; assign to {name}.target or "
                           f"{name}.modulus")
    session.variables[name] = value
    proc = getattr(session, "on_assign_call", {}).get(name)
    if proc is not None and proc in session.commands:
        # PARAMETER name ... ON_ASSIGN_CALL proc: run it after each assignment
        busy = session.__dict__.setdefault("_on_assign_busy", set())
        if name not in busy:
            busy.add(name)
            try:
                session.interp.run_proc(session.commands[proc], [])
            finally:
                busy.discard(name)


def internal(session: SessionLike, name):
    """The value of a built-in name (``total_energy``, ``vertex_count``, a
    setting, a toggle, a named constraint)."""
    s = session.surface
    t = session.totals
    if name in session.settings:
        return session.settings[name]
    if name in N.CONSTANTS:
        return N.CONSTANTS[name]
    if s is not None and name in s.quantities:
        return QRef(name)
    for cid, cname in getattr(s, "constraint_names", {}).items():
        if cname == name:
            return float(cid)
    for bid, bname in getattr(s, "boundary_names", {}).items():
        if bname == name:
            return float(bid)
    if name in session.toggles or name in TOGGLES:
        return float(session.toggles.get(name, TOGGLE_DEFAULTS.get(name, 0)))
    if s is None:
        raise ExpressionError(f"undefined name '{name}' (no surface loaded)")
    if name == "__symmetry_group__":        # wrap_compose / wrap_inverse (model.groups)
        group = group_of(s)
        if group is None:
            raise ExpressionError("no symmetry group other than the torus")
        return group
    simple = {
        "total_energy": lambda: t.energy,
        "total_area": lambda: t.total_area,
        "total_length": lambda: t.total_length,
        "vertex_count": lambda: s.nv, "edge_count": lambda: s.ne,
        "facet_count": lambda: s.n_facets, "body_count": lambda: s.bodies.n,
        "facetedge_count": lambda: facetedge_count(session),
        "space_dimension": lambda: s.sdim, "surface_dimension": lambda: 1 if s.string else 2,
        "high_constraint": lambda: max(s.constraints, default=0),
        "high_boundary": lambda: max(s.boundaries, default=0),
        # REF: the torus model is its "torus" group (symmetry_group 1 too);
        # SYMMETRY_GROUP "torus" alone is not TORUS
        "torus": lambda: int(s.periods is not None and s.symmetry_group is None),
        "datafilename": lambda: session.filename,
        "gravity_constant": lambda: s.gravity_constant,
        "sq_curvature_modulus": lambda: s.sq_curvature_modulus,
        "g": lambda: s.gravity_constant,
        "iteration_counter": lambda: session.iteration_counter,
        "total_time": lambda: session.total_time,
        "equi_count": lambda: session.counts.get("equi", 0),
        "edge_delete_count": lambda: session.counts.get("edge_delete", 0),
        "facet_delete_count": lambda: session.counts.get("facet_delete", 0),
        "delete_count": lambda: (session.counts.get("edge_delete", 0)
                                 + session.counts.get("facet_delete", 0)),
        "edge_refine_count": lambda: session.counts.get("edge_refine", 0),
        "facet_refine_count": lambda: session.counts.get("facet_refine", 0),
        "vertex_pop_count": lambda: session.counts.get("vertex_pop", 0),
        "edge_pop_count": lambda: session.counts.get("edge_pop", 0),
        "pop_count": lambda: session.counts.get("vertex_pop", 0) + session.counts.get("edge_pop", 0),
        "notch_count": lambda: session.counts.get("notch", 0),
        "refine_count": lambda: session.counts.get("refine", 0), "where_count": lambda: session.counts.get("where", 0),
        "random": lambda: float(session.rng.random()),
        "quantity_count": lambda: len(s.quantities),
        "symmetry_group": lambda: int(s.periods is not None or s.symmetry_group is not None),
        "simplex_representation": lambda: 0,
        "lagrange_order": lambda: s.order, "linear": lambda: int(s.order == 1),
        "quadratic": lambda: int(s.order == 2),
        "lagrange": lambda: 0,
        "date_and_time": lambda: time.strftime("%a %b %d %H:%M:%S %Y"),
        # REF: "total elapsed Evolver execution time in seconds"; here the
        # processor time of the process (REF prints 0.005 right after loading cube.fe)
        "clock": time.process_time,
    }
    fn = simple.get(name)
    if fn is None:
        known = list(simple) + list(session.variables) + list(session.settings) + list(
            s.quantities) + list(TOGGLES)
        raise ExpressionError(f"undefined name '{name}'" + did_you_mean(name, known))
    v = fn()
    return v if isinstance(v, str) else float(v)


def facetedge_count(session: SessionLike):
    """The number of facet-edges (3 per facet; the string model's chains)."""
    s = session.surface
    if s.string:
        return SM.facetedge_count(s)
    return 3 * s.nf
