"""Reading and writing geometry in other programs' formats: NURBS curves, surfaces and solids
in GoTools ``.g2``, triangle meshes in STL."""

from .g2 import CLASS_IDS, format_g2, read_g2, write_g2
from .stl import read_stl, write_stl

__all__ = ["CLASS_IDS", "format_g2", "read_g2", "read_stl", "write_g2", "write_stl"]
