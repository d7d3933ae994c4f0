"""The Scene: what a datafile declares, before any geometry is built.

Text -> :class:`Scene` (this module, filled by :mod:`pyevolver.datafile.reader`)
-> :class:`pyevolver.model.surface.Surface` (arrays) -> methods, constraints ->
evolve / remesh -> outputs.
"""
from __future__ import annotations

from array import array
from typing import Any
from dataclasses import dataclass, field

import numpy as np


@dataclass
class ConstraintDecl:
    id: int
    formula: object                  # Formula: phi(x) (level set phi = 0)
    flags: set = field(default_factory=set)   # global convex nonwall nonnegative nonpositive
    energy: list | None = None       # [Formula]*3 (E1 E2 E3) or None
    content: list | None = None      # [Formula]*3 or None
    line: int = 0


@dataclass
class BoundaryDecl:
    id: int
    nparams: int
    coords: list                     # [Formula] x1.. x_sdim of p1..pk
    flags: set = field(default_factory=set)
    energy: list | None = None
    content: list | None = None
    line: int = 0


@dataclass
class MethodDecl:
    method: str
    is_global: bool = False
    scalar: object = None            # Formula
    vector: list | None = None       # [Formula]*3
    modulus: float = 1.0
    name: str = ""                   # instance name
    ignore_fixed: bool = False
    ignore_constraints: bool = False
    line: int | None = None          # source line of a METHOD_INSTANCE declaration
    parameter_1: float | None = None  # the instance's PARAMETER_1 (sqcurve_string's power)


@dataclass
class QuantityDecl:
    name: str
    kind: str                        # energy fixed conserved info_only
    target: float = 0.0
    modulus: float = 1.0
    tolerance: float = -1.0
    lagrange_multiplier: float = 0.0
    methods: list = field(default_factory=list)   # [MethodDecl]
    function: object = None          # FUNCTION expression of ``inst.value`` names
    line: int = 0


@dataclass
class ElementBlock:
    """The lines of one element section.

    ``ids`` are datafile ids in reading order; ``data`` the defining numbers
    of each element (coordinates, endpoint ids, edge ids, facet ids);
    ``attrs`` maps the position of an element to its attribute list
    ``[(keyword, [values]), ...]`` (only elements that have attributes);
    ``lines`` the source line of each element.
    """

    ids: list = field(default_factory=list)
    data: list = field(default_factory=list)
    attrs: dict = field(default_factory=dict)
    lines: object = field(default_factory=lambda: array("l"))


@dataclass
class Scene:
    filename: str = "<datafile>"
    parameters: dict = field(default_factory=dict)     # name -> value (ordered)
    flags: set = field(default_factory=set)
    values: dict = field(default_factory=dict)         # top-section numeric settings
    decl_lines: dict = field(default_factory=dict)     # setting or flag -> source line
    constraints: dict = field(default_factory=dict)    # id -> ConstraintDecl
    boundaries: dict = field(default_factory=dict)     # id -> BoundaryDecl
    quantities: dict = field(default_factory=dict)     # name -> QuantityDecl
    method_instances: dict = field(default_factory=dict)  # name -> MethodDecl
    attributes: dict = field(default_factory=dict)     # (etype, name) -> (type, size)
    periods: np.ndarray | None = None
    symmetry_group: str | None = None                  # SYMMETRY_GROUP "name", lower case
    read_warnings: list = field(default_factory=list)  # (line, message) of the read section
    macros: dict = field(default_factory=dict)         # #define macros kept (keep_macros)
    vertices: ElementBlock = field(default_factory=ElementBlock)
    edges: ElementBlock = field(default_factory=ElementBlock)
    faces: ElementBlock = field(default_factory=ElementBlock)
    bodies: ElementBlock = field(default_factory=ElementBlock)
    read_text: str | None = None
    read_line: int = 0
    wraps: dict = field(default_factory=dict)          # edge position -> wrap list
    arrays: dict = field(default_factory=dict)         # global arrays: name -> (type, ndarray)
    source_lines: Any = None          # the text's lines (error excerpts; datafile.source_lines)
    constraint_names: dict = field(default_factory=dict)  # id -> name (named constraints)
    boundary_names: dict = field(default_factory=dict)    # id -> name (named boundaries)
    on_assign: dict = field(default_factory=dict)         # parameter -> procedure
                                                          # (ON_ASSIGN_CALL)
    optimizing: dict = field(default_factory=dict)        # OPTIMIZING_PARAMETER name ->
                                                          # (pdelta, pscale)
    param_deltas: dict = field(default_factory=dict)      # every parameter's (pdelta,
                                                          # pscale) given in the file
    unsupported: list = field(default_factory=list)       # (feature, line, column): refused
                                                          # once the whole file is read
    warnings: list = field(default_factory=list)          # (message, line, column): the
                                                          # lines the Evolver warns about
    top_commands: list = field(default_factory=list)      # (text, line): top-section
                                                          # procedure/function definitions

    @property
    def space_dimension(self):
        return int(self.values.get("space_dimension", 3))

    @property
    def string(self):
        """The string model (surface dimension 1: ``STRING`` or
        ``SURFACE_DIMENSION 1``)."""
        return "string" in self.flags or int(self.values.get("surface_dimension", 2)) == 1

    @property
    def simplex(self):
        """The simplex model (``SIMPLEX_REPRESENTATION``): facets are oriented
        vertex lists."""
        return "simplex_representation" in self.flags

    @property
    def torus(self):
        return "torus" in self.flags or "torus_filled" in self.flags
