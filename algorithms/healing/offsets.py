"""Normals of the discrete Coons patch and its upper and lower offsets (001 eqs. 6-8).

Each grid point ``x_{I,J}`` gets a unit normal by central differences (eq. 6;
one-sided differences on the boundary rows and columns), and the segment
``a_{I,J} b_{I,J}`` of eq. (7), ``x ± d n``, along which it is projected onto
the original surfaces. The box of all ``a`` and ``b`` selects the original
geometry that takes part (clipping, :mod:`.clipping`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import DegenerateGeometryError, InvalidGeometryError
from .coons import CoonsGrid

__all__ = ["Offsets", "grid_normals", "offset_distance", "offsets"]


@dataclass(frozen=True, eq=False)
class Offsets:
    """Upper and lower offset points and their box.

    Attributes
    ----------
    upper, lower : (M + 1, N + 1, 3) float
        ``a_{I,J} = x + d n`` and ``b_{I,J} = x - d n`` (eq. 7).
    normals : (M + 1, N + 1, 3) float
        Unit normals of eq. (6).
    distance : float
        ``d``.
    box : (2, 3) float
        Axis-aligned box of all upper and lower points.
    """

    upper: NDArray
    lower: NDArray
    normals: NDArray
    distance: float
    box: NDArray


def _differences(x: NDArray, axis: int) -> NDArray:
    """Central differences ``x[i+1] - x[i-1]`` along ``axis``, one-sided at the ends."""
    y = np.moveaxis(x, axis, 0)
    d = np.empty_like(y)
    d[1:-1] = y[2:] - y[:-2]
    d[0] = y[1] - y[0]
    d[-1] = y[-1] - y[-2]
    return np.moveaxis(d, 0, axis)


def grid_normals(points: NDArray) -> NDArray:
    """Unit normals of a point grid by central differences (001 eq. 6).

    Parameters
    ----------
    points : (M + 1, N + 1, 3) float

    Returns
    -------
    (M + 1, N + 1, 3) float
        Where the cross product vanishes (a collapsed side, a corner with a
        straight angle) the normal of the corner quadrilateral is used.

    Raises
    ------
    DegenerateGeometryError
        The whole grid is flat in one direction (zero area).
    """
    cross = np.cross(_differences(points, 0), _differences(points, 1))
    length = np.linalg.norm(cross, axis=-1)
    scale = np.linalg.norm(np.ptp(points.reshape(-1, 3), axis=0))
    bad = length <= 1e-12 * scale * scale
    quad = np.cross(points[-1, -1] - points[0, 0], points[0, -1] - points[-1, 0])
    quad_length = np.linalg.norm(quad)
    if quad_length <= 1e-12 * scale * scale and np.any(bad):
        raise DegenerateGeometryError("the Coons patch has zero area: no normal direction")
    cross[bad] = quad
    length[bad] = quad_length
    return cross / length[..., None]


def offset_distance(points: NDArray) -> float:
    """``d`` of eq. (8): one eighth of the perimeter of the corner quadrilateral.

    Parameters
    ----------
    points : (M + 1, N + 1, 3) float
    """
    c = points[[0, -1, -1, 0], [0, 0, -1, -1]]
    return float(np.sum(np.linalg.norm(c - np.roll(c, -1, axis=0), axis=1)) / 8.0)


def offsets(grid: CoonsGrid, distance: float | None = None) -> Offsets:
    """Upper/lower offsets of a Coons grid (eqs. 6-8).

    Parameters
    ----------
    grid : CoonsGrid
    distance : float, optional
        ``d`` in model units; default eq. (8).
    """
    x = grid.points
    d = offset_distance(x) if distance is None else float(distance)
    if not (np.isfinite(d) and d > 0):
        raise InvalidGeometryError(f"offset distance must be finite and > 0, got {d!r}")
    n = grid_normals(x)
    a, b = x + d * n, x - d * n
    both = np.concatenate([a.reshape(-1, 3), b.reshape(-1, 3)])
    return Offsets(a, b, n, d, np.stack([both.min(axis=0), both.max(axis=0)]))
