"""Energies of the simplex model (:mod:`pyevolver.model.simplex`):
:class:`SimplexTotals`.

* a facet's area is its k-dimensional volume (the Gram determinant of its
  sides, :func:`pyevolver.geometry.simplex.simplex_areas`), the energy its
  tension times that (REF: simplex3.fe, the regular tetrahedron of side √2
  in R^4 has area 1/3, the corner ones 1/6, total_energy 1);
* a body's volume is the sum over its oriented facets of the cones from the
  origin, ``det[x_0 … x_k]/(k+1)!`` (REF: simplex3.fe's 4-simplex has volume
  1/24; the surface dimension must be the space dimension less one);
* prescribed pressures add ``−P V``.

Gradients are analytic (``tests/methods/test_simplex.py`` checks them by
central differences).
"""
from __future__ import annotations

import numpy as np

from ..errors import UnsupportedError
from ..geometry import kernels as G
from ..geometry import simplex as GS
from ..model.surface import Surface
from .totals import MODEL_TOTALS, Totals


class SimplexTotals(Totals):
    """:class:`~pyevolver.methods.totals.Totals` of a simplex-model surface.

    Attributes (beyond the common ones)
    -----------------------------------
    facet_P : (nf, k+1, d) array
        The facets' corners.
    facet_volume : (nf,) array
        Each facet's cone content (zeros when d != k + 1).
    """

    def __init__(self, s: Surface):
        self.surface = s
        X = s.X
        self.facet_P = X[s.SF] if s.n_facets else np.zeros((0, s.simplex + 1, X.shape[1]))
        self._S = GS.simplex_sides(self.facet_P)
        self.facet_area = GS.simplex_areas(self._S)
        self.total_area = float(self.facet_area.sum())
        self.terms = {}
        energy = float(self.facet_area @ s.facet_tension)
        self.terms["facet_tension"] = energy
        self.con_energy, self.con_content = 0.0, None
        if X.shape[1] == s.simplex + 1:
            self.facet_volume = GS.cone_contents(self.facet_P)
        else:
            self.facet_volume = np.zeros(s.n_facets)
        b = s.bodies
        self.volumes = (b.facet_matrix @ self.facet_volume + b.volconst) if b.n else np.zeros(0)
        self.energy = self._finish_energy(energy, 0.0)

    @property
    def facet_N2(self) -> np.ndarray:  # type: ignore[override]
        """Refused: a simplex facet has no normal vector here."""
        raise UnsupportedError("facet normals in the simplex model")

    def energy_gradient(self) -> np.ndarray:
        """Gradient (nv, d) of the total energy."""
        s = self.surface
        per = GS.simplex_area_grad(self._S, self.facet_area) * s.facet_tension[:, None, None]
        g = G.scatter_nd(s.nv, s.SF.ravel(), per.reshape(-1, per.shape[2]))
        b = s.bodies
        if b.n:
            pmask = ~np.isnan(b.pressure)
            if pmask.any():
                vg = self.body_volume_gradients()
                g -= np.einsum("b,bvk->vk", b.pressure[pmask], vg[pmask])
        return g

    def body_volume_gradients(self) -> np.ndarray:
        """(nb, nv, d) gradients of the body volumes."""
        s = self.surface
        b = s.bodies
        d = s.X.shape[1]
        out = np.zeros((b.n, s.nv, d))
        if not b.n or not s.n_facets:
            return out
        per = GS.cone_content_grad(self.facet_P)            # (nf, k+1, d)
        M = b.facet_matrix.tocsr()
        flat = s.SF.ravel()
        for i in range(b.n):
            w = np.asarray(M.getrow(i).todense()).ravel()
            out[i] = G.scatter_nd(s.nv, flat, (per * w[:, None, None]).reshape(-1, d))
        return out

    def volume_magnitudes(self) -> np.ndarray:
        """Per body, the sum of the absolute facet contents."""
        b = self.surface.bodies
        return abs(b.facet_matrix) @ np.abs(self.facet_volume)


MODEL_TOTALS["simplex"] = SimplexTotals
