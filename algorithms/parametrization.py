"""How far a surface is from chord-length parametrization (eqs. 29.1 and 29.2).

A surface :math:`s(u, v)` is *chord-length parametrized* (Handbook of Grid
Generation, section 29.2) when on the grid of its knots

.. math::

    \\frac{\\|s(u_{i+1}, v_j) - s(u_i, v_j)\\|}{\\|s(u_{i-1}, v_j) - s(u_i, v_j)\\|}
        \\approx \\frac{\\Delta u_i}{\\Delta u_{i-1}}  \\qquad (29.1)

    \\frac{\\|s(u_i, v_{j+1}) - s(u_i, v_j)\\|}{\\|s(u_i, v_{j-1}) - s(u_i, v_j)\\|}
        \\approx \\frac{\\Delta v_j}{\\Delta v_{j-1}}  \\qquad (29.2)

with :math:`\\Delta u_i = u_{i+1} - u_i` and :math:`\\Delta v_j = v_{j+1} - v_j`.

The figure computed here: take the distinct knots of each direction and split
every knot span uniformly so that each direction has at least
:data:`MIN_INTERVALS` intervals. At every interior grid node, divide the left
side of (29.1) by its right side,

.. math:: r^u_{ij} = \\frac{\\|s(u_{i+1}, v_j) - s(u_i, v_j)\\| / \\|s(u_i, v_j) - s(u_{i-1}, v_j)\\|}
                          {\\Delta u_i / \\Delta u_{i-1}},

and take the mismatch :math:`\\max(r, 1/r) \\ge 1` (likewise :math:`r^v` from
29.2). The worst mismatch over the grid is reported per direction and overall:
1.0 is a perfect chord-length parametrization; 2 means that somewhere one
parameter step covers twice the distance its neighbour covers per unit of
parameter. Nodes where one of the two chords has (numerically) zero length,
e.g. along a collapsed edge or at a pole, are skipped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .surface import NurbsSurface

__all__ = ["ParametrizationQuality", "parametrization_quality", "quality_grid",
           "MIN_INTERVALS"]

#: Minimum number of grid intervals per direction.
MIN_INTERVALS = 8
#: Chords shorter than this fraction of the grid's longest chord count as collapsed.
COLLAPSED_CHORD = 1e-12


@dataclass(frozen=True)
class ParametrizationQuality:
    """Worst chord-length mismatch of a surface (see module docstring).

    Attributes
    ----------
    worst_u, worst_v : float
        Largest mismatch ``max(r, 1/r)`` of eq. 29.1 (u) and 29.2 (v);
        ``nan`` when no interior node in that direction has two non-zero chords.
    worst : float
        ``max(worst_u, worst_v)`` ignoring nan.
    worst_u_at, worst_v_at, worst_at : (u, v) or None
        Parameters of the grid node where the worst value occurs.
    grid_shape : (a, b)
        Number of grid nodes in u and v.
    """

    worst_u: float
    worst_v: float
    worst: float
    worst_u_at: tuple[float, float] | None
    worst_v_at: tuple[float, float] | None
    worst_at: tuple[float, float] | None
    grid_shape: tuple[int, int]

    @property
    def is_chord_length(self) -> bool:
        """True when the worst mismatch is within 1 % of perfect."""
        return bool(self.worst <= 1.01)


def quality_grid(knots: NDArray, degree: int, n_control: int,
                 min_intervals: int = MIN_INTERVALS) -> NDArray:
    """Distinct knots of the domain with each span split into equal parts.

    Every span is split into ``ceil(min_intervals / n_spans)`` parts, so the
    grid has at least ``min_intervals`` intervals.
    """
    lo, hi = knots[degree], knots[n_control]
    breaks = np.unique(knots[degree:n_control + 1])
    breaks = breaks[(breaks >= lo) & (breaks <= hi)]
    n_spans = len(breaks) - 1
    parts = max(1, math.ceil(min_intervals / max(n_spans, 1)))
    steps = np.linspace(0.0, 1.0, parts + 1)[:-1]
    grid = (breaks[:-1, None] + steps[None, :] * np.diff(breaks)[:, None]).reshape(-1)
    return np.append(grid, breaks[-1])


def parametrization_quality(surface: NurbsSurface,
                            min_intervals: int = MIN_INTERVALS) -> ParametrizationQuality:
    """Worst deviation of ``surface`` from chord-length parametrization (eqs. 29.1/29.2).

    Parameters
    ----------
    surface : NurbsSurface
    min_intervals : int
        Minimum number of grid intervals per direction (default 8).

    Returns
    -------
    ParametrizationQuality
    """
    nu, nv = surface.n_control
    u = quality_grid(surface.knots_u, surface.degree_u, nu, min_intervals)
    v = quality_grid(surface.knots_v, surface.degree_v, nv, min_intervals)
    points = surface.evaluate_grid(u, v)                      # (a, b, d)
    chord_u = np.linalg.norm(np.diff(points, axis=0), axis=-1)  # (a-1, b)
    chord_v = np.linalg.norm(np.diff(points, axis=1), axis=-1)  # (a, b-1)
    longest = max(float(chord_u.max(initial=0.0)), float(chord_v.max(initial=0.0)))
    collapsed = COLLAPSED_CHORD * longest if longest > 0 else np.inf

    mis_u = _mismatch(chord_u, np.diff(u), collapsed)            # (a-2, b)
    mis_v = _mismatch(chord_v.T, np.diff(v), collapsed).T       # (a, b-2)
    worst_u, at_u = _worst(mis_u, u[1:-1], v)
    worst_v, at_v = _worst(mis_v, u, v[1:-1])
    if math.isnan(worst_v) or (not math.isnan(worst_u) and worst_u >= worst_v):
        worst, at = worst_u, at_u
    else:
        worst, at = worst_v, at_v
    return ParametrizationQuality(worst_u, worst_v, worst, at_u, at_v, at,
                                  (len(u), len(v)))


def _mismatch(chords: NDArray, steps: NDArray, collapsed: float) -> NDArray:
    """max(r, 1/r) at interior nodes along axis 0; nan where a chord is collapsed."""
    prev, nxt = chords[:-1], chords[1:]
    valid = (prev > collapsed) & (nxt > collapsed)
    step_ratio = (steps[1:] / steps[:-1])[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        r = (nxt / prev) / step_ratio
        out = np.maximum(r, 1.0 / r)
    return np.where(valid, out, np.nan)


def _worst(mismatch: NDArray, u: NDArray, v: NDArray) -> tuple[float, tuple[float, float] | None]:
    if mismatch.size == 0 or np.all(np.isnan(mismatch)):
        return math.nan, None
    i, j = np.unravel_index(np.nanargmax(mismatch), mismatch.shape)
    return float(mismatch[i, j]), (float(u[i]), float(v[j]))
