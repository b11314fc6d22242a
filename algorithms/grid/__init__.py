"""Structured surface grids (003; 000 §29.1): distributions, TFI, elliptic refinement, quality.

* :mod:`.distribution` -- point distributions along a line in exact arc length;
* :mod:`.tfi` -- the normalized arc-length distribution mesh and weighted TFI;
* :mod:`.elliptic` -- elliptic refinement on the surface's metric (003 eqs. 5-9);
* :mod:`.quality` -- orthogonality, skewness, Jacobian... measured on the surface;
* :mod:`.structured` -- :func:`grid_surface`, the whole step on one surface;
* :mod:`.held` -- curves held as grid lines;
* :mod:`.network` -- :func:`grid_network`, point-matched blocks over a patch network;
* :mod:`.faces` -- which trimmed faces a block can cover;
* :mod:`.io` -- Plot3D, CGNS and VTK writers.
"""

from __future__ import annotations

from .distribution import by_curvature, geometric, points_along, stretched, uniform
from .elliptic import EllipticResult, refine
from .network import NetworkGrid, grid_network
from .quality import GridQuality, cell_skewness, grid_quality
from .structured import Spacing, SurfaceGrid, grid_surface
from .tfi import distribution_mesh, transfinite

__all__ = [
    "EllipticResult",
    "GridQuality",
    "NetworkGrid",
    "Spacing",
    "SurfaceGrid",
    "by_curvature",
    "cell_skewness",
    "distribution_mesh",
    "geometric",
    "grid_network",
    "grid_quality",
    "grid_surface",
    "points_along",
    "refine",
    "stretched",
    "transfinite",
    "uniform",
]
