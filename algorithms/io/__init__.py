"""Reading and writing geometry in other programs' formats: NURBS curves, surfaces and solids
in GoTools ``.g2``, triangle meshes in STL (in and out) and Wavefront OBJ (in)."""

from .g2 import CLASS_IDS, format_g2, read_g2, write_g2
from .obj import read_obj
from .stl import read_stl, write_stl

__all__ = ["CLASS_IDS", "format_g2", "read_g2", "read_obj", "read_stl", "write_g2", "write_stl"]
