"""The result of :meth:`Session.g <pyevolver.session.core.Session.g>`: one
object with the run's final numbers that is also the list of its steps (as
``g`` returned before, so ``for r in s.g(5)`` and ``s.g(1)[0].energy`` keep
working)."""
from __future__ import annotations

from typing import Any

import numpy as np


class GResult(list):
    """The steps of a ``g`` run (:class:`~pyevolver.evolve.iterate.StepResult`
    each: ``energy``, ``area``, ``scale``, ``pressures``, ``message``) and
    the state after the run.

    Attributes
    ----------
    energy, area : float
        Total energy and area after the run.
    scale : float
        The last step's scale (the session's ``scale`` without steps).
    pressures : numpy.ndarray
        The bodies' pressures (Lagrange multipliers of fixed volumes) after
        the last step; empty without steps.
    quantity_pressures : dict
        The fixed quantities' Lagrange multipliers after the last step.
    """

    energy: float = float("nan")
    area: float = float("nan")
    scale: float = float("nan")
    pressures: np.ndarray = np.zeros(0)
    quantity_pressures: dict = {}

    @property
    def steps(self) -> list:
        """The per-step records (a plain list)."""
        return list(self)

    @property
    def energies(self) -> np.ndarray:
        """The energy after each step."""
        return np.array([r.energy for r in self], float)

    def finish(self, session: Any) -> "GResult":
        """Fill the final numbers from ``session`` (after the run)."""
        t = session.totals
        if t is not None:
            self.energy = float(t.energy)
            self.area = float(getattr(t, "total_area", float("nan")))
        if len(self):
            last = self[-1]
            self.scale = float(last.scale)
            self.pressures = np.asarray(last.pressures, float)
            self.quantity_pressures = dict(last.quantity_pressures or {})
        else:
            self.scale = float(session.settings.get("scale", float("nan")))
            self.pressures = np.zeros(0)
            self.quantity_pressures = {}
        return self

    def __repr__(self) -> str:
        n = len(self)
        text = f"<g: {n} step{'s' if n != 1 else ''}, energy {self.energy:.10g}, " \
               f"area {self.area:.10g}, scale {self.scale:.6g}"
        if len(self.pressures):
            text += ", pressures " + " ".join(f"{p:.6g}" for p in self.pressures)
        return text + ">"

    __str__ = __repr__
