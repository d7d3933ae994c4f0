"""Spontaneous curvature and area-difference elasticity (ADE): the datafile
form of the energy and the relations between the three vesicle models.

The energy (Miao, Seifert, Wortis & Döbereiner 1994, *Budding transitions
of fluid-bilayer vesicles: the effect of area-difference elasticity*,
Phys. Rev. E 49, 5389)

    F = (κ/2) ∮ (C1 + C2 − C0)² dA + (κ̄ π / (2 A D²)) (ΔA − ΔA0)²,

with the bilayer area difference ``ΔA = D ∮ (C1 + C2) dA = 2 D M``
(``M = ∫ H dA``, ``H = (C1 + C2)/2``), is in the units of this package
(``A = 4π R0²``, ``R0 = 1``; energies divided by ``2κ``; a sphere has
``∫H² dA = 4π``)

    E = ∫ (H − c0/2)² dA + (π α / A) (M − 4π m0)²,   F/(8πκ) = E/(4π),

``c0 = C0 R0``, ``α = κ̄/κ`` and ``m0 = ΔA0 / (8π D R0)`` the reduced
preferred area difference (1 for the sphere).  It is the model of
:class:`pyevolver.studies.axisymmetric.Helfrich`.

The spontaneous-curvature (SC), bilayer-couple (BC) and ADE models are
related by Legendre-type transforms (Miao et al. 1994, Sec. II; Seifert
1997, *Configurations of fluid membranes and vesicles*, Adv. Phys. 46, 13):
with ``W_BC(v, m)`` the critical values of ``∫H² dA`` at fixed
area, reduced volume ``v`` and ``M = 4π m``,

* SC: ``E_SC = ∫H² dA − c0 M + π c0²``; its critical points are BC critical
  points, ``c0`` being the multiplier of ``M``: ``∂W_BC/∂M = c0``;
* ADE: ``E_ADE(v) = W_BC(v, m) − 4π c0 m + π c0² + 4π² α (m − m0)²``
  at the ``m`` where this is stationary; the ADE shape is the SC shape of
  the effective spontaneous curvature ``c0_eff = c0 − 2π α (m − m0)``
  (the derivative of the penalty with respect to M, moved into the SC
  term).  ``α → ∞`` gives the BC model at ``m = m0``, ``α = 0`` the SC model.

These are derived here from the energies above (the signs and factors are
those of our normalization); :func:`bilayer_couple` computes BC points by
solving the SC problem for the ``c0`` whose shape has ``M = 4π m``.

In a datafile (:func:`ade_header`) the ADE term is a FUNCTION quantity of a
``mean_curvature_integral`` method instance, the spontaneous curvature the
Evolver's ``h_zero`` (a mean curvature: ``h_zero = c0/2``); evolver-nox-d
2.70 and pyevolver print the same numbers for it (tests/methods/test_ade.py).
The discrete ADE points are :mod:`pyevolver.studies.phase_ade_points`.
"""
from __future__ import annotations

import numpy as np

from .axisymmetric import CanhamResult, Helfrich, canham_reference

#: the squared mean curvature methods of the phase study that honour h_zero (the
#: MDSB cotangent energy is pyevolver's own: its datafiles do not run in the Evolver)
HZERO_METHODS = ("normal_sq_mean_curvature", "star_perp_sq_mean_curvature",
                 "star_normal_sq_mean_curvature", "cotan_sq_mean_curvature")


def ade_header(c0: float = 0.0, alpha: float = 0.0, m0: float = 1.0, area: float = 4 * np.pi,
               method: str = "star_perp_sq_mean_curvature", bend: str = "willmore") -> str:
    """Datafile top section of the Helfrich/ADE energy in units of ``2κ``.

    ``∫(H − h_zero)² dA`` by ``method`` (a quantity named ``bend``) with
    ``h_zero = c0/2``, and for ``alpha > 0`` the ADE term
    ``(π α / area) (M − 4π m0 √(area/4π))²`` as the FUNCTION quantity ``ade``
    of the method instance ``mci`` (``mean_curvature_integral``, the exact
    ``Σ_e ½ L_e θ_e`` of a polyhedron).  ``area`` is the vesicle's (fixed)
    area, so that ``m0`` is reduced by ``R0 = √(area/4π)``.
    """
    if method not in HZERO_METHODS:
        raise ValueError(f"{method} does not take a spontaneous curvature (h_zero); "
                         f"one of {HZERO_METHODS}")
    lines = [f"parameter c0 = {c0!r}   // reduced spontaneous curvature C0*R0",
             "parameter h_zero = c0/2   // the Evolver's h_zero is a mean curvature",
             f"quantity {bend} energy method {method} global"]
    if alpha:
        r0 = float(np.sqrt(area / (4 * np.pi)))
        # (the constants as parameters computed here: pyevolver's FUNCTION
        # quantities took no ``pi`` when this was written; they do now)
        lines += [f"parameter alpha = {alpha!r}   // kappa_bar/kappa",
                  f"parameter m0 = {m0!r}   // reduced preferred area difference",
                  f"parameter ade_k = {np.pi * alpha / area!r}   // pi*alpha/A",
                  f"parameter ade_m0 = {4 * np.pi * m0 * r0!r}   // 4*pi*m0*R0",
                  "method_instance mci method mean_curvature_integral global",
                  "quantity ade energy function ade_k*(mci.value - ade_m0)^2"]
    return "\n".join(lines) + "\n"


# -- the axisymmetric models and their relations --------------------------------------------

def reduced_area_difference(res: CanhamResult) -> float:
    """``Δa = M / (4π R0)`` of a reference shape (area ``4π``: ``R0 = 1``);
    1 for the sphere (Seifert, Berndl & Lipowsky 1991)."""
    return res.mean_curvature / (4 * np.pi)


def effective_c0(model: Helfrich, m: float) -> float:
    """``c0_eff = c0 − 2π α (m − m0)``: the spontaneous curvature whose SC
    problem has the ADE shape of reduced area difference ``m`` as a critical
    point (the ADE term's derivative ``2πα/A (M − 4π m0)`` with respect to
    ``M``, at ``A = 4π``, joins the SC term's ``−c0``)."""
    return model.c0 - 2 * np.pi * model.alpha * (m - model.m0)


def ade_energy_from_bc(w_bc: float, m: float, model: Helfrich) -> float:
    """``E_ADE = W_BC − 4π c0 m + π c0² + 4π² α (m − m0)²`` (area ``4π``),
    the ADE energy of the BC critical point of ``∫H² dA = w_bc`` at
    ``M = 4π m``."""
    return (w_bc - 4 * np.pi * model.c0 * m + np.pi * model.c0 ** 2
            + 4 * np.pi ** 2 * model.alpha * (m - model.m0) ** 2)


def bilayer_couple(v0: float, m: float, branch: str, n: int = 32, c0: float = 0.0,
                   coef0: np.ndarray | None = None, tol: float = 1e-12, maxit: int = 60,
                   max_step: float = 0.5) -> tuple[CanhamResult, float]:
    """The bilayer-couple critical point of ``∫H² dA`` at area ``4π``,
    reduced volume ``v0`` and ``M = ∫H dA = 4π m`` on ``branch``.

    It is the spontaneous-curvature critical point whose ``c0`` (the
    multiplier of ``M``) gives ``M = 4π m``: the secant
    method on ``c0`` from ``c0`` (steps at most ``max_step``, halved while
    the SC solve fails), each SC problem solved by :func:`canham_reference`
    from the previous shape (``coef0`` first).  ``M`` changes slowly with
    ``c0`` (``∂²W_BC/∂M²`` is large), hence the step limit.

    Returns
    -------
    (result, c0)
        The SC result at the final ``c0`` (``result.willmore`` is ``W_BC``)
        and ``c0 = ∂W_BC/∂M``.
    """
    def solve(c, a0):
        with np.errstate(invalid="ignore", over="ignore"):
            return canham_reference(v0, branch, n=n, coef0=a0, model=Helfrich(c0=c))
    target = 4 * np.pi * m
    r1 = solve(c0, coef0)
    f1 = r1.mean_curvature - target
    c_prev, f_prev = None, None
    for _ in range(maxit):
        if abs(f1) < tol * target:
            return r1, c0
        if c_prev is None or f1 == f_prev:
            step = -np.sign(f1) * 0.05
        else:
            step = -f1 * (c0 - c_prev) / (f1 - f_prev)
        step = float(np.clip(step, -max_step, max_step))
        for _ in range(8):
            try:
                r2 = solve(c0 + step, r1.coef)
                break
            except (RuntimeError, np.linalg.LinAlgError):
                step *= 0.5
        else:
            break
        c_prev, f_prev = c0, f1
        c0, r1 = c0 + step, r2
        f1 = r1.mean_curvature - target
    raise RuntimeError(f"bilayer couple at v0={v0}, m={m}: M off by {f1:.2e}")
