"""The discrete Coons patch of a boundary (001 §3, eq. 4; 000 §29.3.2).

The four boundary curves are sampled uniformly in arc length and blended
bilinearly. The parameters of the boundary samples are their normalized arc
lengths (``u_{I,0} = u_{I,N} = I / M``, ``v_{0,J} = v_{M,J} = J / N``), so the
parameters of eq. (4), which vary linearly between opposite sides, are the
uniform ones and the grid follows the curves' lengths, not their
parametrizations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError
from .boundary import Boundary

__all__ = ["CoonsGrid", "discrete_coons"]


@dataclass(frozen=True, eq=False)
class CoonsGrid:
    """Points of the discrete Coons patch.

    Attributes
    ----------
    points : (M + 1, N + 1, 3) float
        ``x_{I,J}`` of eq. (4).
    u, v : (M + 1, N + 1) float
        Their parameters ``u_{I,J}``, ``v_{I,J}`` in ``[0, 1]``.
    """

    points: NDArray
    u: NDArray
    v: NDArray

    @property
    def resolution(self) -> tuple[int, int]:
        return self.points.shape[0] - 1, self.points.shape[1] - 1


def discrete_coons(boundary: Boundary, m: int, n: int) -> CoonsGrid:
    """Discrete bilinear Coons patch (001 eq. 4) at resolution ``(m, n)``.

    Parameters
    ----------
    boundary : Boundary
    m, n : int >= 2
        Intervals in u (along the bottom curve) and v (along the left curve).

    Returns
    -------
    CoonsGrid
        Its boundary rows/columns are the arc-length samples of the curves.
    """
    if m < 2 or n < 2:
        raise InvalidGeometryError(f"resolution must be at least (2, 2), got ({m}, {n})")
    bottom, top, left, right = boundary.sample(m, n)
    u = np.broadcast_to(np.linspace(0.0, 1.0, m + 1)[:, None], (m + 1, n + 1))
    v = np.broadcast_to(np.linspace(0.0, 1.0, n + 1)[None, :], (m + 1, n + 1))
    uu, vv = u[..., None], v[..., None]
    x00, x0n, xm0, xmn = bottom[0], top[0], bottom[-1], top[-1]
    points = ((1 - uu) * left[None, :] + uu * right[None, :]
              + (1 - vv) * bottom[:, None] + vv * top[:, None]
              - ((1 - uu) * (1 - vv) * x00 + (1 - uu) * vv * x0n
                 + uu * (1 - vv) * xm0 + uu * vv * xmn))
    return CoonsGrid(points, np.array(u), np.array(v))
