"""Reading and writing NURBS curves, surfaces and solids in other programs' formats (GoTools ``.g2``)."""

from .g2 import CLASS_IDS, format_g2, read_g2, write_g2

__all__ = ["CLASS_IDS", "format_g2", "read_g2", "write_g2"]
