"""String-model energies (surface dimension 1): facet areas and gravity by
one-dimensional divergence theorems over the facets' edge chains,
constraint integrands at vertices, their gradients, and the string model's
:class:`StringTotals`.  Topology of the chains: :mod:`pyevolver.model.string`
(whose docstring states the formulas, spec §3.2).
"""
from __future__ import annotations

import numpy as np

from ..model.formulas import LocatedFormula
from ..model.string import chain_points, facet_entries
from .totals import MODEL_TOTALS, Totals


def _edge_area(Pt, Ph):
    return -(Ph[:, 0] - Pt[:, 0]) * (Pt[:, 1] + Ph[:, 1]) / 2.0


def _edge_gravity(Pt, Ph):
    yt, yh = Pt[:, 1], Ph[:, 1]
    return -(Ph[:, 0] - Pt[:, 0]) * (yt * yt + yt * yh + yh * yh) / 6.0


def vertex_integrand(s, which):
    """``[(formula, vertex mask)]`` of constraint ENERGY / CONTENT integrands
    (their single component) with the vertices on the constraint."""
    out = []
    for cid, on in s.vcon.items():
        c = s.constraints[cid]
        comps = getattr(c, which)
        if comps and on.any():
            out.append((LocatedFormula(comps[0], f"constraint {cid} {which}",
                                       getattr(c, "line", None)), on))
    return out


def point_values(s, formula, idx: np.ndarray) -> np.ndarray:
    """(n,) values of ``formula`` at the vertices ``idx``."""
    P = s.X[idx]
    coords = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
    return formula.values(s.param_env(), coords, len(idx))


def point_gradients(s, formula, idx: np.ndarray) -> np.ndarray:
    """(n, 3) gradients of ``formula`` at the vertices ``idx``."""
    P = s.X[idx]
    coords = {"x": P[:, 0], "y": P[:, 1], "z": P[:, 2]}
    return formula.gradient(s.param_env(), coords, len(idx))


def content_coefficients(s, on):
    """(nf, nv) counts head - tail of the vertices in ``on`` over each
    facet's edges, as a dense-free list ``(facet, vertex, coef)``."""
    owner, _, _, tail, head = facet_entries(s)
    f = np.concatenate([owner, owner])
    v = np.concatenate([head, tail])
    c = np.concatenate([np.ones(len(head)), -np.ones(len(tail))])
    keep = on[v]
    return f[keep], v[keep], c[keep]


def vertex_energy(s):
    """Sum of the constraint ENERGY integrands at the vertices on them."""
    total = 0.0
    for formula, on in vertex_integrand(s, "energy"):
        total += float(np.sum(point_values(s, formula, np.nonzero(on)[0])))
    return total


def facet_areas(s, t=None):
    """(nf,) areas of the string facets, content integrals included."""
    nsf = len(s.sf_ptr) - 1
    owner = facet_entries(s)[0]
    area = np.bincount(owner, weights=_edge_area(*chain_points(s, t)), minlength=nsf)
    for formula, on in vertex_integrand(s, "content"):
        f, v, c = content_coefficients(s, on)
        if len(f):
            area += np.bincount(f, weights=c * point_values(s, formula, v), minlength=nsf)
    return area


def facet_gravity(s, t=None):
    """(nf,) ∬ y dA of each facet (per unit G ρ)."""
    owner = facet_entries(s)[0]
    return np.bincount(owner, weights=_edge_gravity(*chain_points(s, t)),
                       minlength=len(s.sf_ptr) - 1)


# ---------------------------------------------------------------------------
# gradients


def chain_grad(s, per_facet, fn):
    """Gradient of Σ_f w_f Σ_{edges of f} fn-term (fn gives the tail and head
    derivatives, each (m, 3))."""
    owner, _, _, tail, head = facet_entries(s)
    w = per_facet[owner]
    gt, gh = fn(*chain_points(s))
    out = np.zeros((s.nv, 3))
    for k in range(2):
        out[:, k] = (np.bincount(tail, weights=w * gt[:, k], minlength=s.nv)
                     + np.bincount(head, weights=w * gh[:, k], minlength=s.nv))
    return out


def area_derivs(Pt: np.ndarray, Ph: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tail and head derivatives (m, 2) of the per-edge area terms."""
    dx = Ph[:, 0] - Pt[:, 0]
    sy = Pt[:, 1] + Ph[:, 1]
    gt = np.stack([sy / 2.0, -dx / 2.0], axis=1)
    gh = np.stack([-sy / 2.0, -dx / 2.0], axis=1)
    return gt, gh


def gravity_derivs(Pt: np.ndarray, Ph: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tail and head derivatives (m, 2) of the per-edge gravity terms."""
    dx = Ph[:, 0] - Pt[:, 0]
    yt, yh = Pt[:, 1], Ph[:, 1]
    q = (yt * yt + yt * yh + yh * yh) / 6.0
    gt = np.stack([q, -dx * (2 * yt + yh) / 6.0], axis=1)
    gh = np.stack([-q, -dx * (yt + 2 * yh) / 6.0], axis=1)
    return gt, gh


def facet_area_gradient(s, per_facet):
    """Gradient (nv, 3) of Σ_f w_f A_f, content integrals included."""
    g = chain_grad(s, per_facet, area_derivs)
    for formula, on in vertex_integrand(s, "content"):
        f, v, c = content_coefficients(s, on)
        if len(f):
            d = point_gradients(s, formula, v) * (c * per_facet[f])[:, None]
            for k in range(3):
                g[:, k] += np.bincount(v, weights=d[:, k], minlength=s.nv)
    return g


def body_gradient(s, i: int) -> np.ndarray:
    """Gradient (nv, 3) of body ``i``'s area."""
    w = np.asarray(s.bodies.facet_matrix.getrow(i).todense()).ravel()
    return facet_area_gradient(s, w)


def volume_gradients(t):
    """(nb, nv, 3) gradients of the body areas."""
    s = t.surface
    return np.stack([body_gradient(s, i) for i in range(s.bodies.n)]) if s.bodies.n else \
        np.zeros((0, s.nv, 3))


# ---------------------------------------------------------------------------
# totals


class StringTotals(Totals):
    """Energy, length and body areas of a string surface (the attributes
    of :class:`pyevolver.methods.totals.Totals`; ``total_area`` is the total
    length, as in REF)."""

    def __init__(self, s):
        self.surface = s
        self.facet_area = np.zeros(0)
        self.facet_volume = np.zeros(0)
        self.facet_N2 = np.zeros((0, 3))
        self.total_area = self.total_length
        self.terms = {}
        energy = float(self.edge_length @ s.edge_tension)
        self.terms["edge_tension"] = energy
        self.con_energy = vertex_energy(s)
        self.con_content = None
        energy += self.con_energy
        b = s.bodies
        self.sfacet_area = facet_areas(s, self) if len(s.sf_ptr) > 1 else np.zeros(0)
        self.volumes = (b.facet_matrix @ self.sfacet_area + b.volconst) if b.n else \
            np.zeros(0)
        self.energy = self._finish_energy(energy, self._gravity() if b.n else 0.0)

    def _facet_gravity(self):
        return facet_gravity(s=self.surface, t=self)

    def volume_magnitudes(self):
        s = self.surface
        owner = facet_entries(s)[0]
        per = np.bincount(owner, weights=np.abs(_edge_area(*chain_points(s, self))),
                          minlength=len(s.sf_ptr) - 1)
        return abs(s.bodies.facet_matrix) @ per


MODEL_TOTALS["string"] = StringTotals
