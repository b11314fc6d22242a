"""Boundary curves by arc length and curvature (000 §29.2.4).

Each boundary of the surface is an isoparametric curve of the original. Its
interpolation points are placed in three steps:

1. **Estimate the count** from the curvature. For a C2 cubic spline through
   points ``h`` apart (in arc length) on a curve of curvature ``kappa`` the
   error is about ``5/384 h^4 |C''''|`` with ``|C''''| ~ kappa^3``; within ``tol``
   this gives a local point density ``kappa^(3/4) / (76.8 tol)^(1/4)`` per unit
   length. Added to a plain arc-length density of ``MIN_INTERVALS / L`` and
   integrated along the curve, it gives the number of points.
2. **Place them** at equal steps of that integrated density (the adaptive knot
   selection: points crowd where the curve bends, and are spread by arc length
   where it is straight).
3. **Refine**: a C2 cubic (not-a-knot) interpolant with arc-length parameters
   is passed through the points; its distance to the original curve is measured
   at :data:`CHECK_PER_INTERVAL` points per interval by closest-point projection,
   and every interval that is off by more than the tolerance gets its midpoint
   (in arc length) as a new point, until the interpolant is within tolerance.

The result of this module is a set of *arc-length fractions* ``0 = f_0 < ... <
f_n = 1`` per boundary, which :mod:`.reconcile` merges with the opposite boundary.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import PchipInterpolator

from ..curve import NurbsCurve
from ..fitting import interpolate_curve, knots_from_breakpoints
from ..measure import cumulative_arc_length
from ..projection import project_to_curve

__all__ = [
    "CHECK_PER_INTERVAL",
    "MIN_INTERVALS",
    "ArcLengthTable",
    "arc_length_table",
    "boundary_fractions",
]

#: Intervals every boundary gets at least (the arc-length part of the density).
MIN_INTERVALS = 3
#: Check points per interpolation interval when measuring a boundary fit.
CHECK_PER_INTERVAL = 10
#: Samples per knot span of the original curve in the arc-length table.
TABLE_PER_SPAN = 24
#: Samples of the table at least, also added uniformly in arc length.
TABLE_MIN = 400
#: Relative accuracy of the tabulated arc lengths.
ARC_TOL = 1e-10
#: Refinement rounds of one boundary before giving up (the surface loop goes on).
MAX_ROUNDS = 12


@dataclass(frozen=True)
class ArcLengthTable:
    """Dense table of an isoparametric curve: parameter, arc length and curvature.

    Attributes
    ----------
    curve : NurbsCurve
        The curve (parameter = the original surface parameter).
    t : (k,) float
        Parameters, increasing, first and last the domain ends.
    arc : (k,) float
        Arc length from the start, non-decreasing.
    curvature : (k,) float
        Curvature (of circles through samples uniform in arc length).
    """

    curve: NurbsCurve
    t: NDArray
    arc: NDArray
    curvature: NDArray

    @property
    def length(self) -> float:
        return float(self.arc[-1])

    def parameters_at(self, fractions: NDArray) -> NDArray:
        """Curve parameters at arc-length fractions ``(n,)`` in [0, 1] (monotone cubic)."""
        f = np.clip(np.asarray(fractions, dtype=float), 0.0, 1.0)
        if self.length <= 0.0:
            lo, hi = self.t[0], self.t[-1]
            return lo + f * (hi - lo)
        x = self.arc / self.length
        keep = np.concatenate([[True], np.diff(x) > 1e-13])
        t = PchipInterpolator(x[keep], self.t[keep])(f)
        t[f <= 0.0], t[f >= 1.0] = self.t[0], self.t[-1]
        return np.clip(t, self.t[0], self.t[-1])

    def fractions_at(self, t: NDArray) -> NDArray:
        """Arc-length fractions of curve parameters ``(n,)``."""
        if self.length <= 0.0:
            return (np.asarray(t) - self.t[0]) / (self.t[-1] - self.t[0])
        return np.interp(t, self.t, self.arc) / self.length


def _menger_curvature(points: NDArray) -> NDArray:
    """Curvature of the circle through each three consecutive points ``(k, d)`` -> ``(k,)``.

    Used on samples uniform in arc length, it does not depend on the
    parametrization (an analytic ``|C' x C''| / |C'|^3`` blows up where a bad
    parametrization makes the speed vanish).
    """
    a, b = np.diff(points[:-1], axis=0), np.diff(points[1:], axis=0)
    c = points[2:] - points[:-2]
    if points.shape[1] == 3:
        area2 = np.linalg.norm(np.cross(a, b), axis=1)
    else:
        area2 = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    denominator = (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1)
                   * np.linalg.norm(c, axis=1))
    inner = np.where(denominator > 0, 2.0 * area2 / np.where(denominator > 0, denominator, 1.0),
                     0.0)
    return np.concatenate([inner[:1], inner, inner[-1:]])


def arc_length_table(curve: NurbsCurve, collapsed: float = 0.0) -> ArcLengthTable:
    """Tabulate ``curve`` uniformly in each knot span and uniformly in arc length.

    The second set matters for badly parametrized curves (``u^3``): samples
    uniform in the parameter leave long stretches of the curve nearly empty.
    A curve whose control polygon is not longer than ``collapsed`` (model
    units) is a point: its table has zero length.
    """
    knots = np.unique(curve.knots[curve.degree:curve.n_control + 1])
    per = max(TABLE_PER_SPAN, -(-TABLE_MIN // max(len(knots) - 1, 1)))
    steps = np.linspace(0.0, 1.0, per + 1)[:-1]
    t0 = np.append((knots[:-1, None] + steps * np.diff(knots)[:, None]).ravel(), knots[-1])
    polygon = float(np.sum(np.linalg.norm(np.diff(curve.control_points, axis=0), axis=1)))
    if polygon <= collapsed:
        return ArcLengthTable(curve, t0, np.zeros_like(t0), np.zeros_like(t0))
    s0 = cumulative_arc_length(curve, t0, tol=ARC_TOL)
    s_uniform = np.linspace(0.0, s0[-1], TABLE_MIN + 1)
    arc, keep = np.unique(s0, return_index=True)
    t_uniform = np.interp(s_uniform, arc, t0[keep])
    t0 = np.unique(np.concatenate([t0, t_uniform]))
    t0 = t0[np.concatenate([np.diff(t0) > 1e-12 * (t0[-1] - t0[0]), [True]])]
    s0 = cumulative_arc_length(curve, t0, tol=ARC_TOL)
    kappa = _menger_curvature(curve.evaluate(t_uniform))
    return ArcLengthTable(curve, t0, s0, np.interp(s0, s_uniform, kappa))


def initial_fractions(table: ArcLengthTable, tol: float) -> NDArray:
    """Arc-length fractions of the first interpolation points (steps 1 and 2).

    Returns
    -------
    (n,) float, ``n >= MIN_INTERVALS + 1``, from 0 to 1.
    """
    length = table.length
    density = table.curvature ** 0.75 / (76.8 * tol) ** 0.25 + MIN_INTERVALS / length
    ds = np.diff(table.arc)
    effort = np.concatenate([[0.0], np.cumsum(0.5 * (density[1:] + density[:-1]) * ds)])
    n_intervals = max(MIN_INTERVALS, int(np.ceil(effort[-1])))
    targets = np.linspace(0.0, effort[-1], n_intervals + 1)
    effort_u, keep = np.unique(effort, return_index=True)
    fractions = np.interp(targets, effort_u, table.arc[keep]) / length
    fractions[0], fractions[-1] = 0.0, 1.0
    return np.unique(fractions)


def boundary_interpolant(table: ArcLengthTable, fractions: NDArray) -> NurbsCurve:
    """C2 cubic (not-a-knot) interpolant through the points at ``fractions``,
    parametrized by arc length ``fractions * length``."""
    points = table.curve.evaluate(table.parameters_at(fractions))
    params = fractions * table.length
    return interpolate_curve(points, degree=3, parameters=params,
                             knots=knots_from_breakpoints(params, 3))


def interval_errors(table: ArcLengthTable, fractions: NDArray, fit: NurbsCurve) -> NDArray:
    """Largest distance of the original curve from ``fit`` per interval ``(n-1,)``.

    :data:`CHECK_PER_INTERVAL` points of the original per interval, projected
    onto the fit (start: their arc length, which is close to the fit parameter).
    """
    sub = np.linspace(0.0, 1.0, CHECK_PER_INTERVAL + 1)[1:-1]
    f = (fractions[:-1, None] + sub * np.diff(fractions)[:, None])      # (n-1, c)
    points = table.curve.evaluate(table.parameters_at(f.ravel()))
    guess = np.clip(f.ravel() * table.length, *fit.domain)
    distance = project_to_curve(fit, points, guess=guess).distance
    return distance.reshape(f.shape).max(axis=1)


def boundary_fractions(table: ArcLengthTable, tol: float) -> tuple[NDArray, float]:
    """Arc-length fractions of interpolation points whose C2 interpolant is within ``tol``.

    Parameters
    ----------
    table : ArcLengthTable
        The original boundary curve, not collapsed (``length > 0``).
    tol : float
        Model units.

    Returns
    -------
    fractions : (n,) float
        From 0 to 1, increasing.
    error : float
        Largest measured distance of the original from the last interpolant
        (``<= tol`` unless :data:`MAX_ROUNDS` were not enough; the surface
        loop refines further then).
    """
    fractions = initial_fractions(table, tol)
    error = np.inf
    for _ in range(MAX_ROUNDS):
        errors = interval_errors(table, fractions, boundary_interpolant(table, fractions))
        error = float(errors.max())
        bad = errors > tol
        if not np.any(bad):
            break
        mid = 0.5 * (fractions[:-1] + fractions[1:])
        fractions = np.sort(np.concatenate([fractions, mid[bad]]))
    return fractions, error
