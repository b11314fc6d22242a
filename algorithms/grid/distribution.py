"""Point distributions along a grid line: the laws grid users ask for, exact in 3D.

A *distribution* is an increasing array ``x`` of ``n`` fractions with
``x[0] = 0`` and ``x[-1] = 1``: the normalized arc length of the grid nodes along
a line (003, "normalized arc length based" distribution space). The laws:

* :func:`uniform` -- equal spacing;
* :func:`geometric` -- each spacing ``growth`` times the one before;
* :func:`stretched` -- hyperbolic-tangent stretching given the first and/or the
  last spacing (one- or two-sided, Vinokur [V]); the spacings are solved so that
  the *discrete* first and last spacing are the ones asked for, not only the
  derivative of the continuous law;
* :func:`by_curvature` -- nodes denser where a curve bends (equidistribution of
  ``1 + strength * L * kappa`` in arc length).

:func:`points_along` turns fractions into the parameters of a curve by exact
arc length (Gauss--Legendre, :func:`~surfprep.algorithms.measure.cumulative_arc_length`
with a Newton polish on the speed), so a spacing asked for in model units is the
spacing measured between the 3D points.

References
----------
.. [V] M. Vinokur, "On one-dimensional stretching functions for finite-difference
   calculations", J. Comput. Phys. 50 (1983) 215-234.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq, root

from ...errors import DegenerateGeometryError, InvalidGeometryError
from ..arc_length_inversion import parameters_at_lengths
from ..curve import NurbsCurve
from ..measure import cumulative_arc_length

__all__ = ["by_curvature", "by_curvature_points", "geometric", "points_along", "stretched", "uniform"]

#: parameter samples per knot span when a curve's arc length is tabulated
_SAMPLES_PER_SPAN = 24


def _check_count(n: int) -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
        raise InvalidGeometryError(f"the node count must be an integer, got {n!r}")
    if n < 2:
        raise InvalidGeometryError(f"a grid line needs at least 2 nodes, got {n}")
    return int(n)


def _check_spacing(value: float, name: str, n: int) -> float:
    value = float(value)
    if not math.isfinite(value) or not 0.0 < value < 1.0:
        raise InvalidGeometryError(
            f"{name} spacing must be a fraction of the line's length in (0, 1), got {value!r}")
    return value


def uniform(n: int) -> NDArray:
    """``n`` equally spaced fractions of ``[0, 1]``.

    Returns
    -------
    (n,) float
    """
    return np.linspace(0.0, 1.0, _check_count(n))


def geometric(n: int, *, growth: float | None = None, first: float | None = None) -> NDArray:
    """Fractions whose spacings grow by a constant ratio.

    ``x_k = (r^k - 1) / (r^(n-1) - 1)``, so ``(x_{k+1} - x_k) / (x_k - x_{k-1}) = r``.
    Give the ratio ``growth`` (``r < 1`` clusters at the end), or the ``first``
    spacing (a fraction of the length) and the ratio is solved for.

    Returns
    -------
    (n,) float
    """
    n = _check_count(n)
    if (growth is None) == (first is None):
        raise InvalidGeometryError("give exactly one of growth and first")
    if first is not None:
        first = _check_spacing(first, "first", n)
        if n == 2:
            raise InvalidGeometryError("a line of 2 nodes has one spacing: the whole length")
        growth = _growth_for_first(n, first)
    r = float(growth)
    if not math.isfinite(r) or r <= 0.0:
        raise InvalidGeometryError(f"growth must be a positive ratio, got {growth!r}")
    if abs(r - 1.0) < 1e-12:
        return uniform(n)
    k = np.arange(n, dtype=float)
    # r^k - 1 by expm1 keeps the small spacings accurate for r near 1
    x = np.expm1(k * math.log(r)) / math.expm1((n - 1) * math.log(r))
    x[0], x[-1] = 0.0, 1.0
    return x


def _growth_for_first(n: int, first: float) -> float:
    """The ratio ``r`` with ``(r - 1) / (r^(n-1) - 1) = first``."""
    m = n - 1
    if abs(first - 1.0 / m) < 1e-14:
        return 1.0

    def spacing(log_r: float) -> float:
        if abs(log_r) < 1e-12:
            return 1.0 / m - first
        return math.expm1(log_r) / math.expm1(m * log_r) - first

    lo, hi = (1e-12, 1.0) if first < 1.0 / m else (-1.0, -1e-12)
    while spacing(lo) * spacing(hi) > 0:          # widen until the root is bracketed
        lo, hi = (lo, 2 * hi) if first < 1.0 / m else (2 * lo, hi)
        if max(abs(lo), abs(hi)) > 700:
            raise InvalidGeometryError(f"no geometric law of {n} nodes has first spacing {first}")
    return math.exp(brentq(spacing, lo, hi, xtol=1e-15, rtol=1e-15))


def _one_sided(n: int, first: float) -> NDArray:
    """Tanh stretching clustered at ``x = 0`` (``first`` below ``1/(n-1)``) or
    spread from it (above): ``1 + tanh(d (xi - 1)) / tanh(d)``, resp.
    ``tanh(d xi) / tanh(d)``, with ``d`` solved for the discrete first spacing [V]."""
    m = n - 1
    xi = np.arange(n) / m
    if abs(first - 1.0 / m) < 1e-14:
        return xi
    if first < 1.0 / m:
        def law(d: float, at: NDArray) -> NDArray:
            return 1.0 + np.tanh(d * (at - 1.0)) / math.tanh(d)
    else:
        def law(d: float, at: NDArray) -> NDArray:
            return np.tanh(d * at) / math.tanh(d)

    def error(d: float) -> float:
        return float(law(d, np.array([1.0 / m]))[0]) - first

    lo, hi = 1e-8, 1.0
    while error(lo) * error(hi) > 0:
        hi *= 2.0
        if hi > 700.0:
            raise InvalidGeometryError(
                f"no tanh law of {n} nodes has first spacing {first} (too small a fraction)")
    d = brentq(error, lo, hi, xtol=1e-14, rtol=1e-15)
    x = law(d, xi)
    x[0], x[-1] = 0.0, 1.0
    if np.any(np.diff(x) <= 0.0):
        raise InvalidGeometryError(
            f"a tanh law of {n} nodes with first spacing {first} leaves spacings that round to "
            "zero; ask for fewer nodes or a smaller spacing")
    return x


def _two_sided(n: int, first: float, last: float) -> NDArray:
    """Vinokur's two-sided law ``u / (A + (1 - A) u)``, ``u = (1 + tanh(d (xi - 1/2)) /
    tanh(d / 2)) / 2`` (the ``tan`` form where both spacings exceed the uniform one),
    with ``A`` and ``d`` solved for the discrete first and last spacings [V]."""
    m = n - 1
    xi = np.arange(n) / m
    big = 1.0 / (m * math.sqrt(first * last))       # Vinokur's B
    trig = big < 1.0

    def law(a: float, d: float, at: NDArray) -> NDArray:
        if abs(d) < 1e-9:
            u = at
        elif trig:
            u = 0.5 * (1.0 + np.tan(d * (at - 0.5)) / math.tan(0.5 * d))
        else:
            u = 0.5 * (1.0 + np.tanh(d * (at - 0.5)) / math.tanh(0.5 * d))
        return u / (a + (1.0 - a) * u)

    # Vinokur's start: sinh(d)/d = B (or sin(d)/d = B), A = sqrt(last / first)
    if trig:
        d0 = brentq(lambda d: math.sin(d) / d - big, 1e-9, math.pi - 1e-9)
    else:
        d0 = brentq(lambda d: math.sinh(d) / d - big, 1e-9, 700.0) if big > 1.0 + 1e-12 else 1e-6
    ends = np.array([1.0 / m, 1.0 - 1.0 / m])

    def residual(p: NDArray) -> NDArray:
        a, d = math.exp(p[0]), p[1]
        x1, xm = law(a, d, ends)
        return np.array([x1 / first - 1.0, (1.0 - xm) / last - 1.0])

    sol = root(residual, np.array([0.5 * math.log(last / first), d0]), method="hybr", tol=1e-14)
    if not np.all(np.isfinite(sol.x)) or np.max(np.abs(residual(sol.x))) > 1e-9:
        raise InvalidGeometryError(
            f"no two-sided tanh law of {n} nodes has first spacing {first} and last {last}")
    x = law(math.exp(sol.x[0]), sol.x[1], xi)
    if np.any(np.diff(x) <= 0.0):
        raise InvalidGeometryError(
            f"the two-sided law for first spacing {first} and last {last} on {n} nodes is not monotone")
    x[0], x[-1] = 0.0, 1.0
    return x


def stretched(n: int, *, first: float | None = None, last: float | None = None) -> NDArray:
    """Hyperbolic-tangent stretching with a given first and/or last spacing [V].

    Parameters
    ----------
    n : int >= 3
    first, last : float in (0, 1), optional
        Spacing of the first / last interval as a fraction of the line's length
        (give at least one). One given: the one-sided law, clustered at (or spread
        from) that end; both: Vinokur's two-sided law.

    Returns
    -------
    (n,) float, with ``x[1] - x[0] == first`` and ``x[-1] - x[-2] == last`` to 1e-12.

    Examples
    --------
    >>> x = stretched(41, first=1e-3)
    >>> round(float(x[1]), 12)
    0.001
    """
    n = _check_count(n)
    if first is None and last is None:
        raise InvalidGeometryError("give a first spacing, a last spacing or both")
    if n == 2:
        raise InvalidGeometryError("a line of 2 nodes has one spacing: the whole length")
    if first is not None:
        first = _check_spacing(first, "first", n)
    if last is not None:
        last = _check_spacing(last, "last", n)
    if first is not None and last is not None:
        if first + last >= 1.0:
            raise InvalidGeometryError(f"first + last spacing must be below 1, got {first + last}")
        return _two_sided(n, first, last)
    if first is not None:
        return _one_sided(n, first)
    return 1.0 - _one_sided(n, last)[::-1]


def by_curvature(curve: NurbsCurve, n: int, *, strength: float = 1.0) -> NDArray:
    """Fractions denser where the curve bends.

    Equidistributes the weight ``w = 1 + strength * L * kappa`` in arc length
    (``L`` the curve's length, ``kappa`` its curvature): node ``k`` sits where
    ``int_0^s w = k / (n-1) * int_0^L w``. ``strength = 0`` is :func:`uniform`.

    Returns
    -------
    (n,) float, fractions of the curve's arc length.
    """
    n = _check_count(n)
    strength = float(strength)
    if not math.isfinite(strength) or strength < 0.0:
        raise InvalidGeometryError(f"strength must be >= 0, got {strength!r}")
    t, s = _arc_table(curve)
    length = s[-1]
    d = curve.derivatives(t, 2)
    d1, d2 = d[:, 1, :], d[:, 2, :]
    speed = np.linalg.norm(d1, axis=1)
    if d1.shape[1] == 2:
        cross = np.abs(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0])
    else:
        cross = np.linalg.norm(np.cross(d1, d2), axis=1)
    kappa = np.where(speed > 0, cross / np.maximum(speed, 1e-300) ** 3, 0.0)
    w = 1.0 + strength * length * kappa
    weight = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(s))])
    targets = np.linspace(0.0, weight[-1], n)
    x = np.interp(targets, weight, s) / length
    x[0], x[-1] = 0.0, 1.0
    return x


def by_curvature_points(points: ArrayLike, n: int, *, strength: float = 1.0) -> NDArray:
    """:func:`by_curvature` for a curve given by dense points ``(m, 3)`` (discrete
    curvature: the turning angle at each point over the mean of its two legs).

    Returns
    -------
    (n,) float, fractions of the polyline's length.
    """
    n = _check_count(n)
    p = np.asarray(points, dtype=float)
    legs = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(legs)])
    if not s[-1] > 0.0:
        raise DegenerateGeometryError("the curve has zero length: it cannot carry a distribution")
    d1, d2 = np.diff(p, axis=0)[:-1], np.diff(p, axis=0)[1:]
    n1, n2 = np.linalg.norm(d1, axis=1), np.linalg.norm(d2, axis=1)
    ok = (n1 > 0) & (n2 > 0)
    cos = np.einsum("ij,ij->i", d1, d2) / np.where(ok, n1 * n2, 1.0)
    turn = np.where(ok, np.arccos(np.clip(cos, -1.0, 1.0)), 0.0)
    kappa = np.concatenate([[0.0], turn / np.maximum(0.5 * (n1 + n2), 1e-300), [0.0]])
    kappa[0], kappa[-1] = kappa[1], kappa[-2]
    w = 1.0 + float(strength) * s[-1] * kappa
    weight = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * legs)])
    x = np.interp(np.linspace(0.0, weight[-1], n), weight, s) / s[-1]
    x[0], x[-1] = 0.0, 1.0
    return x


def _arc_table(curve: NurbsCurve) -> tuple[NDArray, NDArray]:
    """Parameters sampled on every knot span and the exact arc length at each."""
    knots = np.unique(curve.knots[curve.degree:curve.knots.size - curve.degree])
    t = np.concatenate([np.linspace(a, b, _SAMPLES_PER_SPAN, endpoint=False)
                        for a, b in itertools.pairwise(knots)] + [knots[-1:]])
    s = cumulative_arc_length(curve, t)
    if not s[-1] > 0.0:
        raise DegenerateGeometryError("the curve has zero length: it cannot carry a distribution")
    return t, s


def points_along(curve: NurbsCurve, fractions: ArrayLike) -> NDArray:
    """Parameters of the points at the given fractions of the curve's arc length.

    The arc length is tabulated exactly (Gauss--Legendre per span) on a fine
    parameter sample, inverted by monotone interpolation, then each parameter is
    polished by Newton's method on ``s(t) - x L`` with the speed ``|C'(t)|``.

    Parameters
    ----------
    curve : NurbsCurve
    fractions : (n,) float, non-decreasing in [0, 1]

    Returns
    -------
    (n,) float, the parameters; ends exactly at the domain's ends for 0 and 1.

    Raises
    ------
    DegenerateGeometryError
        The curve has zero length.
    """
    x = np.asarray(fractions, dtype=float)
    if x.ndim != 1 or not np.all(np.isfinite(x)) or np.any(x < 0) or np.any(x > 1) \
            or np.any(np.diff(x) < 0):
        raise InvalidGeometryError("fractions must be a non-decreasing 1-D array in [0, 1]")
    t, s = _arc_table(curve)
    out = parameters_at_lengths(lambda u: np.linalg.norm(curve.derivatives(u, 1)[:, 1, :], axis=1),
                                t, s, x * s[-1], (x > 0) & (x < 1))
    lo, hi = curve.domain
    out[x == 0] = lo
    out[x == 1] = hi
    return out
