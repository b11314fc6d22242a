"""Healing of gaps, holes, overlaps and intersections with four-sided bicubic
B-spline approximants joined G0/G1 (Hamann & Jean 1996, paper 001; handbook
§29.3; Soni & Hamann 1993, paper 003)."""

from .approximant import LocalApproximant, ResolutionStep, local_approximant
from .boundary import Boundary, as_boundary, corners_boundary
from .clipping import SurfaceSource
from .interpolant import Interpolant
from .multiquadric import HardyMode

# one local approximant (approximant.py and the modules of its steps)
__all__ = [
    "Boundary",
    "HardyMode",
    "Interpolant",
    "LocalApproximant",
    "ResolutionStep",
    "SurfaceSource",
    "as_boundary",
    "corners_boundary",
    "local_approximant",
]
