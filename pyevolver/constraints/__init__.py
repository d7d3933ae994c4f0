"""Level-set constraints and parametric boundaries: projection, tangent
spaces, one-sided constraints, boundary parameters.

The public API::

    project_to_constraints(s, idx)   # Newton projection onto level sets
    project_tangent(s, [vecs])       # remove the constraint-normal parts
    displace(s, state(s), dX)        # move (boundary vertices in parameter space)
"""
from __future__ import annotations

from ..model.formulas import Integrand, LocatedFormula, located
from ..model.surface import HOOKS
from .boundary import boundary_eval, boundary_groups, displace, restore_state, solve_small, state
from .levelset import (constrained_vertices, integral_edges, project_tangent,
                       project_to_constraints, release_one_sided, vertex_coords)

HOOKS.project = project_to_constraints

__all__ = ["Integrand", "LocatedFormula", "located", "boundary_eval", "boundary_groups",
           "displace", "restore_state", "solve_small", "state", "constrained_vertices",
           "integral_edges", "project_tangent", "project_to_constraints", "release_one_sided",
           "vertex_coords"]
