from .core import Session

__all__ = ["Session"]
