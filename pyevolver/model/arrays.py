"""A Surface from vertex and triangle arrays, without a datafile.

:func:`surface_from_arrays` fills a :class:`~pyevolver.model.scene.Scene`
with element tables (vertex coordinates, edges, faces as signed edge ids,
the layout the datafile reader produces) and builds it with
:func:`~pyevolver.model.surface.build_surface`, so the result is the
surface the same mesh written as a datafile would load to: the same
elements in the same order, ids 1, 2, ... .
"""
from __future__ import annotations

from array import array

import numpy as np

from .scene import ElementBlock, Scene
from .build import build_surface
from .surface import HOOKS, Surface


def triangle_edges(F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The undirected edges of a triangle list.

    Parameters
    ----------
    F : (nf, 3) int array
        Vertex indices of each triangle.

    Returns
    -------
    E : (ne, 2) int array
        Each edge once, ``E[:, 0] < E[:, 1]``, sorted.
    idx : (nf, 3) int array
        The edge of side k of each triangle (from corner k to corner k + 1).
    """
    F = np.asarray(F, np.int64)
    if not len(F):
        return np.zeros((0, 2), np.int64), np.zeros((0, 3), np.int64)
    head = np.roll(F, -1, axis=1)
    lo, hi = np.minimum(F, head).ravel(), np.maximum(F, head).ravel()
    key = lo * (int(F.max()) + 1) + hi
    _, first, inv = np.unique(key, return_index=True, return_inverse=True)
    return np.stack([lo[first], hi[first]], 1), inv.reshape(F.shape)


def _block(data) -> ElementBlock:
    n = len(data)
    return ElementBlock(ids=list(range(1, n + 1)), data=data,
                        lines=array("l", bytes(array("l").itemsize * n)))


def surface_from_arrays(vertices: np.ndarray, facets: np.ndarray, *,
                        fixed: np.ndarray | None = None,
                        tension: np.ndarray | None = None,
                        body: bool = False,
                        bodies: list | None = None,
                        filename: str = "<arrays>") -> Surface:
    """Build a Surface (soap film, 3 dimensions) from a triangle mesh.

    Parameters
    ----------
    vertices : (nv, 3) float array
        Coordinates; (nv, 2) arrays get z = 0.
    facets : (nf, 3) int array
        Vertex indices (0-based) of each triangle; its orientation is the
        facet's.  Edges are the distinct sides, ordered as
        :func:`triangle_edges` gives them.
    fixed : (nv,) bool array, optional
        The ``fixed`` vertices.
    tension : (nf,) float array, optional
        Facet tensions (default 1).
    body : bool
        Add one body bounded by every facet (positively oriented; its
        volume is not fixed).
    bodies : list of (facets, attributes), optional
        Bodies instead: each the signed 1-based facet numbers bounding it
        (negative: the facet bounds it with its back) and its datafile
        attributes, ``[("volume", [v]), ("density", [d]), ...]``.
    filename : str
        The name error messages give.

    Returns
    -------
    Surface
        Equal to the surface the same mesh written as a datafile loads to.
    """
    X = np.asarray(vertices, float)
    if X.ndim != 2 or X.shape[1] not in (2, 3):
        raise ValueError(f"vertices must be (nv, 3), not {X.shape}")
    if X.shape[1] == 2:
        X = np.hstack([X, np.zeros((len(X), 1))])
    F = np.asarray(facets, np.int64).reshape(-1, 3)
    if len(F) and (F.min() < 0 or F.max() >= len(X)):
        raise ValueError("a facet refers to a vertex that does not exist")
    E, idx = triangle_edges(F)
    sign = np.where(F == E[idx, 0], 1, -1)
    scene = Scene(filename=filename)
    scene.vertices = _block(np.ascontiguousarray(X))
    scene.edges = _block(E + 1)
    scene.faces = _block(sign * (idx + 1))
    if body:
        scene.bodies = _block([list(range(1, len(F) + 1))])
    elif bodies:
        scene.bodies = _block([[int(f) for f in facets] for facets, _ in bodies])
        scene.bodies.attrs = {k: list(attrs) for k, (_, attrs) in enumerate(bodies) if attrs}
    s = build_surface(scene)
    if fixed is not None:
        s.vattr["fixed"] = np.asarray(fixed).reshape(-1) != 0
    if tension is not None:
        s.fattr["tension"] = np.asarray(tension, float).reshape(-1)
    return s


HOOKS.from_arrays = surface_from_arrays
