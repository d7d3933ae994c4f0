"""Mesh upkeep: operations that change the surface's topology or smooth it.

Each operation takes a Surface and returns a new one (or modifies
coordinates only), so the session can restore the previous surface when a
command fails.
"""
from .grow import grow
from .refine import refine

__all__ = ["grow", "refine"]
