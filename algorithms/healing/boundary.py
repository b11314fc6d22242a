"""The four boundary curves of a local approximant and their arc-length sampling.

A local approximant (001 §3, 000 §29.3.2) is bounded by four curves that meet
end to end. Each curve is a :class:`NurbsCurve` (an edge of the model, a curve
on, above or below the surfaces) or an ``(n, 3)`` polyline; four picked points
give four straight lines (:func:`corners_boundary`, 003).

Convention
----------
The curves are given in loop order ``bottom, right, top, left``: bottom runs
from corner ``p00`` to ``p10`` (the approximant's ``v = 0`` side, ``u`` growing),
right from ``p10`` to ``p11`` (``u = 1``), top from ``p11`` to ``p01``
(``v = 1``, ``u`` falling) and left from ``p01`` back to ``p00`` (``u = 0``).
A curve given the other way round is reversed automatically (the first curve
fixes the orientation), so edges of a face can be passed as they come. Ends
that miss each other by more than ``gap_tol`` are refused with the gap; smaller
gaps are closed by moving both ends to their midpoint.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import DegenerateGeometryError, InvalidGeometryError
from ..arc_length_inversion import parameters_at_lengths
from ..curve import NurbsCurve
from ..measure import cumulative_arc_length

__all__ = ["SIDE_NAMES", "Boundary", "BoundaryCurve", "as_boundary", "corners_boundary"]

SIDE_NAMES = ("bottom", "right", "top", "left")
#: default gap_tol: this fraction of the boundary's bounding-box diagonal
DEFAULT_RELATIVE_GAP = 1e-4
_ARC_SAMPLES = 8             # table entries per knot span (Newton from the table polishes)

BoundaryCurve = NurbsCurve | NDArray


@dataclass(frozen=True, eq=False)
class Boundary:
    """Four oriented boundary curves meeting end to end (module docstring).

    Attributes
    ----------
    curves : tuple of four NurbsCurve or (n, 3) float
        In loop order bottom, right, top, left, each oriented along the loop.
    corners : (4, 3) float
        ``p00, p10, p11, p01``: the loop's vertices (start of each curve), the
        gaps within ``gap_tol`` averaged away.
    gaps : (4,) float
        Distance between the end of curve ``k`` and the start of curve ``k + 1``
        as given.
    """

    curves: tuple
    corners: NDArray
    gaps: NDArray

    @property
    def size(self) -> float:
        """Bounding-box diagonal of the corners and curve samples (model units)."""
        pts = np.concatenate([_dense(c) for c in self.curves])
        return float(np.linalg.norm(np.ptp(pts, axis=0)))

    def sample(self, m: int, n: int) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """Points uniform in arc length on the four sides, in the patch's directions.

        Parameters
        ----------
        m, n : int >= 1
            Intervals along u (bottom, top) and v (left, right).

        Returns
        -------
        bottom, top : (m + 1, 3) float
            ``x_{I,0}`` and ``x_{I,N}``, ``I = 0..M`` (001 eq. 4).
        left, right : (n + 1, 3) float
            ``x_{0,J}`` and ``x_{M,J}``, ``J = 0..N``.
        The corner points are the :attr:`corners` exactly.
        """
        c = self.corners
        bottom = _uniform_points(self.curves[0], m, c[0], c[1])
        right = _uniform_points(self.curves[1], n, c[1], c[2])
        top = _uniform_points(self.curves[2], m, c[2], c[3])[::-1]
        left = _uniform_points(self.curves[3], n, c[3], c[0])[::-1]
        return bottom, top, left, right


# ------------------------------------------------------------------ building
def corners_boundary(p00: ArrayLike, p10: ArrayLike, p11: ArrayLike, p01: ArrayLike
                     ) -> Boundary:
    """Four straight lines between four picked points (003, "four points").

    Parameters
    ----------
    p00, p10, p11, p01 : (3,) float
        Corners in loop order (clockwise or counter-clockwise).
    """
    pts = [_point(p, name) for p, name in zip((p00, p10, p11, p01),
                                               ("p00", "p10", "p11", "p01"), strict=True)]
    lines = [np.stack([pts[k], pts[(k + 1) % 4]]) for k in range(4)]
    return as_boundary(lines)


def as_boundary(curves: Boundary | Sequence[BoundaryCurve], *,
                gap_tol: float | None = None) -> Boundary:
    """Check, orient and close four boundary curves (module docstring).

    Parameters
    ----------
    curves : Boundary or sequence of four NurbsCurve / (n, 3) float
    gap_tol : float, optional
        Largest accepted distance between consecutive ends, model units.
        Default :data:`DEFAULT_RELATIVE_GAP` times the boundary's size.

    Raises
    ------
    InvalidGeometryError
        Not four curves, a curve not in 3D, NaN, or ends that do not meet
        (the message names the corner and the gap).
    DegenerateGeometryError
        A curve of zero length.
    """
    if isinstance(curves, Boundary):
        return curves
    curves = list(curves)
    if len(curves) != 4:
        raise InvalidGeometryError(f"a boundary needs exactly four curves, got {len(curves)}")
    curves = [_check_curve(c, SIDE_NAMES[k]) for k, c in enumerate(curves)]
    ends = [_ends(c) for c in curves]
    size = float(np.linalg.norm(np.ptp(np.concatenate([_dense(c) for c in curves]), axis=0)))
    if not size > 0:
        raise DegenerateGeometryError("the four boundary curves collapse to a point")
    tol = DEFAULT_RELATIVE_GAP * size if gap_tol is None else float(gap_tol)
    curves, ends = _orient(curves, ends)
    gaps = np.array([np.linalg.norm(ends[k][1] - ends[(k + 1) % 4][0]) for k in range(4)])
    worst = int(np.argmax(gaps))
    if gaps[worst] > tol:
        a, b = SIDE_NAMES[worst], SIDE_NAMES[(worst + 1) % 4]
        raise InvalidGeometryError(
            f"boundary curves do not meet end to end: the {a} curve ends "
            f"{gaps[worst]:.3g} from the start of the {b} curve (gap_tol {tol:.3g}); "
            f"gaps at the four corners: {np.array2string(gaps, precision=3)}")
    corners = np.stack([0.5 * (ends[(k - 1) % 4][1] + ends[k][0]) for k in range(4)])
    return Boundary(tuple(curves), corners, gaps)


# ------------------------------------------------------------------- helpers
def _point(p: ArrayLike, name: str) -> NDArray:
    a = np.asarray(p, dtype=float)
    if a.shape != (3,):
        raise InvalidGeometryError(f"{name} must be a 3D point, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InvalidGeometryError(f"{name} contains NaN or infinite values")
    return a


def _check_curve(c, side: str) -> BoundaryCurve:
    if isinstance(c, NurbsCurve):
        if c.dimension != 3:
            raise InvalidGeometryError(f"the {side} curve must be a 3D curve, got {c.dimension}D")
        return c
    try:
        a = np.array(c, dtype=float)
    except (TypeError, ValueError):
        raise InvalidGeometryError(
            f"the {side} curve must be a NurbsCurve or an (n, 3) point array") from None
    if a.ndim != 2 or a.shape[1] != 3 or a.shape[0] < 2:
        raise InvalidGeometryError(f"the {side} polyline must have shape (n >= 2, 3), "
                                   f"got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InvalidGeometryError(f"the {side} polyline contains NaN or infinite values")
    if not np.any(np.linalg.norm(np.diff(a, axis=0), axis=1) > 0):
        raise DegenerateGeometryError(f"the {side} polyline has zero length")
    a.setflags(write=False)
    return a


def _ends(c: BoundaryCurve) -> tuple[NDArray, NDArray]:
    if isinstance(c, NurbsCurve):
        return c.evaluate(c.domain[0]), c.evaluate(c.domain[1])
    return c[0], c[-1]


def _reverse(c: BoundaryCurve) -> BoundaryCurve:
    if isinstance(c, NurbsCurve):
        a, b = c.domain
        return NurbsCurve(c.control_points[::-1], (a + b) - c.knots[::-1], c.degree,
                          None if c.weights is None else c.weights[::-1])
    return c[::-1]


def _orient(curves: list, ends: list) -> tuple[list, list]:
    """Reverse curves 1..3 where that makes their start meet the previous end
    (curve 0 too when its start is nearer curve 1 than its end is)."""
    s0, e0 = ends[0]
    d_end = min(np.linalg.norm(e0 - p) for p in ends[1])
    d_start = min(np.linalg.norm(s0 - p) for p in ends[1])
    if d_start < d_end:
        curves[0], ends[0] = _reverse(curves[0]), (e0, s0)
    for k in range(1, 4):
        prev_end = ends[k - 1][1]
        s, e = ends[k]
        if np.linalg.norm(e - prev_end) < np.linalg.norm(s - prev_end):
            curves[k], ends[k] = _reverse(curves[k]), (e, s)
    return curves, ends


def _dense(c: BoundaryCurve) -> NDArray:
    if isinstance(c, NurbsCurve):
        return c.evaluate(np.linspace(*c.domain, 33))
    return np.asarray(c)


def _uniform_points(c: BoundaryCurve, m: int, start: NDArray, end: NDArray) -> NDArray:
    """``m + 1`` points uniform in arc length, the ends replaced by the corners."""
    s = np.linspace(0.0, 1.0, m + 1)
    if isinstance(c, NurbsCurve):
        t = _arc_length_table(c)
        length = cumulative_arc_length(c, t)
        if not length[-1] > 0:
            raise DegenerateGeometryError("a boundary curve has zero length")

        def speed(x):
            return np.linalg.norm(c.derivatives(x, 1)[:, 1], axis=1)

        # arc length(u) = target: Newton from the table, each length measured from the
        # table's entry below (not from the start: that was 3 whole-curve integrations)
        u = parameters_at_lengths(speed, t, length, s * length[-1],
                                  np.ones(s.size, bool))
        pts = c.evaluate(u)
    else:
        chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(c, axis=0), axis=1))])
        target = s * chord[-1]
        pts = np.stack([np.interp(target, chord, c[:, k]) for k in range(3)], axis=1)
    pts[0], pts[-1] = start, end
    return pts


def _arc_length_table(c: NurbsCurve) -> NDArray:
    """Parameters dense enough that arc length is close to linear between them."""
    knots = np.unique(c.knots[c.degree:c.n_control + 1])
    s = np.linspace(0.0, 1.0, _ARC_SAMPLES + 1)[:-1]
    t = (knots[:-1, None] + s * np.diff(knots)[:, None]).ravel()
    return np.append(t, knots[-1])
