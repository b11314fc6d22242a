"""surfprep: prepare B-spline CAD geometry for grid generation and downstream CAD."""

from .algorithms import NurbsCurve, NurbsSurface
from .errors import *  # noqa: F401,F403
from .errors import __all__ as _errors_all

__version__ = "0.1.0"
__all__ = ["NurbsCurve", "NurbsSurface", *_errors_all]
