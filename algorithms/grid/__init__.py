"""Structured surface grids (003; 000 §29.1): distributions, TFI, elliptic refinement, quality.

* :mod:`.distribution` -- point distributions along a line in exact arc length;
* :mod:`.tfi` -- the normalized arc-length distribution mesh and weighted TFI;
* :mod:`.elliptic` -- elliptic refinement on the surface's metric (003 eqs. 5-9);
* :mod:`.quality` -- orthogonality, skewness, Jacobian... measured on the surface;
* :mod:`.structured` -- :func:`grid_surface`, the whole step on one surface;
* :mod:`.io` -- Plot3D, CGNS and VTK writers.
"""

from __future__ import annotations

from .distribution import by_curvature, geometric, points_along, stretched, uniform
from .elliptic import EllipticResult, refine
from .quality import GridQuality, grid_quality
from .structured import Spacing, SurfaceGrid, grid_surface
from .tfi import distribution_mesh, transfinite

__all__ = [
    "EllipticResult",
    "GridQuality",
    "Spacing",
    "SurfaceGrid",
    "by_curvature",
    "distribution_mesh",
    "geometric",
    "grid_quality",
    "grid_surface",
    "points_along",
    "refine",
    "stretched",
    "transfinite",
    "uniform",
]
