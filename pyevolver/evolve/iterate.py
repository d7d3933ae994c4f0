"""The ``g`` iteration: one gradient-descent step under constraints (spec §7).

Per step: forces from every energy; fixed vertices held; level-set
constraints by tangent projection and Newton projection back; fixed body
volumes and FIXED quantities through Lagrange multipliers with the
restoring loop; the optimizing-scale line search or a fixed scale.
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..constraints import (displace, project_tangent, project_to_constraints, release_one_sided,
                       restore_state, state)
from ..errors import UnsupportedError
from ..threads import blas_limited
from . import fastpath as FP, gradient as GR, optparams as OP
from ..errors import ConstraintError
from .mobility import Mobility, diffuse, jiggle_vertices, normal_project


def _solve(A, d):
    """``A⁻¹ d``, least squares when A is singular (restoring coefficients,
    multipliers)."""
    A = np.asarray(A, dtype=float)
    if A.shape == (1, 1) and A[0, 0] != 0 and math.isfinite(A[0, 0]) and \
            np.all(np.isfinite(d)):
        # one fixed value (a body): LAPACK's solve of a 1 x 1 system is this
        # division, bit for bit, at a tenth of the cost
        return np.asarray(d, dtype=float) / A[0, 0]
    if A.size and np.all(np.isfinite(A)) and np.all(np.isfinite(d)) \
            and (A[0, 0] == 0 if A.shape == (1, 1) else np.linalg.cond(A) >= 1e10):
        # dependent constraint gradients (an icosahedron's area and volume
        # gradients are both radial): the minimum-norm least-squares step
        # instead of coefficients of 1e13 whose cancellation is round-off
        # (1 x 1: the condition number is 1, or infinite for 0)
        return np.linalg.lstsq(A, d, rcond=1e-10)[0]
    try:
        return np.linalg.solve(A, d)        # non-finite values: the caller restores
    except np.linalg.LinAlgError:
        return np.full(len(d), np.nan)


INFINITE_WARNING = "WARNING 1864: Motion would cause infinite energy. Restoring coordinates."


class _Infinite(Exception):
    """A trial motion reached an infinite or NaN energy."""


@dataclass
class IterateSettings:
    """What a ``g`` step reads of its caller's settings and toggles.

    ``scale`` is the starting (or, with ``fixed_scale``, the fixed) scale;
    the optimizing search ends at :attr:`StepResult.scale`, which the caller
    keeps as its next ``scale``.
    """

    scale: float = 0.1
    scale_limit: float = 1.0
    scale_scale: float = 1.0
    target_tolerance: float = 1e-4
    fixed_scale: bool = False          # the ``m`` command: no line search
    conj_grad: bool = False
    ribiere: bool = True               # Polak-Ribiere, else Fletcher-Reeves
    check_increase: bool = False
    hessian_normal: bool = True        # ``hessian``: normal motion only
    hessian_backtrack: bool = False    # ``hessian``: halve a step that raises the energy
    area_normalization: bool = False   # mobility 1 / (star area / 3) (evolve.mobility)
    normal_motion: bool = False        # velocity projected on the vertex normal
    runge_kutta: bool = False          # a fixed-scale step by RK4
    diffusion: bool = False            # gas diffusion between bodies
    diffusion_coeff: float = 0.0
    jiggle: bool = False               # a random perturbation after each step
    approximate_curvature: bool = False  # mobility: the inverse linear mass matrix
    jiggle_temperature: float = 0.05

    @classmethod
    def from_mappings(cls, settings: Mapping, toggles: Mapping) -> "IterateSettings":
        """From a settings dict (``scale``, ``scale_limit``, ...) and a
        toggles dict (``conj_grad``, ``_fixed_scale``, ...) as the command
        language keeps them."""
        return cls(scale=settings["scale"], scale_limit=settings["scale_limit"],
                   scale_scale=settings.get("scale_scale", 1.0),
                   target_tolerance=settings.get("target_tolerance", 1e-4),
                   fixed_scale=bool(toggles.get("_fixed_scale", 0)),
                   conj_grad=bool(toggles.get("conj_grad", 0)),
                   ribiere=bool(toggles.get("ribiere", 1)),
                   check_increase=bool(toggles.get("check_increase", 0)),
                   hessian_normal=bool(toggles.get("hessian_normal", 1)),
                   hessian_backtrack=bool(toggles.get("hessian_backtrack", 0)),
                   area_normalization=bool(toggles.get("area_normalization", 0)),
                   normal_motion=bool(toggles.get("normal_motion", 0)),
                   runge_kutta=bool(toggles.get("runge_kutta", 0)),
                   diffusion=bool(toggles.get("diffusion", 0)),
                   diffusion_coeff=float(settings.get("diffusion_coeff", 0.0)),
                   jiggle=bool(toggles.get("jiggle", 0)),
                   approximate_curvature=bool(toggles.get("approximate_curvature", 0)),
                   jiggle_temperature=float(settings.get("jiggle_temperature", 0.05)))


@dataclass
class StepResult:
    """What one ``g`` (or ``hessian``) step did (``scipy.optimize``-style result).

    ``printed``: the step was taken (a progress line is due; the caller
    counts the iteration and adds ``scale`` to its total time).  ``totals``:
    the evaluation of the surface after the step.  ``motion``: the force
    (nv, 3), the moving vertices' starting coordinates (nv, 3) and the
    motion direction (nv, 3) of a ``g`` step, with its surface first (read
    by the ``v_force``, ``v_oldx`` and ``v_velocity`` attributes).  In the
    list that ``g n`` returns, only the last step keeps its ``totals``
    and ``motion`` (a few megabytes each on large surfaces).
    """

    energy: float
    area: float
    scale: float
    pressures: np.ndarray
    quantity_pressures: dict
    printed: bool = True
    message: str = ""
    warnings: list = field(default_factory=list)
    totals: Any = None
    motion: tuple | None = None


def _check_freedom(s, mobile, ncons):
    """REF's ERROR 3004 before a step: fewer degrees of freedom than fixed
    volumes and quantities (e.g. column.fe after ``t 0.1`` leaves only FIXED
    vertices and its fixed volume).  A mobile vertex counts its coordinates
    less its two-sided level-set constraints, or its boundary's parameters
    (an upper bound of the motions, so only a sure shortage is an error)."""
    if ncons == 0:
        return
    free = np.where(mobile, s.X.shape[1], 0)
    if s.vcon:
        for c, on in s.vcon.items():
            flags = getattr(s.constraints.get(c), "flags", set()) or set()
            if not ({"nonnegative", "nonpositive"} & set(flags)):
                free = free - (mobile & np.asarray(on, bool))
    bnd = s.vattr.get("boundary")
    if bnd is not None:
        for bid, b in s.boundaries.items():
            sel = mobile & (bnd == bid)
            free = np.where(sel, b.nparams, free)
    dof = int(np.maximum(free, 0).sum())
    if dof < ncons:
        raise ConstraintError(f"Degrees of freedom, {dof}, is less than number of "
                              f"constraints, {ncons}. (REF's ERROR 3004; perhaps a "
                              "constraint is not applied to any elements?)")


class _Constraints:
    """Fixed global values: body volumes and FIXED quantities."""

    def __init__(self, surface):
        s = surface
        b = s.bodies
        self.bodies = [i for i in range(b.n) if not math.isnan(b.target[i])]
        self.redundant = None
        if s.torus_filled and self.bodies:
            # one body is redundant in a filled torus: not restored, but its
            # difference counts in the restoring loop's sum (REF's itdebug
            # "Diff" on twointor.fe is twice body 2's difference)
            self.redundant = self.bodies[0]
            self.bodies = self.bodies[1:]
        self.quantities = [q for q in s.quantities.values() if q.kind == "fixed"]
        # REF makes bodies named quantities (boundary integrals; groups but torus)
        self.named_bodies = any(bd.content is not None or bd.energy is not None
                                for bd in s.boundaries.values()) \
            or s.symmetry_group not in (None, "torus")

    def __len__(self):
        return len(self.bodies) + len(self.quantities)

    def values(self, t):
        return np.array([t.volumes[i] for i in self.bodies] +
                        [t.quantity_values[q.name] for q in self.quantities])

    def targets(self, s):
        return np.array([s.bodies.target[i] for i in self.bodies] +
                        [q.target for q in self.quantities])

    def redundant_diff(self, t, default):
        """The redundant body's |target − volume| / tolerance (0 without one)."""
        if self.redundant is None:
            return 0.0
        i = self.redundant
        b = t.surface.bodies
        tol = default * t.volume_magnitudes()[i] if self.named_bodies else default
        return float(abs(b.target[i] - t.volumes[i]) / (tol if tol > 0 else default))

    def tolerances(self, t, default):
        """Tolerance of each constrained value in the restoring loop, which
        stops when sum |d_i| / tol_i <= 1 (REF's itdebug prints that sum as
        "Diff").

        A named quantity's tolerance is its TOLERANCE when set (>= 0), else
        ``target_tolerance`` times the sum of the absolute values of its
        element contributions.  A body's is ``target_tolerance`` itself,
        unless the Evolver converts bodies to named quantities (it does so
        when a boundary carries ENERGY or CONTENT integrals, e.g. column.fe),
        when it is scaled like a quantity's.  Measured with itdebug on
        tankex.fe and catbody.fe (absolute), qmound.fe and column.fe (scaled).
        """
        if self.bodies:
            if self.named_bodies:
                mag = t.volume_magnitudes()
                out = [default * mag[i] for i in self.bodies]
            else:
                out = [default] * len(self.bodies)
        else:
            out = []
        for q in self.quantities:
            if q.tolerance is not None and q.tolerance >= 0:
                out.append(q.tolerance)
            else:
                out.append(default * t.quantity_value(q, magnitude=True))
        out = np.array(out, dtype=float)
        return np.where(out > 0, out, default)

    def gradients(self, t):
        gs = []
        if self.bodies:
            vg = GR.body_volume_gradients(t)
            gs += [vg[i] for i in self.bodies]
        for q in self.quantities:
            gs.append(GR.quantity_gradient(t, q))
        return gs


def _refuse_normal_motion(s, cons):
    """The cases of ``normal_motion`` whose REF numbers were not reproduced.

    Equal to REF: cube.fe (with its volume off target too), cat.fe, quad.fe
    (``r; g 10``, ``r; U; g 10``).  Not: a fixed volume with fixed vertices
    (catbody.fe) or with level-set constraints (mound.fe), where REF's
    second step moves mirror-image vertices differently.
    """
    if s.string:
        raise UnsupportedError("normal_motion in the string model",
                               "the string model's vertex normal is not implemented")
    if len(cons) and (bool(s.vattr["fixed"].any()) or bool(s.vcon)
                      or bool((s.vattr.get("boundary", np.zeros(1)) != 0).any())):
        raise UnsupportedError("normal_motion with fixed volumes or quantities and fixed or "
                               "constrained vertices", "REF's normal there was not reproduced")


def _refuse_approx_curv(s, cons, mobile):
    """The cases of ``approx_curv`` not reproduced: fixed volumes or
    quantities (REF 2.70 exits at the first ``g``: cube.fe, mound.fe,
    slidestr.fe) and moving vertices on level-set constraints (1.5e-5 off
    REF on a constrained film)."""
    if len(cons):
        raise UnsupportedError("approx_curv with fixed volumes or quantities",
                               "evolver-nox-d 2.70 exits at the first g there")
    if s.vcon and any(bool((m & mobile).any()) for m in s.vcon.values()):
        raise UnsupportedError("approx_curv with vertices on level-set constraints",
                               "REF's projection in that metric was not reproduced")


class Iterator:
    """Runs ``g`` steps on a surface; keeps the state carried from step to
    step (conjugate-gradient history, whether the pressures are valid, the
    damping of ``newton``).

    Parameters
    ----------
    surface : Surface or callable
        The surface, or a function returning the current one (when the
        caller replaces its surface between steps, e.g. by ``autochop``).
    settings : IterateSettings, optional
        Used by :meth:`step` and the restoring of :meth:`_move` unless a
        step is given its own.
    """

    def __init__(self, surface, settings: IterateSettings | None = None):
        self._surface = surface
        self.settings = settings if settings is not None else IterateSettings()
        self.cg_history = None
        self.cg_S_old = 0.0
        self.cg_f_old = None
        # the multipliers (pressures) are set by a g step; hessian needs them
        self.pressures_valid = False
        self.newton_delta: float | None = None   # the damping the last `newton` run ended with
        self._diverged = False        # a constraint projection of the last move diverged
        self.rng = np.random.default_rng(1)      # the jiggle toggle's (the caller's may replace it)

    # -- helpers ----------------------------------------------------------------
    @property
    def surface(self):
        """The current surface."""
        s = self._surface
        return s() if callable(s) else s

    def _mobile(self):
        s = self.surface
        return ~s.vattr["fixed"]

    def _project_tangent(self, vecs):
        """Project vectors (list of (nv,3)) onto the constraint tangent spaces."""
        return project_tangent(self.surface, vecs)

    def _mobility(self, t):
        """The force-to-velocity conversion at the evaluation ``t`` (REF
        takes the restoring motions' metric at the moved positions: catbody.fe
        ``r; g 10`` with area normalization, 6e-4 off with the starting one)."""
        return Mobility(t, self.settings.area_normalization,
                        self.settings.approximate_curvature, self._mobile())

    def _constrained_dirs(self, t, cons, mobile):
        gs = cons.gradients(t)
        for g in gs:
            g[~mobile] = 0.0
        us = self._mobility(t).apply(self._project_tangent(gs))
        k = len(gs)
        A = np.empty((k, k))
        for i in range(k):
            for j in range(k):
                A[i, j] = float(np.sum(gs[i] * us[j]))
        for i in range(k):
            if A[i, i] == 0:
                A[i, i] = 1.0
        return gs, us, A

    def _project(self, moved):
        """Project moved vertices to their constraints; a diverging
        projection marks the step for undoing."""
        if len(project_to_constraints(self.surface, moved)):
            self._diverged = True

    def _hold_one_sided(self, t):
        """After the actual move: the vertices its first projection put on a
        one-sided constraint, and that the restoring moved off it, are
        projected back onto it (REF: drop_afm.fe's defect vertex ends the
        step exactly on its NONNEGATIVE plane; trial moves do not do this)."""
        hold = getattr(self, "_move_hits", None)
        self._move_hits = None
        if not hold:
            return t
        s = self.surface
        idx = np.unique(np.concatenate(list(hold.values())))
        project_to_constraints(s, idx, hold=hold)
        return s.evaluate()

    # -- one move ------------------------------------------------------------------
    def _move(self, base, vel, scale, cons, us, A, mobile, targets, report, trial=False):
        """Trial move M(scale) from the snapshot ``base`` (:func:`surface.state`):
        step, project, restore constraint values.  With ``us`` None the
        restoring directions are taken at the moved positions."""
        s = self.surface
        displace(s, base, scale * vel)
        moved = np.nonzero(mobile)[0]
        s._one_sided_hits = None
        self._project(moved)
        self._move_hits = None if trial else s._one_sided_hits
        if not len(cons):
            return s.evaluate()
        tol = self.settings.target_tolerance
        t = s.evaluate()
        d = targets - cons.values(t)
        err = float(np.sum(np.abs(d) / cons.tolerances(t, tol))) + cons.redundant_diff(t, tol)
        if us is None:
            # restore along the constraint gradients at the moved positions
            _, us, A = self._constrained_dirs(t, cons, mobile)
        cur_us, cur_A = us, A
        start, d_start = state(s), d
        factor = 1.0
        for it in range(10):
            delta = factor * _solve(cur_A, d)
            prev = state(s)
            shift = sum(dl * u for dl, u in zip(delta, cur_us))
            displace(s, prev, shift)
            self._project(moved)
            t_new = s.evaluate()
            d_new = targets - cons.values(t_new)
            err_new = (float(np.sum(np.abs(d_new) / cons.tolerances(t_new, tol)))
                       + cons.redundant_diff(t_new, tol))
            if err_new <= 1.0:
                # converged: REF stops here even when the difference grew
                # (itdebug on check 14, step 7: "Diff: 0.382765", one
                # volume_restore(), done at 0.6068)
                if it == 9 and not trial:
                    # converged at the last of the 10 corrections: REF's count
                    # ran out, and the next step starts CG afresh (catbody.fe
                    # with area normalization, `U; r; g 3`)
                    self.cg_history = None
                return t_new
            if err_new > 100 * err and err > 0:
                if report is not None:
                    report.append(f"Total constraint difference would increase by factor of "
                                  f"{err_new / err:f}.")
                    report.append("Aborting constraint adjustment.")
                restore_state(s, prev)
                return s.evaluate()
            if err_new > 1.01 * err:
                # REF (itdebug): "Diff increased. Restoring coords." puts back
                # the coordinates the restoring started from (after the move
                # and the projection), whatever corrections succeeded since;
                # the next correction is computed there with gradients taken
                # there, times a factor halved at each consecutive increase
                # (reset by a success), and judged against the increased value
                # (REF's Old_diff).  Checked step for step on checks 13 and 14.
                restore_state(s, start)
                t = s.evaluate()
                d = d_start
                _, cur_us, cur_A = self._constrained_dirs(t, cons, mobile)
                self._carry = (cur_us, cur_A)
                err = err_new
                factor *= 0.5
                continue
            factor = 1.0
            improved = err_new < 0.5 * err
            t, d, err = t_new, d_new, err_new
            if not improved:
                _, cur_us, cur_A = self._constrained_dirs(t, cons, mobile)
            self._carry = (cur_us, cur_A)
        # REF's loop ends with one more, unchecked, correction (itdebug: a last volume_restore(),
        # no "Next diff" after the tenth check), then warns with the last difference it checked
        delta = factor * _solve(cur_A, d)
        displace(s, state(s), sum(dl * u for dl, u in zip(delta, cur_us)))
        self._project(moved)
        t = s.evaluate()
        if report is not None and not trial:
            # (REF reports this for the actual move only, not for trial moves)
            report.append("WARNING 1055: Volume or quantity constraints don't converge in "
                          "10 projections.")
            report.append(f"Total difference {err:g} times tolerance")
            self.cg_history = None
        return t

    # -- the step --------------------------------------------------------------------
    @blas_limited
    def step(self, settings: IterateSettings | None = None, start: Any = None) -> StepResult:
        """One ``g`` step: the motion, the line search (or the fixed
        scale) and the restoring of the fixed values.

        Parameters
        ----------
        settings : IterateSettings, optional
            Replaces :attr:`settings` (kept for later steps and moves).
        start : Totals, optional
            The previous step's ``totals`` when nothing changed since (one
            ``g n``): the start's evaluation if the coordinates are the same.

        Returns
        -------
        StepResult
            With ``totals`` the evaluation after the step and ``motion``
            the step's force, start and direction.
        """
        if settings is not None:
            self.settings = settings
        settings = self.settings
        fast = FP.step(self, settings, start, StepResult, _solve)   # (plain surfaces: fastpath)
        if fast is not None:
            return fast
        s = self.surface
        mobile = self._mobile()
        cons = _Constraints(s)
        _check_freedom(s, mobile, len(cons))
        end = self.__dict__.pop("_end", None)
        if (start is not None and end is not None and end[0] is start and start.surface is s
                and end[1].shape == s.X.shape and np.array_equal(end[1], s.X)):
            t0 = start
        else:
            t0 = s.evaluate()
        if settings.diffusion and s.bodies.n:
            self._diffuse(t0, settings)
        f = -GR.energy_gradient(t0)
        # optimizing parameters: moved by -scale * pscale * dE/dp with the vertices
        popt = bool(OP.names(s))
        if popt:
            if len(cons):
                OP.refuse(s, "fixed volumes or FIXED quantities")
            for opt in ("area_normalization", "normal_motion", "runge_kutta",
                        "approximate_curvature"):
                if getattr(settings, opt):      # the parameters' mobility is not measured
                    OP.refuse(s, opt)
            self._pbase: np.ndarray | None = OP.values(s)
            # in the scaled parameter q = p / pscale the force is
            # -pscale dE/dp, moved like a vertex coordinate (with conj_grad
            # too: the parameters join the CG sums and history)
            pscale = OP.scales(s)
            if settings.conj_grad and np.any(pscale != 1.0):
                # REF's CG sums with PSCALE: matched on one hexagon (0.3),
                # not on another (0.5); only PSCALE 1 is measured exactly
                OP.refuse(s, "conj_grad and a PSCALE other than 1")
            graw = OP.gradient(s)
            fq = -pscale * graw
            pvel = pscale * fq
        else:
            self._pbase = None
            fq = graw = np.zeros(0)

        def params_at(scale_):
            if popt:
                OP.set_values(s, self._pbase + scale_ * pvel)
        # the vertex attributes v_force and v_oldx read the last step's force
        # (REF: FIXED vertices included, not projected onto constraints; +0.0
        # turns -0 into 0) and the moving vertices' starting coordinates
        # (pyevolver.commands.attributes)
        motion: tuple = (s, f + 0.0, np.where(mobile[:, None], s.X, 0.0))
        f[~mobile] = 0.0
        f_raw = f
        s._one_sided_released = None
        targets = cons.targets(s)
        if settings.normal_motion:
            _refuse_normal_motion(s, cons)
        if settings.approximate_curvature:
            _refuse_approx_curv(s, cons, mobile)
        mob = self._mobility(t0)
        for _pass in range(2):
            (f_tan,) = self._project_tangent([f_raw])
            (f,) = mob.apply([f_tan])
            lam = np.zeros(len(cons))
            if len(cons):
                gs, us, A = self._constrained_dirs(t0, cons, mobile)
                b = np.array([float(np.sum(f * g)) for g in gs])
                lam = _solve(A, b)
                vel = f - sum(l * u for l, u in zip(lam, us))
            else:
                gs, us, A = [], [], np.zeros((0, 0))
                vel = f
            if _pass:
                break
            # hit one-sided constraints that the force (with the constraints'
            # multipliers) takes a vertex off, for this step
            release_one_sided(s, f_raw - sum(l * g for l, g in zip(lam, gs)))
            if not getattr(s, "_one_sided_released", None):
                break
        if settings.normal_motion:
            # (REF projects before CG, whose sums see the projected velocity,
            # and the CG direction again: cube.fe and cat.fe `r; U; g 10`)
            vel = normal_project(t0, vel)
        # conjugate gradient
        if settings.conj_grad:
            # Fletcher-Reeves: gamma = S/S_old with S = sum vel.f; Polak-Ribiere
            # (the Evolver's default, toggle `ribiere`) subtracts sum vel.f_old;
            # a negative gamma restarts (PR+).  Found by printing v_velocity and
            # v_force of evolver-nox-d on cube.fe and tankex.fe.  Vertices on
            # parametric boundaries are left out of the sums and keep their
            # plain motion; the optimizing parameters add (p-scale dE/dp)^2 and
            # (their Ribiere term) to the sums but move along their plain
            # gradient (REF: the CG direction is kept in the parameters'
            # "grad", the motion uses their "velocity"; measured on the
            # shengdie torus sheets, whose ends are boundaries).
            bnd = s.vattr.get("boundary")
            cgv = mobile if bnd is None else mobile & (bnd == 0)
            S = float(np.sum(vel[cgv] * f_tan[cgv])) + float(fq @ fq)
            q_old = getattr(self, "cg_q", None)
            if self.cg_history is not None and (
                    self.cg_history.shape != vel.shape or q_old is None
                    or len(q_old) != len(fq)):
                self.cg_history = None          # the surface or parameters changed
            if self.cg_history is None or self.cg_S_old < 1e-15:
                gamma = 0.0
            else:
                num = S
                if settings.ribiere:
                    num -= float(np.sum(vel[cgv] * self.cg_f_old[cgv]))
                    num -= float(graw @ q_old)      # REF: grad·oldgrad, no pscale
                gamma = num / self.cg_S_old
                if gamma > 10 or gamma < 0:     # negative: restart (PR+)
                    gamma = 0.0
            h = vel.copy() if self.cg_history is None else vel + gamma * self.cg_history
            h[~cgv] = vel[~cgv]
            if settings.normal_motion:
                h = normal_project(t0, h)
            self.cg_history = h
            self.cg_q = graw
            self.cg_S_old = S
            self.cg_f_old = f_raw      # the Evolver keeps the unprojected force
            vel = h
        X0 = state(s)
        motion += (vel,)                        # v_velocity: the motion direction
        warnings: list[str] = []
        trial_msgs: list[str] = []
        # Trial moves start from the directions at X0 (REF resets them after
        # each trial); the repeated move after a rejected one starts from the
        # directions the rejected move last recomputed (REF keeps those),
        # checked restoring step by restoring step on check 14.
        self._carry = (us, A)
        first = [True]          # the first trial motion of the step

        def E(scale):
            self._diverged = False
            params_at(scale)
            t = self._move(X0, vel, scale, cons, us, A, mobile, targets, trial_msgs,
                           trial=True)
            e = math.nan if self._diverged else t.energy
            if not math.isfinite(e) and scale > 0 and first[0]:
                # REF: a first trial motion to an infinite (or NaN) energy ends
                # the step with WARNING 1864 (checked on an overflowing gravity)
                raise _Infinite()
            first[0] = False
            return e if math.isfinite(e) else math.inf

        smax = settings.scale_limit
        fixed_scale = settings.fixed_scale
        if fixed_scale:
            scale = settings.scale
            E0 = None
        else:
            try:
                scale, E0, s1 = self._line_search(E, settings.scale, smax)
            except _Infinite:
                return self._undo(X0, t0, settings.scale, lam, trial_msgs, motion)
        if fixed_scale and settings.runge_kutta:
            if len(cons):
                raise UnsupportedError("runge_kutta with fixed volumes or quantities",
                                       "REF's stages there were not reproduced")
            vel = self._runge_kutta(X0, vel, settings.scale_scale * scale, cons, mobile)
        # actual move (REF prints what the trial moves reported first)
        report = trial_msgs
        self._carry = (us, A)
        self._diverged = False
        params_at(settings.scale_scale * scale)
        t = self._move(X0, vel, settings.scale_scale * scale, cons, us, A,
                       mobile, targets, report)
        t = self._hold_one_sided(t)
        e = t.energy
        if not math.isfinite(e) or self._diverged or not np.all(np.isfinite(s.X)):
            return self._undo(X0, t0, scale, lam, report, motion)
        if E0 is None:
            E0 = t0.energy
        if settings.check_increase and e > E0:
            restore_state(s, X0)
            self._restore_params()
            self.cg_history = None
            warnings.append("WARNING 1865: Motion would have increased energy. Restoring "
                            "coordinates.")
            return StepResult(t0.energy, t0.total_area, scale, lam, {}, False,
                              message="increase", warnings=report + warnings,
                              totals=s.evaluate(), motion=motion)
        if not fixed_scale and e > E0 and scale > 0:
            scale = s1
            us_c, A_c = self._carry
            params_at(scale)
            t = self._move(X0, vel, scale, cons, us_c, A_c, mobile, targets, report)
            t = self._hold_one_sided(t)
            self.cg_history = None
            if not math.isfinite(t.energy) or self._diverged or not np.all(np.isfinite(s.X)):
                return self._undo(X0, t0, scale, lam, report, motion)
        if settings.jiggle:
            # iterate.htm: after the constraints are enforced "if jiggling is
            # on, the surface is randomly perturbed" (then projected again)
            self._project(jiggle_vertices(s, settings.jiggle_temperature, self.rng))
        # reported pressures: P = -lambda
        b = s.bodies
        qp = {}
        k = 0
        if b.n:
            b.lagrange[:] = 0.0
        for i in cons.bodies:
            b.lagrange[i] = -lam[k]
            k += 1
        for q in cons.quantities:
            q.pressure = -lam[k]
            qp[q.name] = q.pressure
            k += 1
        self.pressures_valid = True
        if settings.jiggle:     # (else t is the final move's evaluation, where it ended)
            t = s.evaluate()
        self._end = (t, s.X.copy())
        return StepResult(t.energy, t.total_area, scale,
                          b.lagrange.copy() if b.n else np.zeros(0), qp, True,
                          warnings=report + warnings, totals=t, motion=motion)

    def _diffuse(self, t, settings):
        """Gas diffusion at the start of a step: the fixed target volumes
        move by :func:`~pyevolver.evolve.mobility.diffuse`."""
        s = t.surface
        if s.string:
            raise UnsupportedError("diffusion in the string model",
                                   "edge_diffusion is not implemented")
        b = s.bodies
        d = diffuse(t, settings.diffusion_coeff, settings.scale)
        ok = ~np.isnan(b.target)
        b.target[ok] = b.target[ok] + d[ok]

    def _plain_velocity(self, t, cons, mobile):
        """The velocity (nv, 3) at the evaluation ``t`` without CG: the
        force held at fixed vertices, projected on the constraints, converted
        by the mobility, less the fixed values' multiples, normal-projected
        with ``normal_motion``."""
        f = -GR.energy_gradient(t)
        f[~mobile] = 0.0
        (f,) = self._mobility(t).apply(self._project_tangent([f]))
        if len(cons):
            gs, us, A = self._constrained_dirs(t, cons, mobile)
            lam = _solve(A, np.array([float(np.sum(f * g)) for g in gs]))
            f = f - sum(l * u for l, u in zip(lam, us))
        if self.settings.normal_motion:
            f = normal_project(t, f)
        return f

    def _runge_kutta(self, X0, k1, h, cons, mobile):
        """The velocity of a fixed-scale Runge-Kutta step ``h`` from the
        state ``X0`` with first stage ``k1`` (iterate.htm; the toggle acts
        only with a fixed scale, toggle.htm RUNGE_KUTTA).

        The stages of RK4 are taken at X0 + h/2 k1, X0 + h/2 k2 and
        X0 + h k3; REF 2.70 then moves by its last stage k4, not by
        (k1 + 2 k2 + 2 k3 + k4) / 6: quad.fe ``r; m 0.1; g 1`` gives
        4.41826089959718 with k4, 4.40845090908222 with the RK4 average
        (measured; docs/differences.md).
        """
        s = self.surface
        ks = [k1]
        for c in (0.5, 0.5, 1.0):
            displace(s, X0, c * h * ks[-1])
            ks.append(self._plain_velocity(s.evaluate(), cons, mobile))
        restore_state(s, X0)
        return ks[3]

    def _undo(self, X0, t0, scale, lam, report, motion=None):
        """A motion to an infinite or NaN energy, or a constraint projection
        that diverged: the coordinates are put back, with the Evolver's
        warning, and no progress line."""
        s = self.surface
        restore_state(s, X0)
        self._restore_params()
        self.cg_history = None
        return StepResult(t0.energy, t0.total_area, scale, lam, {}, False,
                          message="infinite",
                          warnings=report + [INFINITE_WARNING], totals=s.evaluate(),
                          motion=motion)

    def _restore_params(self):
        """Put the optimizing parameters back to their values before the step."""
        if getattr(self, "_pbase", None) is not None:
            OP.set_values(self.surface, self._pbase)

    def _line_search(self, E, scale, smax):
        """The optimizing-scale search of spec §7.6; returns (s, E0, s1)."""
        s = min(scale, smax)
        if s <= 0:
            s = 1e-6 * smax
        E1 = E(s)
        s1 = s
        E0 = E(0.0)
        s0 = 0.0
        E2 = s2 = None
        final = False
        if E1 < E0:
            while True:
                s = 2 * s
                E2 = E(s)
                s2 = s
                if not math.isfinite(E2):
                    s = s / 2
                    final = True
                    break
                if E2 > E1:
                    s = s / 2
                    break
                E1, s1 = E2, s2
                if s >= smax:
                    break
        else:
            n = 0
            while True:
                n += 1
                if n > 20:
                    s = 0.0
                    break
                E2, s2 = E1, s1
                s = s / 2
                if s < 1e-12 * smax:
                    s = 0.0
                    break
                E1 = E(s)
                s1 = s
                if E1 <= E0:
                    break
            s = 2 * s
        if not final:
            if s > smax:
                s = smax
            elif s > 0:
                den = E0 * (s1 - s2) + E1 * (s2 - s0) + E2 * (s0 - s1)
                if den == 0:
                    s = 0.0
                else:
                    s = ((E0 - E2) * s1 * s1 + (E1 - E0) * s2 * s2 + (E2 - E1) * s0 * s0) / (2 * den)
        s = min(s, smax)
        return s, E0, s1


def progress_line(k: int, result: StepResult, string_model: bool = False) -> str:
    """The Evolver's progress line ``k. area: ... energy: ...  scale: ...``."""
    return "%3d. %s: %#17.15g energy: %#17.15g  scale: %#g" % (
        k, "length" if string_model else "area", result.area, result.energy, result.scale)
