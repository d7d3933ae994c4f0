"""The Surface: coordinates and topology as numpy arrays, built from a Scene.

Element indices are 0-based internally; the Evolver's ids are index + 1
(elements are renumbered consecutively in reading order, the datafile id is
kept as ``original``).  Attributes, constraints, boundaries and quantities
exist only when the datafile declares them.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import numpy as np

from ..geometry import kernels as G
from ..expr import nodes as N
from .facet_csr import PendingCSR


class Hooks:
    """Services of the layers above the model, installed at their import.

    The model does not import them (layers point one way); they register:

    * ``evaluate(surface) -> Totals`` (:mod:`pyevolver.methods.totals`);
    * ``project(surface, idx) -> failed`` (:mod:`pyevolver.constraints`);
    * ``method_etype(name) -> "vertex" | "edge" | "facet"``, raising
      :class:`~pyevolver.errors.UnsupportedError` for an unknown method
      (:mod:`pyevolver.methods.registry`);
    * ``from_arrays(vertices, facets, **options) -> Surface``
      (:mod:`pyevolver.model.arrays`, which builds through the Scene
      builder; imported with the ``pyevolver.model`` package).
    """

    evaluate: Callable[[Any], Any] | None = None
    project: Callable[[Any, np.ndarray], np.ndarray] | None = None
    method_etype: Callable[[str], str] | None = None
    from_arrays: Callable[..., Any] | None = None

    def require(self, name: str) -> Callable:
        fn = getattr(self, name)
        if fn is None:
            raise RuntimeError(f"pyevolver: no {name} service installed "
                               f"(import pyevolver, not pyevolver.model alone)")
        return fn


HOOKS = Hooks()


@dataclass
class Quantity:
    """A named quantity at run time."""

    name: str
    kind: str                      # energy fixed conserved info_only
    target: float = 0.0
    modulus: float = 1.0
    tolerance: float = -1.0
    methods: list = field(default_factory=list)    # [(MethodDecl, etype, idx, sign)]
    value: float = 0.0
    pressure: float = 0.0
    # FUNCTION quantities: a Formula of the global values of method instances,
    # ``inst.value``; the instances are quantities of kind "instance"
    function: object = None
    line: int | None = None        # source line of its declaration


@dataclass
class Bodies:
    n: int = 0
    target: Optional[np.ndarray] = None        # nan where no volume constraint
    volconst: Optional[np.ndarray] = None
    pressure: Optional[np.ndarray] = None      # prescribed pressure (nan = none)
    density: Optional[np.ndarray] = None
    volume: Optional[np.ndarray] = None        # last computed
    lagrange: Optional[np.ndarray] = None      # reported pressures (multipliers)
    original: Optional[np.ndarray] = None
    occurrences: Optional[tuple] = None        # (body, facet, sign) as listed (duplicates kept)

    # the sparse (nb, nf) matrix of +-1 occurrences; a load leaves its CSR
    # arrays (pyevolver.model.facet_csr), made a scipy matrix when first read
    _facet_matrix = None

    @property
    def facet_matrix(self):
        M = self._facet_matrix
        if isinstance(M, PendingCSR):
            M = self._facet_matrix = M.to_scipy()
        return M

    @facet_matrix.setter
    def facet_matrix(self, M):
        self._facet_matrix = M

    @property
    def facet_csr(self):
        """The facet matrix, or its CSR arrays while it is not made yet
        (enough for :func:`pyevolver.methods._common.csr_matvec`)."""
        return self._facet_matrix


class Surface:
    """Arrays of one surface (soapfilm model, linear elements)."""

    def __init__(self):
        self.sdim = 3
        self.sdim_line: int | None = None   # the datafile line of SPACE_DIMENSION (refusals)
        self.X = np.zeros((0, 3))
        self.E = np.zeros((0, 2), dtype=np.int64)
        self.FE = np.zeros((0, 3), dtype=np.int64)
        self.vattr = {}
        self.eattr = {}
        self.fattr = {}
        self.vcon = {}      # constraint id -> bool (nv,)
        self.econ = {}      # constraint id -> int8 (ne,) (+1 / -1 orientation)
        self.fcon = {}      # constraint id -> bool (nf,)
        self.extra = {}     # (etype, name) -> array
        self.bodies = Bodies()
        self.quantities = {}
        self.constraints = {}
        self.boundaries = {}
        self.periods = None
        self.symmetry_group = None   # SYMMETRY_GROUP "torus": the torus model (model/symmetry.py)
        self.symmetric_content = False
        self.torus_filled = False
        self.params = {}
        self.gravity_constant = 1.0
        self.gravity_on = True       # the `gravity` toggle (G v sets it to v != 0)
        self.gap_constant = 1.0
        self.sq_curvature_modulus = 0.0     # legacy SQUARED_CURVATURE c
        self.metric = None                  # a model.metric.Metric (METRIC ...) or None
        self.curvature_mode = "plain"       # toggles: effective_area -> eff, normal_curvature -> norm
        # the string model (surface dimension 1): facets are edge chains kept in
        # sf_ptr / sf_enc (pyevolver.model.string) and FE stays empty
        self.string = False
        # the element order: 1 linear, 2 the quadratic model, in which the
        # edge midpoints are the last ne vertices, in edge order (see midv)
        self.order = 1
        self.sf_ptr = np.zeros(1, np.int64)
        self.sf_enc = np.zeros(0, np.int64)
        # the simplex model (SIMPLEX_REPRESENTATION, pyevolver.model.simplex):
        # ``simplex`` is the surface dimension k, and facet f is the oriented
        # vertex list ``SF[f]`` (k + 1 vertices); E and FE stay empty
        self.simplex = 0
        self.SF = np.zeros((0, 0), np.int64)

    # -- topology helpers ---------------------------------------------------
    @property
    def nv(self):
        return len(self.X)

    @property
    def ne(self):
        return len(self.E)

    @property
    def nf(self):
        return len(self.FE)

    @property
    def midv(self) -> np.ndarray | None:
        """(ne,) the midpoint vertex of each edge in the quadratic model
        (the last ``ne`` vertices, in edge order); None in the linear model."""
        if self.order != 2:
            return None
        return np.arange(self.nv - self.ne, self.nv)

    @property
    def n_facets(self):
        """Facets as the command language counts them: the edge chains in
        the string model, the triangles otherwise."""
        if self.simplex:
            return len(self.SF)
        return len(self.sf_ptr) - 1 if self.string else len(self.FE)

    def topology(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Topology-derived arrays, cached while ``E`` and ``FE`` are the same
        array objects: ``(idx, sgn, F)`` = edge index (nf, 3), orientation
        sign (nf, 3) and facet vertices (nf, 3).  Operations that change the
        connectivity build new arrays, which invalidates the cache."""
        c = self.__dict__.get("_topo")
        if c is not None and c[0] is self.FE and c[1] is self.E:
            return c[2]
        idx, sgn = G.edge_index(self.FE)
        tails = np.where(sgn > 0, self.E[idx, 0], self.E[idx, 1])
        val = (idx, sgn, tails)
        self._topo = (self.FE, self.E, val)
        return val

    @property
    def F(self):
        """(nf, 3) vertices of each facet (tails of its oriented edges)."""
        return self.topology()[2]

    def facet_corners(self) -> np.ndarray:
        """(3, nf) contiguous copy of ``F.T`` (cached with the topology), for
        gathering one coordinate of every facet corner at once."""
        topo = self.topology()
        c = self.__dict__.get("_corners")
        if c is not None and c[0] is topo:
            return c[1]
        Fc = np.ascontiguousarray(topo[2].T)
        self._corners = (topo, Fc)
        return Fc

    def ids(self, kind: str) -> np.ndarray:
        """(n,) element ids of ``kind`` ("vertex", "edge", "facet"): 1..n
        after loading; deletions (``t``, ``w``, ...) leave gaps, as in the
        Evolver, and new elements take ids above the largest."""
        attrs = {"vertex": self.vattr, "edge": self.eattr, "facet": self.fattr}[kind]
        n = {"vertex": self.nv, "edge": self.ne, "facet": self.n_facets}[kind]
        a = attrs.get("id")
        return a if a is not None else np.arange(1, n + 1)

    def element_id(self, kind: str, i: int) -> int:
        """The id of element ``i`` of ``kind`` (``ids(kind)[i]`` without
        making the whole array: attribute reads element by element)."""
        attrs = {"vertex": self.vattr, "edge": self.eattr, "facet": self.fattr}[kind]
        a = attrs.get("id")
        return int(a[i]) if a is not None else int(i) + 1

    @property
    def facet_tension(self):
        return self.fattr["tension"]

    @property
    def edge_tension(self):
        return self.eattr.get("tension", np.zeros(self.ne))

    def wrap_shift(self) -> np.ndarray | None:
        """(ne, 3) period shift of each edge of a torus-model surface (None otherwise)."""
        w = self.eattr.get("wrap")
        if w is None or self.periods is None:
            return None
        return w @ self.periods

    def param_env(self) -> N.MapEnv:
        """The datafile's parameters (and ``g``, the gravity constant) for formulas."""
        env = dict(self.params)
        env.setdefault("g", self.gravity_constant)
        return N.MapEnv(env)

    def __repr__(self) -> str:
        model = "string" if self.string else "soapfilm"
        if self.simplex:
            model = f"simplex, dimension {self.simplex}"
        if self.order == 2:
            model += ", quadratic"
        torus = ", torus" if self.periods is not None else ""
        return (f"<Surface {model}{torus}, space dimension {self.sdim}: {self.nv} vertices, "
                f"{self.ne} edges, {self.n_facets} facets, {self.bodies.n} bodies, "
                f"{len(self.quantities)} quantities>")

    @classmethod
    def from_arrays(cls, vertices: np.ndarray, facets: np.ndarray, **options: Any) -> Surface:
        """A surface from a triangle mesh, without a datafile.

        Parameters
        ----------
        vertices : (nv, 3) float array
        facets : (nf, 3) int array
            0-based vertex indices; the orientation is the facet's.
        **options
            ``fixed`` (nv,) bool, ``tension`` (nf,) float, ``body`` bool,
            ``filename`` str: see :func:`pyevolver.model.arrays.surface_from_arrays`.

        Returns
        -------
        Surface
            The surface the same mesh written as a datafile loads to.
        """
        return HOOKS.require("from_arrays")(vertices, facets, **options)

    # -- evaluation --------------------------------------------------------
    def evaluate(self) -> Any:
        """Energy, area, volumes and quantity values at the current coordinates.

        Returns
        -------
        pyevolver.methods.totals.Totals
            (through the hook :mod:`pyevolver.methods.totals` installs).
        """
        return HOOKS.require("evaluate")(self)
