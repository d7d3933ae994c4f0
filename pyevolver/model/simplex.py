"""The simplex model (``SIMPLEX_REPRESENTATION``): surfaces of any dimension k.

The manual ("Simplex model"): each facet is an oriented list of k + 1
vertices, bodies are lists of oriented facets, the datafile's edges section
is optional and no edges are needed.  REF (evolver-nox-d) keeps no edges at
all (``edge_count`` is 0, ``list edges`` is empty) and so does pyevolver:
the facets are one ``(nf, k + 1)`` vertex array ``Surface.SF``, ``E`` and
``FE`` stay empty, ``Surface.simplex`` is k.

What is supported (against REF): FIXED vertices, level-set constraints on
vertices (a refined edge's midpoint is on the constraints common to its
ends, as REF), facet TENSION, bodies with fixed volume or PRESSURE (their
volume needs SPACE_DIMENSION k + 1), ``r``.  What is refused by name here:
constraint integrals and CONVEX constraints, boundaries, named quantities,
the torus model and the quadratic model, an edges section (used by REF only
for constraint and quantity integrals, which are refused).
"""
from __future__ import annotations

import numpy as np

from .ids import IdMap

#: the largest surface dimension whose refinement template is known
MAX_SIMPLEX_DIM = 4


def simplex_dimension(sc) -> int:
    """The surface dimension k of a simplex-model scene (SURFACE_DIMENSION, 2
    when not given)."""
    return int(sc.values.get("surface_dimension", 2))


def check_scene(builder) -> None:
    """Refuse by name what the simplex model does not support here."""
    sc = builder.sc
    k = simplex_dimension(sc)
    line = sc.decl_lines.get("simplex_representation")

    def refuse(what, at=None):
        return builder.error(f"not supported in pyevolver: {what} in the simplex model",
                             at if at is not None else line)

    if k < 2:
        raise refuse(f"SURFACE_DIMENSION {k}", sc.decl_lines.get("surface_dimension"))
    if k > MAX_SIMPLEX_DIM:
        raise refuse(f"SURFACE_DIMENSION {k} (refinement known up to {MAX_SIMPLEX_DIM})",
                     sc.decl_lines.get("surface_dimension"))
    if sc.space_dimension < k:
        raise builder.error(f"SURFACE_DIMENSION {k} is above SPACE_DIMENSION "
                            f"{sc.space_dimension}", sc.decl_lines.get("surface_dimension")
                            or sc.decl_lines.get("space_dimension") or line)
    if sc.space_dimension > 6:
        raise refuse(f"SPACE_DIMENSION {sc.space_dimension} (REF's refinement order is "
                     f"known up to 6 dimensions)", sc.decl_lines.get("space_dimension"))
    if len(sc.bodies.ids) and sc.space_dimension != k + 1:
        raise refuse(f"bodies in SPACE_DIMENSION {sc.space_dimension} with SURFACE_DIMENSION "
                     f"{k} (a body's volume needs dimension k + 1)",
                     sc.decl_lines.get("space_dimension", line))
    if sc.torus:
        raise refuse("the torus model (the manual: no torus model or symmetry groups)")
    if "quadratic" in sc.flags:
        raise refuse("the quadratic model (the manual: not allowed)")
    for c in sc.constraints.values():
        if c.energy or c.content:
            raise refuse("constraint ENERGY and CONTENT integrals", c.line)
        if "convex" in c.flags:
            raise refuse("CONVEX constraints", c.line)
    if sc.boundaries:
        raise refuse("boundaries", next(iter(sc.boundaries.values())).line)
    if sc.quantities or sc.method_instances:
        q = next(iter(list(sc.quantities.values()) + list(sc.method_instances.values())))
        raise refuse("named quantities", getattr(q, "line", None))
    if len(sc.edges.ids):
        raise refuse("an edges section (REF uses it only for integrals)", sc.edges.lines[0])
    if sc.values.get("squared_curvature"):
        raise refuse("SQUARED_CURVATURE", sc.decl_lines.get("squared_curvature"))


def build(builder):
    """The Surface of a simplex-model scene, built with the soapfilm builder's
    vertex, body and attribute readers (``builder``:
    :class:`pyevolver.model.build._Builder`)."""
    sc, s = builder.sc, builder.s
    check_scene(builder)
    builder._actual_volume = {}
    s.params = dict(sc.parameters)
    s.sdim = sc.space_dimension
    s.sdim_line = sc.decl_lines.get("space_dimension")
    s.gravity_constant = sc.values.get("gravity_constant", 1.0)
    s.constraints = dict(sc.constraints)
    builder._vertices()
    builder._project()
    build_faces(builder)
    builder._bodies()
    builder._quantities()
    if builder._actual_volume:
        raise builder.error("not supported in pyevolver: ACTUAL_VOLUME in the simplex model",
                            sc.decl_lines.get("simplex_representation"))
    return s


def build_faces(builder) -> None:
    """Read the faces section as oriented vertex lists into ``s.SF``."""
    sc, s = builder.sc, builder.s
    k = simplex_dimension(sc)
    blk = sc.faces
    nface = len(blk.ids)
    builder.fid = IdMap(blk.ids, "face", sc.filename, blk.lines)
    fixed, tension, no_refine, colors, fcon, fbnd = builder._face_attributes(blk, nface)
    if fcon or fbnd.any():
        raise builder.error("not supported in pyevolver: facet constraints and boundaries "
                            "in the simplex model", sc.decl_lines.get("simplex_representation"))
    for pos, d in enumerate(blk.data):
        if len(d) != k + 1:
            raise builder.error(f"face {blk.ids[pos]}: the simplex model needs {k + 1} vertices "
                                f"per facet (SURFACE_DIMENSION {k}), got {len(d)}",
                                blk.lines[pos])
    data = np.asarray(blk.data, dtype=np.int64).reshape(nface, k + 1)
    if np.any(data <= 0):
        bad = int(np.nonzero((data <= 0).any(axis=1))[0][0])
        raise builder.error(f"face {blk.ids[bad]}: vertex ids are positive in the simplex model",
                            blk.lines[bad])
    owner = np.repeat(np.arange(nface), k + 1)
    flat = builder._signed_refs(blk, data.ravel(), owner, builder.vid, "face", "vertex")
    SF = np.asarray(flat, np.int64).reshape(nface, k + 1)
    rep = np.nonzero([len(set(row)) != k + 1 for row in SF.tolist()])[0]
    if len(rep):
        raise builder.error(f"face {blk.ids[rep[0]]}: a vertex is listed twice",
                            blk.lines[rep[0]])
    s.simplex = k
    s.SF = SF
    builder.facet_attrs(blk, nface, fixed, tension, no_refine, colors)
