"""Data around a hole for the fill (:mod:`.fill`): a ring of projections beyond the boundary.

Where the segments of a Coons grid hit nothing (a hole), 001 §5 interpolates
the positions ``t`` found elsewhere on the grid. For a hole bounded by the four
curves the only positions found are those of the curves themselves (all at
``t = 1/2`` with ``keep_boundary``): the fill is then the Coons patch and the
surrounding surfaces' shape (their tangent planes at the rim, their curvature)
never reaches it.

Beyond the paper, the grid is extended outward by ``rows`` rows and columns
(every grid line continued by the quadratic through its last three points:
the same spacing, tangent and bending at the rim), each new point
gets a normal by central differences (eq. 6) and the segment ``x ± d n``
(eq. 7), and the segments are projected onto the sources like the grid's own
(eqs. 9-11). The positions found there are further data for eqs. (12)-(14):
they carry the surroundings' slope and bending across the rim into the hole.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .coons import CoonsGrid
from .offsets import grid_normals

__all__ = ["Ring", "extend_grid", "ring_segments"]


@dataclass(frozen=True, eq=False)
class Ring:
    """The Coons grid extended by ``rows`` on every side.

    Attributes
    ----------
    u, v : (M + 1 + 2 rows, N + 1 + 2 rows) float
        Grid parameters, continued linearly beyond ``[0, 1]``.
    outer : (M + 1 + 2 rows, N + 1 + 2 rows) bool
        True on the added rows and columns.
    upper, lower : (q, 3) float
        Segment ends of the added points (``q = outer.sum()``), in the order of
        ``outer``'s True entries.
    rows : int
    """

    u: NDArray
    v: NDArray
    outer: NDArray
    upper: NDArray
    lower: NDArray
    rows: int

    def inner(self, array: NDArray) -> NDArray:
        """The part of an extended ``array`` over the original grid."""
        r = self.rows
        return array[r:-r, r:-r]


def _extend_axis0(array: NDArray, rows: int, degree: int) -> NDArray:
    """Rows ``-rows .. -1`` and ``M + 1 .. M + rows`` by polynomial extrapolation."""
    k = np.arange(1, rows + 1, dtype=float)
    nodes = np.arange(degree + 1, dtype=float)
    # Lagrange weights of nodes 0..degree evaluated at -k: (rows, degree + 1)
    weights = np.ones((rows, degree + 1))
    for j in range(degree + 1):
        for i in range(degree + 1):
            if i != j:
                weights[:, j] *= (-k - nodes[i]) / (nodes[j] - nodes[i])
    low = np.tensordot(weights, array[:degree + 1], axes=(1, 0))[::-1]
    high = np.tensordot(weights, array[::-1][:degree + 1], axes=(1, 0))
    return np.concatenate([low, array, high])


def extend_grid(array: NDArray, rows: int, degree: int = 2) -> NDArray:
    """A grid (``(M + 1, N + 1, ...)``) continued by ``rows`` on every side.

    Each grid line is extrapolated by the polynomial of ``degree`` through its
    ``degree + 1`` last points (with ``degree=2`` the continuation keeps the
    lines' position, tangent and bending at the rim; corners are extrapolated
    along both directions in turn).
    """
    degree = int(min(degree, array.shape[0] - 1, array.shape[1] - 1))
    out = _extend_axis0(np.asarray(array, dtype=float), rows, degree)
    return np.swapaxes(_extend_axis0(np.swapaxes(out, 0, 1), rows, degree), 0, 1)


def ring_segments(coons: CoonsGrid, distance: float, rows: int) -> Ring:
    """The extended grid's added points and their segments ``x ± d n`` (eqs. 6-7).

    Parameters
    ----------
    coons : CoonsGrid
        ``(M + 1, N + 1)`` points; ``rows`` must be at most ``min(M, N)``.
    distance : float
        ``d`` of eq. (7).
    rows : int >= 1
    """
    rows = int(min(rows, *coons.resolution))
    points = extend_grid(coons.points, rows)
    normals = grid_normals(points)
    outer = np.ones(points.shape[:2], bool)
    outer[rows:-rows, rows:-rows] = False
    x, n = points[outer], normals[outer]
    return Ring(extend_grid(coons.u, rows), extend_grid(coons.v, rows), outer,
                x + distance * n, x - distance * n, rows)
