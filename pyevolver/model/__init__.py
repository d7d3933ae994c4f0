"""The model: a datafile's declarations (:mod:`~pyevolver.model.scene`), the
surface arrays (:mod:`~pyevolver.model.surface`), the builder from one to the
other (:mod:`~pyevolver.model.build`) and from plain arrays
(:mod:`~pyevolver.model.arrays`, behind ``Surface.from_arrays``)."""
from . import arrays  # noqa: F401  (installs Surface.from_arrays)
