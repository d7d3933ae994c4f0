"""The facet terms of a ``hessian_normal`` Hessian, summed per facet and
assembled once (issue 24).

When every free vertex moves along one direction (the usual
``hessian_normal`` basis: :class:`~pyevolver.evolve.hessian.Basis` with
``B`` of shape (nv, 3, 1)), the facet area and facet volume terms each give
one 3 × 3 block per facet (:mod:`pyevolver.methods.normal_blocks`).  They
are added block by block and the sum is assembled into one CSR matrix with
32-bit indices, instead of one COO matrix per term converted together: a
third of the entries and of the index memory on the 81,920-facet sphere.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..methods import axis_major as AM
from ..methods._common import facet_points, has_group_maps
from ..methods.normal_blocks import area_blocks, volume_blocks


class FacetBlocks:
    """Accumulates per-facet blocks of one evaluation ``t`` on ``basis``."""

    def __init__(self, t, basis):
        self.t, self.basis = t, basis
        s = t.surface
        if AM.available(t):
            self.P, self.E = AM.corner_sides(t)                # (3, 3, nf): x0, x0 + a, x0 + b
        else:
            self.P = np.ascontiguousarray(facet_points(t).transpose(2, 1, 0))
            self.E = None
        self.U = AM.gather(s, basis.B[:, :, 0])                # (3, 3, nf)
        self.K = None

    def _add(self, K):
        if self.K is None:
            self.K = K
        else:
            self.K += K

    def area(self, weights) -> None:
        """Add the blocks of ``Σ_f w_f A_f``."""
        w = np.asarray(weights, float)
        if np.any(w):
            self._add(area_blocks(self.P, self.U, w, self.E))

    def volume(self, weights, symmetric: bool) -> None:
        """Add the blocks of ``Σ_f w_f v_f`` (symmetric or z-flux volume)."""
        w = np.asarray(weights, float)
        if np.any(w):
            self._add(volume_blocks(self.P, self.U, w, symmetric))

    def matrix(self) -> sp.csr_matrix:
        """The (ndof, ndof) sum of the blocks, CSR, duplicates summed."""
        b = self.basis
        n = b.n
        F = self.t.surface.F
        K = self.K if self.K is not None else np.zeros((len(F), 3, 3))
        itype = np.int32 if n < 2 ** 31 - 1 else np.int64
        idx = b.start[F].astype(itype)
        rows = np.repeat(idx, 3, axis=1).ravel()
        cols = np.tile(idx, (1, 3)).ravel()
        vals = K.reshape(-1)
        free = b.ndof[F] > 0
        if not free.all():
            keep = (np.repeat(free, 3, axis=1) & np.tile(free, (1, 3))).ravel()
            rows, cols, vals = rows[keep], cols[keep], vals[keep]
        return sp.csr_matrix((vals, (rows, cols)), shape=(n, n))


def applies(t, basis) -> FacetBlocks | None:
    """A :class:`FacetBlocks` when ``basis`` has one direction per vertex and
    the evaluation ``t`` has plain Euclidean facets (no metric, no symmetry
    group's maps); None otherwise (the terms are then assembled one by one)."""
    if basis is None or basis.B.shape[2] != 1 or has_group_maps(t):
        return None
    s = t.surface
    if s.metric is not None or s.nf == 0:
        return None
    return FacetBlocks(t, basis)
