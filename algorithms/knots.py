"""Knot insertion, refinement, clamping, splitting and restriction of NURBS.

Everything here works on homogeneous control arrays ``(w x, w y, w z, w)`` so
rational curves and surfaces are handled exactly: knot insertion is a linear
map of the homogeneous poles.  The low-level ``*_array`` functions take a
homogeneous array whose axis 0 indexes the control points of the direction
being modified and whose trailing axes are arbitrary; a surface operation in
``u`` is the curve operation applied to every ``v`` column at once (and in ``v``
to the array with its axes swapped), so no Python loop runs over rows.

Knot values are never renormalized: a restricted or split piece keeps the
original parameter values.

Insertion of a knot ``t`` (Boehm, A5.1 of [PT]) into ``t_0 <= ... <= t_{n+p}``
replaces the poles ``P_i`` by

.. math:: Q_i = \\alpha_i P_i + (1 - \\alpha_i) P_{i-1}, \\qquad
          \\alpha_i = \\begin{cases} 1 & t_{i+p} \\le t \\\\ 0 & t_i \\ge t \\\\
          \\frac{t - t_i}{t_{i+p} - t_i} & \\text{otherwise}\\end{cases},
          \\qquad i = 0..n,

which is A5.1 written for every ``i`` at once; inserting ``r`` copies, or many
knots (refinement, A5.4), applies it repeatedly, each time to the whole net.

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   A5.1 (knot insertion), A5.4 (knot refinement), section 5.3 (splitting),
   section 12.2 (periodic and unclamped knot vectors).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidGeometryError
from .curve import NurbsCurve
from .surface import NurbsSurface
from .tensor import (
    Direction,
    as_direction,
    check_in_domain,
    check_parameter,
    domain_of,
    knots_along,
    net_along,
    surface_from_net,
)

__all__ = [
    "clamp",
    "clamp_surface",
    "insert_knot",
    "insert_knot_array",
    "insert_knot_surface",
    "periodic_to_clamped",
    "refine",
    "refine_knots_array",
    "refine_surface",
    "restrict",
    "restrict_array",
    "restrict_surface",
    "split",
    "split_surface",
]


def _multiplicity(knots: NDArray, x: float) -> int:
    return int(np.count_nonzero(knots == x))


# ------------------------------------------------------------- array kernels
def _insert_once(points_w: NDArray, knots: NDArray, degree: int, t: float
                 ) -> tuple[NDArray, NDArray]:
    """Insert ``t`` once (A5.1, all poles at once); no argument checking.

    Requires ``t_p <= t <= t_n`` and a multiplicity of ``t`` at most ``degree``
    before insertion.
    """
    n = points_w.shape[0]
    i = np.arange(n + 1)
    lo, hi = knots[i], knots[i + degree]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = (t - lo) / (hi - lo)
    alpha = np.where(hi <= t, 1.0, np.where(lo >= t, 0.0, ratio))
    alpha = alpha.reshape((n + 1,) + (1,) * (points_w.ndim - 1))
    current = np.concatenate([points_w, points_w[-1:]], axis=0)    # P_i (last unused)
    previous = np.concatenate([points_w[:1], points_w], axis=0)    # P_{i-1} (first unused)
    new_points = alpha * current + (1.0 - alpha) * previous
    new_knots = np.insert(knots, np.searchsorted(knots, t, side="right"), t)
    return new_points, new_knots


def _insert_many(points_w: NDArray, knots: NDArray, degree: int, values: NDArray
                 ) -> tuple[NDArray, NDArray]:
    for t in np.sort(np.asarray(values, dtype=float).reshape(-1)):
        points_w, knots = _insert_once(points_w, knots, degree, float(t))
    return points_w, knots


def _raise_to_multiplicity(points_w: NDArray, knots: NDArray, degree: int, x: float,
                           target: int) -> tuple[NDArray, NDArray]:
    """Insert ``x`` until its multiplicity is at least ``target`` (<= degree + 1)."""
    missing = target - _multiplicity(knots, x)
    for _ in range(max(missing, 0)):
        points_w, knots = _insert_once(points_w, knots, degree, x)
    return points_w, knots


def _trim_start(points_w: NDArray, knots: NDArray, degree: int, a: float
                ) -> tuple[NDArray, NDArray]:
    """Drop everything left of ``a`` (``t_p <= a < t_n``); result clamped at ``a``."""
    points_w, knots = _raise_to_multiplicity(points_w, knots, degree, a, degree)
    last = int(np.searchsorted(knots, a, side="right")) - 1      # knots[last] == a
    keep = last - degree
    new_knots = knots[keep:].copy()
    new_knots[0] = a
    return points_w[keep:], new_knots


def _trim_end(points_w: NDArray, knots: NDArray, degree: int, b: float
              ) -> tuple[NDArray, NDArray]:
    """Drop everything right of ``b`` (``t_p < b <= t_n``); result clamped at ``b``."""
    points_w, knots = _raise_to_multiplicity(points_w, knots, degree, b, degree)
    first = int(np.searchsorted(knots, b, side="left"))           # knots[first] == b
    new_knots = knots[:first + degree + 1].copy()
    new_knots[-1] = b
    return points_w[:first], new_knots


def insert_knot_array(points_w: ArrayLike, knots: ArrayLike, degree: int, value: float,
                      r: int = 1) -> tuple[NDArray, NDArray]:
    """Insert ``value`` ``r`` times into a homogeneous control array (A5.1).

    Parameters
    ----------
    points_w : (n, ...) float
        Homogeneous control points along axis 0; trailing axes are carried along.
    knots : (n + degree + 1,) float
    degree : int
    value : float
        Inside the domain ``[knots[degree], knots[n]]``.
    r : int >= 1
        Number of insertions; the final multiplicity must not exceed ``degree``.

    Returns
    -------
    points_w : (n + r, ...) float
    knots : (n + r + degree + 1,) float
    """
    points_w = np.asarray(points_w, dtype=float)
    knots = np.asarray(knots, dtype=float)
    value = check_parameter(value, "knot value")
    if int(r) != r or r < 1:
        raise InvalidGeometryError(f"r must be an integer >= 1, got {r!r}")
    check_in_domain(value, knots, degree, "knot value")
    s = _multiplicity(knots, value)
    if s + r > degree:
        raise InvalidGeometryError(
            f"inserting knot {value!r} {int(r)} time(s) would raise its multiplicity "
            f"from {s} to {s + int(r)} > degree = {degree}")
    return _insert_many(points_w, knots, degree, np.full(int(r), value))


def refine_knots_array(points_w: ArrayLike, knots: ArrayLike, degree: int,
                       new_knots: ArrayLike) -> tuple[NDArray, NDArray]:
    """Insert every value of ``new_knots`` (knot refinement, A5.4 as repeated A5.1).

    Parameters
    ----------
    points_w : (n, ...) float
    knots : (n + degree + 1,) float
    degree : int
    new_knots : (m,) float
        Values inside the domain, repeats allowed; no resulting multiplicity may
        exceed ``degree``.

    Returns
    -------
    points_w : (n + m, ...) float
    knots : (n + m + degree + 1,) float
    """
    points_w = np.asarray(points_w, dtype=float)
    knots = np.asarray(knots, dtype=float)
    x = np.asarray(new_knots, dtype=float).reshape(-1)
    if x.size == 0:
        return points_w.copy(), knots.copy()
    if not np.all(np.isfinite(x)):
        raise InvalidGeometryError("new knots contain NaN or infinite values")
    lo, hi = domain_of(knots, degree)
    bad = x[(x < lo) | (x > hi)]
    if bad.size:
        raise InvalidGeometryError(
            f"new knot {bad[0]!r} is outside the domain [{lo!r}, {hi!r}]")
    values, counts = np.unique(x, return_counts=True)
    total = counts + np.array([_multiplicity(knots, v) for v in values])
    if total.max() > degree:
        k = int(np.argmax(total))
        raise InvalidGeometryError(
            f"knot {values[k]!r} would get multiplicity {int(total[k])} > degree = {degree}")
    return _insert_many(points_w, knots, degree, x)


def restrict_array(points_w: ArrayLike, knots: ArrayLike, degree: int, a: float, b: float
                   ) -> tuple[NDArray, NDArray]:
    """Restrict a homogeneous control array to the sub-domain ``[a, b]``.

    ``a`` and ``b`` are inserted up to multiplicity ``degree`` and the poles whose
    basis functions vanish on ``[a, b]`` are dropped; the result is clamped
    (end multiplicity ``degree + 1``) with domain exactly ``[a, b]``.

    Parameters
    ----------
    points_w : (n, ...) float
    knots : (n + degree + 1,) float
    a, b : float
        ``knots[degree] <= a < b <= knots[n]``.

    Returns
    -------
    points_w : (n', ...) float
    knots : (n' + degree + 1,) float
    """
    points_w = np.asarray(points_w, dtype=float)
    knots = np.asarray(knots, dtype=float)
    a = check_parameter(a, "a")
    b = check_parameter(b, "b")
    if not a < b:
        raise InvalidGeometryError(f"need a < b, got a = {a!r}, b = {b!r}")
    check_in_domain(a, knots, degree, "a")
    check_in_domain(b, knots, degree, "b")
    knots = _at_bound(_at_bound(knots, a), b)
    points_w, knots = _trim_start(points_w, knots, degree, a)
    return _trim_end(points_w, knots, degree, b)


#: a knot this close to a cut (relative to the knots' magnitude: 64 roundings) is taken
#: at the cut; a wider snap would move the geometry by the snap over the span's width
#: (1e-12 of the span moved a surface by 1.6e-11 of its size next to a short span)
_KNOT_SNAP = 64 * np.finfo(float).eps


def _at_bound(knots: NDArray, value: float) -> NDArray:
    """The knots with those a rounding off ``value`` moved onto it (the geometry moves by a
    rounding; the piece's domain is what was asked). A split a rounding off a knot of
    multiplicity ``degree`` inserted ``degree`` more knots a few ulps away: a span of width
    1e-16 at the end of the piece and derivatives off by orders of magnitude (a half
    cylinder split at its join: S_u of 152 for 45)."""
    near = np.abs(knots - value) <= _KNOT_SNAP * max(float(np.abs(knots).max()), abs(value), 1.0)
    if not near.any() or np.all(knots[near] == value):
        return knots
    out = knots.copy()
    out[near] = value
    return out


# -------------------------------------------------------------------- curves
def _is_clamped_over(knots: NDArray, degree: int, a: float, b: float) -> bool:
    """True when the knot vector already has end knots ``a`` and ``b`` of multiplicity p + 1."""
    return bool(np.all(knots[:degree + 1] == a) and np.all(knots[-degree - 1:] == b))


def _curve_result(curve: NurbsCurve, points_w: NDArray, knots: NDArray,
                  degree: int | None = None) -> NurbsCurve:
    w = points_w[:, -1]
    return NurbsCurve.construct_fast(points_w[:, :-1] / w[:, None], knots,
                                     curve.degree if degree is None else degree,
                                     w if curve.weights is not None else None)


def insert_knot(curve: NurbsCurve, t: float, r: int = 1) -> NurbsCurve:
    """Curve with the knot ``t`` inserted ``r`` times; same geometry (A5.1).

    Raises
    ------
    InvalidGeometryError
        ``t`` outside the domain, not finite, or multiplicity would exceed the degree.
    """
    pw, knots = insert_knot_array(curve.homogeneous_points(), curve.knots, curve.degree, t, r)
    return _curve_result(curve, pw, knots)


def refine(curve: NurbsCurve, new_knots: ArrayLike) -> NurbsCurve:
    """Curve with all of ``new_knots`` (m,) inserted; same geometry (A5.4)."""
    pw, knots = refine_knots_array(curve.homogeneous_points(), curve.knots, curve.degree,
                                   new_knots)
    return _curve_result(curve, pw, knots)


def restrict(curve: NurbsCurve, a: float, b: float) -> NurbsCurve:
    """The piece of ``curve`` over ``[a, b]``, clamped, with the original parameter values.

    A curve already clamped over ``[a, b]`` is returned as is (it is immutable).
    """
    if _is_clamped_over(curve.knots, curve.degree, a, b):
        return curve
    pw, knots = restrict_array(curve.homogeneous_points(), curve.knots, curve.degree, a, b)
    return _curve_result(curve, pw, knots)


def split(curve: NurbsCurve, t: float) -> tuple[NurbsCurve, NurbsCurve]:
    """Split at an interior parameter ``t`` into the pieces over ``[t0, t]`` and ``[t, t1]``.

    Raises
    ------
    InvalidGeometryError
        ``t`` not strictly inside the domain.
    """
    t = check_parameter(t, "split parameter")
    check_in_domain(t, curve.knots, curve.degree, "split parameter", open_ends=True)
    lo, hi = curve.domain
    return restrict(curve, lo, t), restrict(curve, t, hi)


def clamp(curve: NurbsCurve) -> NurbsCurve:
    """Clamped form of a curve over the same domain ``[t_p, t_n]``.

    The domain ends are inserted up to multiplicity ``p`` and the poles outside
    are dropped, so the end knots get multiplicity ``p + 1`` and the end poles
    are the end points. An already clamped curve comes back unchanged.
    """
    lo, hi = curve.domain
    return restrict(curve, lo, hi)


def periodic_to_clamped(poles: ArrayLike, degree: int, knots: ArrayLike | None = None,
                        weights: ArrayLike | None = None) -> NurbsCurve:
    """Clamped NURBS curve of a closed periodic B-spline.

    The periodic curve has ``n`` poles ``P_0..P_{n-1}`` that wrap
    (``P_{i+n} = P_i``) and one period of knots ``u_0 <= ... <= u_n`` with
    period ``T = u_n - u_0``, extended periodically
    ``t_{j + n} = t_j + T`` (section 12.2 of [PT]). The unclamped curve with the
    ``n + p`` wrapped poles and the ``n + 2p + 1`` extended knots is built and
    then clamped over its domain ``[u_0, u_n]``.

    Parameters
    ----------
    poles : (n, d) float
        The distinct poles of one period, ``n >= degree + 1``.
    degree : int >= 1
    knots : (n + 1,) float, optional
        One period of knots, non-decreasing, ``u_n > u_0``, each multiplicity at
        most ``degree`` (``u_0`` and ``u_n`` are the same knot: their multiplicities
        add up). Default: uniform ``0, 1, ..., n``.
    weights : (n,) float, optional
        Positive weights of the poles.

    Returns
    -------
    NurbsCurve
        Clamped, domain ``[u_0, u_n]``, ``C(u_0) == C(u_n)``.
    """
    poles = np.asarray(poles, dtype=float)
    if poles.ndim != 2:
        raise InvalidGeometryError(f"poles must have shape (n, d), got {poles.shape}")
    if int(degree) != degree or degree < 1:
        raise InvalidGeometryError(f"degree must be an integer >= 1, got {degree!r}")
    p, n = int(degree), poles.shape[0]
    if n < p + 1:
        raise InvalidGeometryError(
            f"a periodic curve of degree {p} needs at least {p + 1} poles, got {n}")
    u = np.arange(n + 1, dtype=float) if knots is None else np.asarray(knots, dtype=float)
    if u.shape != (n + 1,):
        raise InvalidGeometryError(
            f"periodic knots must have shape (n + 1,) = ({n + 1},), got {u.shape}")
    if not np.all(np.isfinite(u)):
        raise InvalidGeometryError("periodic knots contain NaN or infinite values")
    if np.any(np.diff(u) < 0) or not u[-1] > u[0]:
        raise InvalidGeometryError("periodic knots must be non-decreasing with u[n] > u[0]")
    period = u[-1] - u[0]
    j = np.arange(-p, n + p + 1)
    flat = u[j % n] + (j // n) * period
    values, counts = np.unique(flat[p:n + p + 1], return_counts=True)
    counts[0] += counts[-1] - 1 if values.size > 1 else 0     # u_0 and u_n are one knot
    if counts[:-1].max() > p:
        k = int(np.argmax(counts[:-1]))
        raise InvalidGeometryError(
            f"periodic knot {values[k]!r} has multiplicity {int(counts[k])} > degree = {p}")
    idx = np.arange(n + p) % n
    w = None if weights is None else np.asarray(weights, dtype=float)
    if w is not None and w.shape != (n,):
        raise InvalidGeometryError(f"weights must have shape ({n},), got {w.shape}")
    curve = NurbsCurve(poles[idx], flat, p, None if w is None else w[idx])
    return clamp(curve)


# ------------------------------------------------------------------ surfaces
def insert_knot_surface(surface: NurbsSurface, value: float,
                        direction: Direction | str, r: int = 1) -> NurbsSurface:
    """Surface with ``value`` inserted ``r`` times into the knots of ``direction``."""
    direction = as_direction(direction)
    knots, degree = knots_along(surface, direction)
    pw, new = insert_knot_array(net_along(surface, direction), knots, degree, value, r)
    return surface_from_net(surface, direction, pw, new)


def refine_surface(surface: NurbsSurface, new_knots: ArrayLike,
                   direction: Direction | str) -> NurbsSurface:
    """Surface with all of ``new_knots`` (m,) inserted in ``direction``."""
    direction = as_direction(direction)
    knots, degree = knots_along(surface, direction)
    pw, new = refine_knots_array(net_along(surface, direction), knots, degree, new_knots)
    return surface_from_net(surface, direction, pw, new)


def _restrict_direction(surface: NurbsSurface, direction: Direction, a: float, b: float
                        ) -> NurbsSurface:
    knots, degree = knots_along(surface, direction)
    if _is_clamped_over(knots, degree, a, b):
        return surface
    pw, new = restrict_array(net_along(surface, direction), knots, degree, a, b)
    return surface_from_net(surface, direction, pw, new)


def restrict_surface(surface: NurbsSurface, u0: float | None = None, u1: float | None = None,
                     v0: float | None = None, v1: float | None = None) -> NurbsSurface:
    """The patch of ``surface`` over ``[u0, u1] x [v0, v1]``, clamped, original parameters.

    A bound left as ``None`` is the corresponding end of the surface's domain.
    """
    du0, du1, dv0, dv1 = surface.domain
    u0 = du0 if u0 is None else u0
    u1 = du1 if u1 is None else u1
    v0 = dv0 if v0 is None else v0
    v1 = dv1 if v1 is None else v1
    out = _restrict_direction(surface, Direction.U, u0, u1)
    return _restrict_direction(out, Direction.V, v0, v1)


def split_surface(surface: NurbsSurface, value: float, direction: Direction | str
                  ) -> tuple[NurbsSurface, NurbsSurface]:
    """Split along the isoparametric line ``direction = value`` (strictly interior)."""
    direction = as_direction(direction)
    knots, degree = knots_along(surface, direction)
    value = check_parameter(value, "split parameter")
    check_in_domain(value, knots, degree, "split parameter", open_ends=True)
    lo, hi = domain_of(knots, degree)
    return (_restrict_direction(surface, direction, lo, value),
            _restrict_direction(surface, direction, value, hi))


def clamp_surface(surface: NurbsSurface) -> NurbsSurface:
    """Clamped form of a surface in both directions over the same domain."""
    return restrict_surface(surface)
