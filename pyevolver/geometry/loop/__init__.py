"""Loop subdivision surfaces: exact limit-surface evaluation and the true
Willmore energy, area and volume of the limit surface of a closed control
mesh, with gradients (issue 8; the paper's Figure 1(e)).

* :mod:`.stencils` — the regular patch as a quartic box spline (12 control
  points), derived from Loop's rules, and the per-valence maps of a patch
  with one extraordinary vertex (recursive subdivision, Stam 1998);
* :mod:`.patches` — half-edges, validation, the control points of every
  triangle and the global Loop step for meshes that need it;
* :mod:`.energy` — W = ∫H² dA, area and volume by quadrature, and their
  gradients with respect to the control points.

References: C. Loop, *Smooth subdivision surfaces based on triangles*, MS
thesis, Utah 1987; J. Stam, *Evaluation of Loop subdivision surfaces*,
SIGGRAPH 1998 course notes; F. Cirak, M. Ortiz, P. Schröder, *Subdivision
surfaces: a new paradigm for thin-shell finite-element analysis*, IJNME 47
(2000).
"""
from .energy import LoopEvaluator, loop_quantities  # noqa: F401
from .patches import LoopTopology, loop_subdivide  # noqa: F401
from .stencils import regular_basis, triangle_rule  # noqa: F401
