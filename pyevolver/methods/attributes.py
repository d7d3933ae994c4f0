"""Read-only element attributes computed from the geometry, on whole arrays.

The command language reads attributes one element at a time
(``foreach vertex vv do print vv.sqcurve``), but ``sqcurve`` or
``mean_curvature`` of one vertex needs the sums over its star.  Every
attribute here is computed for the whole surface at once, and
:class:`AttrCache` keeps the arrays until the coordinates change, so a
generator over n elements costs one O(n) evaluation, not n.

The values follow the Surface Evolver 2.70 manual ("Element attributes")
and what evolver-nox-d prints (checked in tests/commands/test_attributes.py):

* vertex ``mean_curvature``: ``h = 3 F·N / (2 N·N)`` with ``F`` the area
  gradient at the vertex and ``N`` the sum of its facets' area vectors
  (``N = Σ ½ N_f``), both projected onto the tangent space of the vertex's
  level-set constraints (not of a parametric boundary); signed (positive where the
  surface curves towards its normals); every vertex, FIXED ones included.
* vertex ``sqcurve``: ``h²`` with the ``sq_mean_curvature`` method's
  estimate ``h = 3|F| / (2A)`` (``A`` the star area; ``3|F| / (2|N|)``
  with the ``effective_area`` toggle on, the ``normal_sq_mean_curvature``
  estimate ``h = 3 F·F / (2 F·N)`` with ``normal_curvature`` on), zero
  at FIXED vertices and vertices on parametric boundaries, as that method.
* edge ``dihedral``: the angle between the unit normals of the edge's two
  facets, oriented alike across the edge; 0 unless there are exactly two.
* vertex ``dihedral`` (string model): ``2 asin(|F|/2)``, ``F`` the sum of
  the unit edge vectors leaving the vertex, clamped to π; 0 at vertices
  with fewer than two edges.
"""
from __future__ import annotations

import weakref

import numpy as np

from ..constraints import project_tangent
from ..model.records import edge_facets



def star_sums_projected(s, t):
    """Per-vertex star area ``A`` (nv,), area gradient ``F`` (nv, 3) and
    area-vector sum ``N`` (nv, 3), with ``F`` and ``N`` projected onto the
    tangent spaces of the vertices' level-set constraints.

    The facets' corners come from their first vertex and side vectors, so
    facets that wrap round a torus are taken whole.

    Parameters
    ----------
    s : Surface
    t : Totals
        Geometry of ``s`` at its current coordinates.

    Returns
    -------
    A, F, N : ndarray
    """
    nv = s.nv
    A = np.zeros(nv)
    F = np.zeros((nv, 3))
    N = np.zeros((nv, 3))
    if s.nf:
        S = t.facet_S
        P0 = t.facet_x0
        P = [P0, P0 + S[:, 0], P0 + S[:, 1]]
        N2 = t.facet_N2
        L = np.linalg.norm(N2, axis=1)
        with np.errstate(all="ignore"):
            n = np.nan_to_num(N2 / L[:, None])
        Fc = s.F
        for c in range(3):
            v = Fc[:, c]
            e = P[(c + 2) % 3] - P[(c + 1) % 3]            # the side opposite corner c
            g = 0.5 * np.cross(n, e)
            A += np.bincount(v, weights=0.5 * L, minlength=nv)
            for k in range(3):
                F[:, k] += np.bincount(v, weights=g[:, k], minlength=nv)
                N[:, k] += np.bincount(v, weights=0.5 * N2[:, k], minlength=nv)
    if s.vcon:                  # level-set constraints only (REF: not boundaries)
        F, N = project_tangent(_WithoutBoundaries(s), [F, N])
    return A, F, N


class _WithoutBoundaries:
    """A view of a surface whose vertices are on no parametric boundary."""

    def __init__(self, s):
        self._s = s
        self.vattr = {k: v for k, v in s.vattr.items() if k != "boundary"}

    def __getattr__(self, name):
        return getattr(self._s, name)


def vertex_mean_curvature(s, t):
    """(nv,) the ``mean_curvature`` attribute: ``3 F·N / (2 N·N)``."""
    _, F, N = star_sums_projected(s, t)
    FN = np.einsum("ij,ij->i", F, N)
    NN = np.einsum("ij,ij->i", N, N)
    with np.errstate(all="ignore"):
        h = np.where(NN > 0, 1.5 * FN / NN, 0.0)
    return np.nan_to_num(h)


def vertex_sqcurve(s, t, mode="plain"):
    """(nv,) the ``sqcurve`` attribute: the squared mean curvature estimate
    of ``sq_mean_curvature`` (``mode`` "plain"), of
    ``eff_area_sq_mean_curvature`` ("eff", the ``effective_area`` toggle) or
    of ``normal_sq_mean_curvature`` ("norm", the ``normal_curvature``
    toggle), zero at FIXED and boundary vertices."""
    A, F, N = star_sums_projected(s, t)
    FF = np.einsum("ij,ij->i", F, F)
    with np.errstate(all="ignore"):
        if mode == "norm":
            FN = np.einsum("ij,ij->i", F, N)
            h = np.where(FN != 0, 1.5 * FF / FN, 0.0)
            h2 = h * h
        elif mode == "eff":
            NN = np.einsum("ij,ij->i", N, N)
            h2 = np.where(NN > 0, 2.25 * FF / NN, 0.0)
        else:
            h2 = np.where(A > 0, 2.25 * FF / (A * A), 0.0)
    h2 = np.nan_to_num(h2)
    skip = np.asarray(s.vattr["fixed"], bool).copy()
    if "boundary" in s.vattr:
        skip |= s.vattr["boundary"] != 0
    h2[skip] = 0.0
    return h2


def edge_dihedral(s, t):
    """(ne,) the ``dihedral`` attribute of edges: the angle between the
    unit normals of the two facets on an edge (the second facet's normal
    flipped when both run along the edge the same way); 0 elsewhere."""
    out = np.zeros(s.ne)
    if s.nf == 0:
        return out
    ef, ek, val = edge_facets(s)
    e = np.nonzero(val == 2)[0]
    if not len(e):
        return out
    fa, fb = ef[e, 0], ef[e, 1]
    sa = np.where(s.FE[fa, ek[e, 0]] >= 0, 1.0, -1.0)      # ~e encodes a reversed edge
    sb = np.where(s.FE[fb, ek[e, 1]] >= 0, 1.0, -1.0)
    Na = t.facet_N2[fa]
    Nb = t.facet_N2[fb] * (-sa * sb)[:, None]        # opposite senses: consistent
    with np.errstate(all="ignore"):
        c = np.einsum("ij,ij->i", Na, Nb) / (np.linalg.norm(Na, axis=1) *
                                             np.linalg.norm(Nb, axis=1))
    out[e] = np.arccos(np.clip(np.nan_to_num(c, nan=1.0), -1.0, 1.0))
    return out


def string_vertex_dihedral(s, t):
    """(nv,) the string model's vertex ``dihedral``: ``2 asin(|F|/2)`` with
    ``F`` the sum of the unit vectors along the edges leaving the vertex,
    clamped to π; 0 where fewer than two edges meet."""
    d = t.edge_vec
    L = np.linalg.norm(d, axis=1)
    with np.errstate(all="ignore"):
        u = np.nan_to_num(d / L[:, None])
    nv = s.nv
    F = np.zeros((nv, d.shape[1]))
    for k in range(d.shape[1]):
        F[:, k] = (np.bincount(s.E[:, 0], weights=u[:, k], minlength=nv)
                   - np.bincount(s.E[:, 1], weights=u[:, k], minlength=nv))
    deg = np.bincount(s.E.ravel(), minlength=nv)
    f = np.linalg.norm(F, axis=1)
    out = np.where(f >= 2.0, np.pi, 2.0 * np.arcsin(np.minimum(f, 2.0) / 2.0))
    out[deg < 2] = 0.0
    return out


class AttrCache:
    """Per-surface attribute arrays, valid while the coordinates stay as
    they were when computed.

    ``version`` must be increased whenever coordinates change inside a
    command (``set vertex x ...``): the session's :class:`Totals` are only
    renewed between commands, but attributes read the live coordinates, as
    the Evolver's do.
    """

    def __init__(self):
        self.version = 0
        self._key = None
        self._arrays = {}
        self._geo = None
        self._born = None

    def touch(self, session):
        """Coordinates changed: forget every array (and note that the
        session's totals no longer describe the coordinates)."""
        self._note_born(session)
        self.version += 1

    def _note_born(self, session):
        t = session.totals
        if self._born is None or self._born[0]() is not t:
            self._born = (_ref(t), self.version)
            self._geo = None        # (made at an older version: never used again)

    def geometry(self, session):
        """A :class:`Totals` of the current coordinates: the session's own
        when no coordinate changed since it was made, else a fresh one."""
        t = session.totals
        self._note_born(session)
        if self._born[1] == self.version:
            return t
        s = session.surface
        if self._geo is None or self._geo[0] is not s or self._geo[1] != self.version:
            self._geo = (s, self.version, s.evaluate())
        return self._geo[2]

    def get(self, session, name, fn):
        """``fn(surface, totals)`` for the current coordinates, cached."""
        t = session.totals
        key = (session.surface, _ref(t), self.version)
        if self._key is None or self._key[0] is not key[0] or self._key[1]() is not t \
                or self._key[2] != key[2]:
            self._key = key
            self._arrays = {}
        arr = self._arrays.get(name)
        if arr is None:
            arr = fn(session.surface, self.geometry(session))
            self._arrays[name] = arr
        return arr


def _ref(obj):
    """A weak reference to the session's totals ``obj`` (or None): the cache
    compares them by identity and keeps no old :class:`Totals`, 13 MB at
    81,920 facets, alive beside the ``g`` steps' arrays."""
    return _none if obj is None else weakref.ref(obj)


def _none():
    return None
