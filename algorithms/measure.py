"""Measures of NURBS geometry: bounding boxes, surface normals, curve arc length.

* Control-net bounding boxes bound the geometry when the weights are positive
  (convex hull property, section 4.2 of [PT]).
* Unit normals ``Su x Sv / |Su x Sv|``; at a degenerate point (collapsed edge,
  pole of a sphere) the limit direction is taken from the Taylor expansion of
  ``Su x Sv`` along a step into the domain (first, then second order).
* Arc length by Gauss–Legendre quadrature per knot span with adaptive
  bisection of the spans that have not converged; all quadrature nodes of a
  pass are evaluated in one vectorized call.

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import (
    DegenerateGeometryError,
    InvalidGeometryError,
)
from .curve import NurbsCurve
from .surface import NurbsSurface
from .tolerance import check_tolerance

__all__ = ["arc_length", "bounding_box", "box_centre", "cumulative_arc_length", "normal_turn",
           "normals"]

_GAUSS_ORDER = 10
#: its nodes and weights on [-1, 1] (leggauss costs ~0.4 ms a call; arc length is asked often)
_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(_GAUSS_ORDER)
_GAUSS_NODES.flags.writeable = _GAUSS_WEIGHTS.flags.writeable = False
_MAX_PASSES = 60
#: pending intervals at most, per interval given and in all: where rounding keeps two
#: estimates from agreeing (a relative ``tol`` near machine precision on a long curve
#: with large coordinates), bisection would otherwise double them every pass (2 GB
#: were asked for on a 120 m fuselage waterline at tol = 1e-12)
_MAX_PENDING_PER_INTERVAL = 16
_MAX_PENDING = 1 << 12


# -------------------------------------------------------------- bounding box
def bounding_box(geometry: NurbsCurve | NurbsSurface) -> NDArray:
    """Axis-aligned bounding box of the control points.

    Returns
    -------
    (2, d) float
        ``[minimum corner, maximum corner]``; contains the curve or surface
        (weights are positive by construction).
    """
    points = np.asarray(geometry.control_points).reshape(-1, geometry.dimension)
    return np.stack([points.min(axis=0), points.max(axis=0)])


def box_centre(geometry: NurbsCurve | NurbsSurface) -> NDArray:
    """Midpoint ``(d,)`` of the control-point bounding box: where an algorithm moves a
    far-off curve or surface (:meth:`~.NurbsSurface.translated`) so that its
    coordinates keep their low bits."""
    box = bounding_box(geometry)
    return 0.5 * (box[0] + box[1])


# -------------------------------------------------------------------- normals
def _toward_center(u: NDArray, v: NDArray, box: tuple[float, float, float, float]
                   ) -> tuple[NDArray, NDArray]:
    """Step direction ``(a, b)`` (normalized parameters, max-norm 1) toward the domain center.

    It enters the domain from every boundary point, and from an interior point
    near a degenerate boundary it points away from that boundary.
    """
    u0, u1, v0, v1 = box
    a = (0.5 * (u0 + u1) - u) / (u1 - u0)
    b = (0.5 * (v0 + v1) - v) / (v1 - v0)
    size = np.maximum(np.abs(a), np.abs(b))
    at_center = size == 0
    size = np.where(at_center, 1.0, size)
    return (np.where(at_center, 1.0, a / size)[:, None],
            np.where(at_center, 1.0, b / size)[:, None])


def normals(surface: NurbsSurface, u: ArrayLike, v: ArrayLike) -> NDArray:
    """Unit normals ``Su x Sv / |Su x Sv|`` at broadcast parameters ``u``, ``v``.

    Where ``|Su x Sv|`` is below ``sqrt(eps) L^2`` (``L`` the control-net box
    diagonal, derivatives taken in domain-normalized parameters), the normal is
    the limit of the normal along a step ``(a h, b h)`` from the point toward
    the center of the domain (which enters the domain from any boundary point).
    Exactly at a degenerate point the limit is exact to rounding; close to one
    (within ~sqrt(eps) of the parameter range) the direction is accurate to
    about ``sqrt(eps)``, the conditioning of ``Su x Sv`` there. Writing
    ``S_u(h) = S_u + h (a S_uu + b S_uv) + ...`` and likewise for ``S_v``,

    .. math:: S_u \\times S_v (h) = n_0 + h\\, n_1 + h^2 n_2 + O(h^3),

    the first non-vanishing ``n_k`` gives the direction (at a sphere's pole,
    ``n_1 = S_{uv} \\times S_v``).

    Parameters
    ----------
    surface : NurbsSurface, dimension 3
    u, v : (...) float

    Returns
    -------
    (..., 3) float

    Raises
    ------
    DegenerateGeometryError
        Where even the second-order term vanishes (no normal direction exists).
    """
    if surface.dimension != 3:
        raise InvalidGeometryError(
            f"normals need a surface in 3D, got dimension {surface.dimension}")
    u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
    shape = u.shape
    u, v = u.reshape(-1), v.reshape(-1)
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(v))):
        raise InvalidGeometryError("normals: u and v must be finite")
    u0, u1, v0, v1 = surface.domain
    du, dv = u1 - u0, v1 - v0
    d = surface.derivatives(u, v, 2)
    # derivatives in domain-normalized parameters, so every term scales like length^2
    su, sv = d[:, 1, 0] * du, d[:, 0, 1] * dv
    suu, suv, svv = d[:, 2, 0] * du * du, d[:, 1, 1] * du * dv, d[:, 0, 2] * dv * dv
    a, b = _toward_center(u, v, (u0, u1, v0, v1))
    step_u = a * suu + b * suv          # d(Su)/dh
    step_v = a * suv + b * svv          # d(Sv)/dh
    terms = (np.cross(su, sv),
             np.cross(su, step_v) + np.cross(step_u, sv),
             np.cross(step_u, step_v))
    box = bounding_box(surface)
    # below ~sqrt(eps) L^2 the rounding error of Su x Sv (about eps L^2 / |Su x Sv|
    # in angle) exceeds that of the limit direction (about the distance to the
    # degenerate point, ~ |Su x Sv| / L^2)
    size2 = max(float(np.sum((box[1] - box[0]) ** 2)), np.finfo(float).tiny)
    threshold = np.sqrt(np.finfo(float).eps) * size2
    out = np.zeros_like(su)
    done = np.zeros(u.size, dtype=bool)
    for term in terms:
        norm = np.linalg.norm(term, axis=1)
        take = ~done & (norm > threshold)
        out[take] = term[take] / norm[take, None]
        done |= take
    if not np.all(done):
        k = int(np.flatnonzero(~done)[0])
        raise DegenerateGeometryError(
            f"no normal direction at (u, v) = ({u[k]!r}, {v[k]!r}): Su x Sv and its "
            f"first- and second-order limits vanish")
    return out.reshape(shape + (3,))


def normal_turn(before: NurbsSurface, after: NurbsSurface, u: ArrayLike, v: ArrayLike, *,
                degenerate: float = 1e-3) -> NDArray:
    """Angle between the tangent planes of two surfaces at the same parameters: how far
    a change of a surface (a displacement that keeps its parametrization) turned it.

    .. math:: \\theta = \\arccos \\frac{N_b \\cdot N_a}{|N_b|\\,|N_a|}, \\qquad
              N = S_u \\times S_v,

    in ``[0, pi]``: above ``pi / 2`` the changed surface is folded over there.

    Parameters
    ----------
    before, after : NurbsSurface, dimension 3
    u, v : (...) float, broadcast together
        Parameters, within both domains.
    degenerate : float
        Where ``|N|`` of either surface is below this share of its median over the
        samples (a pole, a collapsed side: the normal's direction is not defined by
        the first derivatives there), or where ``before``'s derivatives are nearly
        parallel (``|N_a| <= degenerate |S_u| |S_v|``: a cusp, where the slightest
        change turns the normal of a tangent plane that was barely defined), the angle
        is NaN.

    Returns
    -------
    (...) float
        Radians, NaN at degenerate samples.

    Examples
    --------
    A plane, and the same plane turned by 0.1 rad about its u-axis:

    >>> import numpy as np
    >>> x, y = np.meshgrid([0.0, 1.0], [0.0, 1.0], indexing="ij")
    >>> flat = NurbsSurface(np.stack([x, y, 0 * x], -1), [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    >>> turned = NurbsSurface(np.stack([x, y * np.cos(0.1), y * np.sin(0.1)], -1),
    ...                       [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    >>> np.round(normal_turn(flat, turned, [0.2, 0.7], [0.5, 0.9]), 12)
    array([0.1, 0.1])
    """
    for name, surface in (("before", before), ("after", after)):
        if surface.dimension != 3:
            raise InvalidGeometryError(
                f"normal_turn needs surfaces in 3D, {name} has dimension {surface.dimension}")
    u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(v))):
        raise InvalidGeometryError("normal_turn: u and v must be finite")
    if not (np.isfinite(degenerate) and 0.0 <= degenerate < 1.0):
        raise InvalidGeometryError(f"degenerate must lie in [0, 1), got {degenerate!r}")
    da, db = before.derivatives(u, v, 1), after.derivatives(u, v, 1)
    a = np.cross(da[..., 1, 0, :], da[..., 0, 1, :])
    b = np.cross(db[..., 1, 0, :], db[..., 0, 1, :])
    na, nb = np.linalg.norm(a, axis=-1), np.linalg.norm(b, axis=-1)
    # the sine from the cross product keeps small angles exact (arccos loses half the
    # digits); the scale cancels in the ratio
    angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))
    if not u.size:
        return angle
    speeds = np.linalg.norm(da[..., 1, 0, :], axis=-1) * np.linalg.norm(da[..., 0, 1, :], axis=-1)
    low = ((na < degenerate * float(np.median(na))) | (nb < degenerate * float(np.median(nb)))
           | (na <= degenerate * speeds) | (nb == 0.0))
    return np.where(low, np.nan, angle)


# ----------------------------------------------------------------- arc length
def _speed_quadrature(curve: NurbsCurve, a: NDArray, b: NDArray,
                      nodes: NDArray, weights: NDArray) -> NDArray:
    """Gauss–Legendre estimate of the integral of ``|C'|`` over each ``[a_i, b_i]``."""
    half = 0.5 * (b - a)
    t = 0.5 * (a + b)[:, None] + half[:, None] * nodes[None, :]      # (m, g)
    speed = np.linalg.norm(curve.derivatives(t, 1)[..., 1, :], axis=-1)
    return half * (speed @ weights)


def _speed_noise(curve: NurbsCurve, a: NDArray, b: NDArray) -> NDArray:
    """Rounding in ``|C'|`` on each interval ``(m,)``: ``C'`` is a sum of control-point
    differences over knot differences, so a span of width ``h`` knows it only to about
    ``degree * eps * max|P| / h`` -- the floor of what two estimates can agree on. A
    span 2e-8 wide at the end of a curve read from STEP at 1e6 otherwise bisected to
    the cap on every call."""
    knots = curve.knots
    span = np.clip(np.searchsorted(knots, 0.5 * (a + b), side="right") - 1, 0, knots.size - 2)
    width = np.maximum(knots[span + 1] - knots[span], b - a)
    magnitude = float(np.abs(curve.control_points).max())
    return 8 * curve.degree * np.finfo(float).eps * magnitude / width


def _integrate_speed(curve: NurbsCurve, a: NDArray, b: NDArray, tol: float) -> NDArray:
    """Arc length of each interval ``[a_i, b_i]`` (inside one knot span each), adaptively.

    An interval is accepted when the estimate on it and the sum on its two
    halves agree to ``tol * (total length) * (width / total width)``; the
    halves' sum is kept. All pending intervals are evaluated together.

    Memory is bounded: once more than ``_MAX_PENDING_PER_INTERVAL`` times the
    given intervals (or ``_MAX_PENDING``) would be pending, the halves' sums are
    accepted as they are -- bisection has then reached rounding level, and going
    on would only double the work and memory every pass.
    """
    nodes, weights = _GAUSS_NODES, _GAUSS_WEIGHTS
    # about its own box centre: the speed comes from differences of control points,
    # which a far-off curve (1e6 away, 100 long) knows only to ~1e-10, so the halves
    # never agreed to tol and bisection ran to its cap (heal 2x, reparam 3x slower)
    curve = curve.translated(-box_centre(curve))
    result = np.zeros(a.size)
    owner = np.arange(a.size)
    whole = _speed_quadrature(curve, a, b, nodes, weights)
    total_width = float(np.sum(b - a))
    scale = max(float(np.sum(whole)), np.finfo(float).tiny)
    noise = _speed_noise(curve, a, b)
    cap = max(_MAX_PENDING, _MAX_PENDING_PER_INTERVAL * a.size)
    for _ in range(_MAX_PASSES):
        mid = 0.5 * (a + b)
        halves = _speed_quadrature(curve, np.concatenate([a, mid]),
                                   np.concatenate([mid, b]), nodes, weights)
        left, right = halves[:a.size], halves[a.size:]
        refined = left + right
        allowed = (tol * scale * (b - a) / total_width + 4 * np.finfo(float).eps * np.abs(refined)
                   + (b - a) * noise[owner])
        ok = np.abs(refined - whole) <= allowed
        np.add.at(result, owner[ok], refined[ok])
        if np.all(ok):
            return result
        keep = ~ok
        if 2 * np.count_nonzero(keep) > cap:
            np.add.at(result, owner[keep], refined[keep])
            return result
        a, b = np.concatenate([a[keep], mid[keep]]), np.concatenate([mid[keep], b[keep]])
        whole = np.concatenate([left[keep], right[keep]])
        owner = np.concatenate([owner[keep], owner[keep]])
    raise DegenerateGeometryError(
        f"arc length did not converge to tol = {tol} after {_MAX_PASSES} bisections")


def _pieces(curve: NurbsCurve, t: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Sorted breakpoints = knots of the domain united with ``t``; pieces between them."""
    lo, hi = curve.domain
    knots = curve.knots[(curve.knots > lo) & (curve.knots < hi)]
    points = np.unique(np.concatenate([[lo, hi], knots, t]))
    return points, points[:-1], points[1:]


def _check_parameters(curve: NurbsCurve, t: NDArray, name: str) -> None:
    lo, hi = curve.domain
    if not np.all(np.isfinite(t)):
        raise InvalidGeometryError(f"{name} must be finite")
    bad = t[(t < lo) | (t > hi)]
    if bad.size:
        raise InvalidGeometryError(f"{name} = {bad[0]!r} is outside the domain [{lo!r}, {hi!r}]")


def cumulative_arc_length(curve: NurbsCurve, t: ArrayLike, tol: float = 1e-12) -> NDArray:
    """Arc length from the domain start to each parameter of ``t``.

    Parameters
    ----------
    curve : NurbsCurve
    t : (...) float
        Parameters inside the domain, in any order.
    tol : float
        Relative tolerance of the total length.

    Returns
    -------
    (...) float, non-decreasing in ``t``.
    """
    tol = check_tolerance(tol)
    t = np.asarray(t, dtype=float)
    _check_parameters(curve, t.reshape(-1), "t")
    points, a, b = _pieces(curve, t.reshape(-1))
    lengths = _integrate_speed(curve, a, b, tol)
    cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
    return cumulative[np.searchsorted(points, t)]


def arc_length(curve: NurbsCurve, t0: float | None = None, t1: float | None = None,
               tol: float = 1e-12) -> float:
    """Length of the curve between the parameters ``t0 <= t1`` (default: whole domain).

    Gauss–Legendre quadrature (10 nodes) on every knot span inside ``[t0, t1]``,
    bisected adaptively until two successive estimates agree to ``tol`` relative
    to the total length.

    Raises
    ------
    InvalidGeometryError
        ``t0`` or ``t1`` outside the domain, not finite, or ``t0 > t1``.
    InvalidToleranceError
        ``tol`` not a finite positive number.
    """
    tol = check_tolerance(tol)
    lo, hi = curve.domain
    t0 = lo if t0 is None else float(t0)
    t1 = hi if t1 is None else float(t1)
    _check_parameters(curve, np.array([t0, t1]), "t0, t1")
    if t0 > t1:
        raise InvalidGeometryError(f"need t0 <= t1, got t0 = {t0!r}, t1 = {t1!r}")
    if t0 == t1:
        return 0.0
    inner = curve.knots[(curve.knots > t0) & (curve.knots < t1)]
    points = np.unique(np.concatenate([[t0, t1], inner]))
    return float(np.sum(_integrate_speed(curve, points[:-1], points[1:], tol)))
