"""Files in other formats: the meshio plugin (``.fe`` for meshio, ``export``)."""
from .meshio_plugin import (EXPORT_FORMATS, export, read_fe, register, surface_mesh,  # noqa: F401
                            write_fe, write_mesh)

__all__ = ["EXPORT_FORMATS", "export", "read_fe", "register", "surface_mesh", "write_fe",
           "write_mesh"]
