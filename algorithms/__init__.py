"""Pure numpy/scipy geometry of surfprep: no OCP, cadquery or build123d here."""

from .curve import NurbsCurve
from .surface import NurbsSurface

__all__ = ["NurbsCurve", "NurbsSurface"]
