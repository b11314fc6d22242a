"""Degree elevation of NURBS curves and surfaces.

Method (exact, in homogeneous coordinates)
------------------------------------------
Raising the degree ``p`` of a spline by ``t`` keeps the function and raises
every knot's multiplicity by ``t`` (section 5.5 of [PT]). It is computed as

1. Bézier decomposition (knot refinement, :mod:`.bezier`);
2. Bézier degree elevation of every piece at once (eq. 5.36 of [PT]):

   .. math:: Q_i = \\sum_{j=\\max(0, i-t)}^{\\min(p, i)}
                  \\frac{\\binom{p}{j}\\binom{t}{i-j}}{\\binom{p+t}{i}} P_j,
             \\qquad i = 0..p+t;

3. instead of the knot removal of A5.9, the poles ``Q`` of the target space
   (degree ``p + t``, multiplicities ``+ t``) are recovered from the elevated
   Bézier poles ``R`` by solving ``A Q = R``, where ``A`` is the knot-insertion
   (Oslo) matrix from the target knot vector to the fully separated Bézier knot
   vector, i.e. the Bézier decomposition of the identity in the target space. The
   system is consistent (``R`` lies in the range of ``A``), ``A`` has full column
   rank and is well conditioned (rows are convex combinations), so the
   least-squares solution is the exact one up to rounding; there is no
   collocation and no Schoenberg–Whitney condition to meet, and knots of
   multiplicity ``p + 1`` (discontinuities) are handled as well.

An unclamped input comes back clamped over its domain (same geometry).

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   section 5.5, eq. (5.36), A5.9.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidGeometryError
from .bezier import bezier_decompose_array
from .curve import NurbsCurve
from .surface import NurbsSurface
from .tensor import Direction, knots_along, net_along, surface_from_net

__all__ = [
    "bezier_elevation_matrix",
    "elevate_degree_array",
    "elevate_degree",
    "elevate_degree_surface",
]


def bezier_elevation_matrix(degree: int, t: int) -> NDArray:
    """Matrix ``E`` with ``Q = E @ P`` raising a Bézier piece from ``degree`` to ``degree + t``.

    Returns
    -------
    (degree + t + 1, degree + 1) float
    """
    p = int(degree)
    i = np.arange(p + t + 1)[:, None]
    j = np.arange(p + 1)[None, :]
    valid = (i - j >= 0) & (i - j <= t)
    numer = _binomials(p)[j] * _binomials(t)[np.clip(i - j, 0, t)]
    return np.where(valid, numer / _binomials(p + t)[i], 0.0)


def _binomials(n: int) -> NDArray:
    """Row ``n`` of Pascal's triangle, ``(n + 1,) float``: ``C(n, k)`` exact, then rounded."""
    return np.array([math.comb(n, k) for k in range(n + 1)], dtype=float)


def elevate_degree_array(points_w: NDArray, knots: NDArray, degree: int, t: int
                         ) -> tuple[NDArray, NDArray]:
    """Raise the degree of a homogeneous control array along axis 0 by ``t``.

    Parameters
    ----------
    points_w : (n, ...) float
    knots : (n + degree + 1,) float
    degree : int
    t : int >= 1

    Returns
    -------
    points_w : (n', ...) float
    knots : (n' + degree + t + 1,) float
        Clamped; distinct interior knots as before, each multiplicity ``+ t``.
    """
    if int(t) != t or t < 1:
        raise InvalidGeometryError(f"degree elevation t must be an integer >= 1, got {t!r}")
    p, t = int(degree), int(t)
    points_w = np.asarray(points_w, dtype=float)
    knots = np.asarray(knots, dtype=float)
    pieces, intervals = bezier_decompose_array(points_w, knots, p)      # (k, p+1, ...)
    elevated = np.einsum("ij,kj...->ki...", bezier_elevation_matrix(p, t), pieces)
    k, new_degree = intervals.shape[0], p + t
    breaks = np.concatenate([intervals[:, 0], intervals[-1:, 1]])       # (k+1,)
    # target space: the original multiplicities + t inside, clamped ends
    mult = np.searchsorted(knots, breaks, "right") - np.searchsorted(knots, breaks, "left")
    mult = np.minimum(mult + t, new_degree + 1)
    mult[0] = mult[-1] = new_degree + 1
    target = np.repeat(breaks, mult)
    n_target = target.size - new_degree - 1
    # Oslo matrix from the target space to the fully separated Bezier space: the
    # Bezier pieces of every target basis function (decomposition of the identity)
    oslo = bezier_decompose_array(np.eye(n_target), target, new_degree)[0]
    oslo = oslo.reshape(k * (new_degree + 1), n_target)                # (k (p+t+1), n_t)
    rhs = elevated.reshape(k * (new_degree + 1), -1)
    solution = np.linalg.lstsq(oslo, rhs, rcond=None)[0]
    return solution.reshape((n_target,) + points_w.shape[1:]), target


def elevate_degree(curve: NurbsCurve, t: int = 1) -> NurbsCurve:
    """Curve of degree ``p + t`` with the same geometry and parametrization."""
    pw, knots = elevate_degree_array(curve.homogeneous_points(), curve.knots, curve.degree, t)
    return NurbsCurve.from_homogeneous(pw, knots, curve.degree + int(t),
                                       rational=curve.weights is not None)


def elevate_degree_surface(surface: NurbsSurface, t_u: int = 0, t_v: int = 0
                           ) -> NurbsSurface:
    """Surface of degrees ``(p + t_u, q + t_v)`` with the same geometry.

    ``t_u`` or ``t_v`` may be 0 to leave that direction alone.
    """
    out = surface
    for direction, t in ((Direction.U, t_u), (Direction.V, t_v)):
        if int(t) != t or t < 0:
            raise InvalidGeometryError(
                f"degree elevation in {direction.name} must be an integer >= 0, got {t!r}")
        if t == 0:
            continue
        knots, degree = knots_along(out, direction)
        pw, new = elevate_degree_array(net_along(out, direction), knots, degree, int(t))
        out = surface_from_net(out, direction, pw, new, degree + int(t))
    return out

