"""``harmonic_energy``: the paper's regularizing energy (pyevolver's own method).

Bauer & Kuwert-style PL methods paper (shared/papers/pl-methods-biomembranes,
section 3): adding λ·E to a PL Willmore energy, with E the Dirichlet energy
of the immersion w.r.t. the conformal structure in which every triangle is
equilateral, ``E = (1/√3) Σ_edges |e|²``.  An edge method; the quantity's
modulus plays the role of λ.  E is quadratic in the vertex positions:
gradient ``(2/√3) e`` at the head and ``−(2/√3) e`` at the tail, Hessian
``(2/√3) [[I, −I], [−I, I]]`` per edge.
"""
from __future__ import annotations

import numpy as np

from ._common import assemble, scatter
from .registry import register_method

C = 1.0 / np.sqrt(3.0)


def values(ctx, m, idx):
    """Per-edge ``|e|² / √3``."""
    d = ctx.edge_vec[idx]
    return C * np.einsum("ij,ij->i", d, d)


def gradient(t, m, idx, w):
    """Gradient (nv, 3) of ``Σ w_e |e|² / √3``."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    g = (2.0 * C * np.asarray(w, float))[:, None] * t.edge_vec[idx]
    return scatter(s.nv, s.E[idx, 1], g) - scatter(s.nv, s.E[idx, 0], g)


def hessian(t, m, idx, w, basis=None):
    """Constant per-edge blocks ``(2/√3) w [[I, −I], [−I, I]]``."""
    s = t.surface
    idx = np.asarray(idx, np.int64)
    K = (2.0 * C * np.asarray(w, float))[:, None, None] * np.eye(3)[None]
    B = np.stack([np.stack([K, -K], 1), np.stack([-K, K], 1)], 1)
    return assemble(s.nv, s.E[idx], B, basis)


register_method("harmonic_energy", "edge", values, gradient, hessian)
