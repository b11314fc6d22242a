"""Interpolation and least-squares approximation of points by B-spline curves and surfaces.

Global interpolation (section 9.2 of [PT]) puts one parameter ``ubar_k`` on each
point ``Q_k`` and solves the collocation system

.. math:: \\sum_i N_{i,p}(\\bar u_k)\\, P_i = Q_k, \\qquad k = 0..n-1, \\qquad (9.5)

whose matrix is banded (each row has at most ``p + 1`` non-zeros next to the
diagonal); it is solved with :func:`scipy.linalg.solve_banded`, all coordinates
(and, for surfaces, all rows of the net) as right-hand sides of one
factorization. Everything returned is non-rational and clamped.

Parameters come from chord lengths (eq. 9.5) or the centripetal rule (eq. 9.6),
knots from averaging (eq. 9.8, and eq. 9.22 with end derivatives) or, for the
classical C2 cubic spline, from the parameters themselves as breakpoints
(:func:`knots_from_breakpoints`).

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   section 9.2 (global interpolation, A9.1), 9.2.2 (end derivatives),
   9.2.3 (C2 cubic splines), 9.2.5 (surfaces, A9.4), 9.4.1 (least squares
   with fixed ends, eqs. 9.63-9.69, A9.7).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import DegenerateGeometryError, InvalidGeometryError
from .basis import basis_derivatives, find_span, validate_knots
from .curve import NurbsCurve
from .surface import NurbsSurface

__all__ = [
    "chord_length_parameters",
    "averaged_knots",
    "knots_from_breakpoints",
    "interpolate_curve",
    "interpolate_surface",
    "approximation_knots",
    "approximate_curve",
    "seam_tangent",
    "solve_banded_rows",
]


# ----------------------------------------------------------------- validation
def _as_points(points: ArrayLike, name: str = "points", ndim: int = 2) -> NDArray:
    q = np.asarray(points, dtype=float)
    if q.ndim != ndim or q.shape[-1] < 1:
        shape = "(n, d)" if ndim == 2 else "(n_u, n_v, d)"
        raise InvalidGeometryError(f"{name} must have shape {shape}, got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise InvalidGeometryError(f"{name} contain NaN or infinite values")
    return q


def _check_degree(degree: int, n_points: int, n_control: int, name: str = "degree") -> int:
    if isinstance(degree, bool) or int(degree) != degree or degree < 1:
        raise InvalidGeometryError(f"{name} must be an integer >= 1, got {degree!r}")
    degree = int(degree)
    if n_control < degree + 1:
        raise InvalidGeometryError(
            f"{name} = {degree} needs at least {degree + 1} control points; "
            f"{n_points} points give {n_control}")
    return degree


def _check_parameters(params: ArrayLike, n: int, name: str = "parameters") -> NDArray:
    t = np.asarray(params, dtype=float)
    if t.shape != (n,):
        raise InvalidGeometryError(f"{name} must have shape ({n},), got {t.shape}")
    if not np.all(np.isfinite(t)):
        raise InvalidGeometryError(f"{name} contain NaN or infinite values")
    if np.any(np.diff(t) < 0):
        raise InvalidGeometryError(f"{name} must be non-decreasing")
    if t[-1] <= t[0]:
        raise DegenerateGeometryError(f"{name} span an empty interval [{t[0]}, {t[-1]}]")
    return t


def _require_distinct(params: NDArray, name: str = "points") -> None:
    same = np.flatnonzero(np.diff(params) <= 0)
    if same.size:
        k = int(same[0])
        raise DegenerateGeometryError(
            f"{name} {k} and {k + 1} have the same parameter (coincident consecutive "
            f"points?); interpolation needs strictly increasing parameters")


# ----------------------------------------------------------------- parameters
def chord_length_parameters(points: ArrayLike, *, centripetal: bool = False,
                            interval: tuple[float, float] = (0.0, 1.0)) -> NDArray:
    """Chord-length (eq. 9.5) or centripetal (eq. 9.6) parameters of a point sequence.

    Parameters
    ----------
    points : (n, d) float, n >= 2
    centripetal : bool
        Use square roots of the chord lengths (better for sharp turns).
    interval : (float, float)
        The parameters run from ``interval[0]`` to ``interval[1]`` exactly.

    Returns
    -------
    (n,) float, non-decreasing
        Repeated consecutive points get equal parameters (interpolation refuses
        them; least squares accepts them).

    Raises
    ------
    DegenerateGeometryError
        All points coincide.
    """
    q = _as_points(points)
    if q.shape[0] < 2:
        raise InvalidGeometryError(f"need at least 2 points, got {q.shape[0]}")
    a, b = (float(x) for x in interval)
    if not (np.isfinite(a) and np.isfinite(b) and a < b):
        raise InvalidGeometryError(f"interval must be finite with a < b, got {interval!r}")
    chords = np.linalg.norm(np.diff(q, axis=0), axis=1)
    if centripetal:
        chords = np.sqrt(chords)
    total = float(np.sum(chords))
    if not total > 0:
        raise DegenerateGeometryError(f"all {q.shape[0]} points coincide: no chord length")
    t = a + (b - a) * np.concatenate([[0.0], np.cumsum(chords)]) / total
    t[-1] = b
    return t


def _grid_parameters(q: NDArray, centripetal: bool = False) -> NDArray:
    """Parameters along axis 0 of a net ``(n_u, n_v, d)``, averaged over columns (A9.3).

    Columns whose points all coincide (a pole) are left out of the average.
    """
    chords = np.linalg.norm(np.diff(q, axis=0), axis=2)              # (n_u - 1, n_v)
    if centripetal:
        chords = np.sqrt(chords)
    total = chords.sum(axis=0)
    keep = total > 0
    if not np.any(keep):
        raise DegenerateGeometryError("every column of the point grid collapses to one point")
    cum = np.concatenate([np.zeros((1, int(keep.sum()))), np.cumsum(chords[:, keep], axis=0)])
    t = np.mean(cum / total[keep], axis=1)
    t[0], t[-1] = 0.0, 1.0
    return t


# ---------------------------------------------------------------------- knots
def averaged_knots(params: ArrayLike, degree: int, *, end_derivatives: bool = False) -> NDArray:
    """Knots by averaging the parameters (eq. 9.8; eq. 9.22 with end derivatives).

    .. math:: u_0 = \\dots = u_p = \\bar u_0, \\quad
              u_{j+p} = \\frac1p \\sum_{i=j}^{j+p-1} \\bar u_i, \\quad
              u_{n} = \\dots = u_{n+p} = \\bar u_{n-1}

    for ``n`` parameters (``n`` control points). With ``end_derivatives`` the
    knots are for ``n + 2`` control points (one extra at each end):
    ``u_{j+p+1} = (1/p) sum_{i=j}^{j+p-1} ubar_i``, ``j = 0..n-p`` (eq. 9.22).

    Parameters
    ----------
    params : (n,) float, non-decreasing
    degree : int
        ``1 <= degree <= n - 1`` (``2 <= degree <= n + 1`` with end derivatives).

    Returns
    -------
    (n + degree + 1,) float, or (n + degree + 3,) with ``end_derivatives``;
    the knots satisfy the Schoenberg-Whitney condition for ``params``.
    """
    t = np.asarray(params, dtype=float)
    t = _check_parameters(t, t.size, "params")
    extra = 2 if end_derivatives else 0
    p = _check_degree(degree, t.size, t.size + extra)
    if end_derivatives and p < 2:
        raise InvalidGeometryError("end derivatives need degree >= 2")
    csum = np.concatenate([[0.0], np.cumsum(t)])
    if end_derivatives:
        j = np.arange(0, t.size - p + 1)
    else:
        j = np.arange(1, t.size - p)
    inner = (csum[j + p] - csum[j]) / p
    return np.concatenate([np.full(p + 1, t[0]), inner, np.full(p + 1, t[-1])])


def knots_from_breakpoints(params: ArrayLike, degree: int = 3, *,
                           end_condition: str = "not-a-knot") -> NDArray:
    """Knots of the classical spline with the parameters as breakpoints (section 9.2.3).

    Parameters
    ----------
    params : (n,) float, strictly increasing
    degree : int
    end_condition : {"not-a-knot", "clamped"}
        ``"not-a-knot"`` (any degree, ``n >= degree + 1`` points, ``n`` control
        points): de Boor's choice. For odd ``p`` the interior knots are the
        parameters without the ``(p - 1) / 2`` first and last interior ones,
        for even ``p`` the midpoints between parameters likewise; for the cubic
        this removes the second and the second-to-last breakpoint, so the first
        and the last two polynomial pieces are one cubic (C3 there).
        ``"clamped"`` (cubic only, ``n + 2`` control points): every interior
        parameter is a knot, the C2 cubic spline of P&T 9.2.3 whose two extra
        conditions are the end derivatives (``interpolate_curve(...,
        end_derivatives=...)``).

    Returns
    -------
    (n + degree + 1,) or, clamped, (n + 6,) float
    """
    t = np.asarray(params, dtype=float)
    t = _check_parameters(t, t.size, "params")
    _require_distinct(t, "params")
    n = t.size
    if end_condition == "clamped":
        if degree != 3:
            raise InvalidGeometryError(
                f"end_condition='clamped' is the cubic spline, got degree {degree!r}")
        inner = t[1:-1]
        p = 3
    elif end_condition == "not-a-knot":
        p = _check_degree(degree, n, n)
        if p % 2:
            h = (p + 1) // 2
            inner = t[h:n - h]
        else:
            h = p // 2
            inner = (0.5 * (t[:-1] + t[1:]))[h:n - 1 - h]
    else:
        raise InvalidGeometryError(
            f"end_condition must be 'not-a-knot' or 'clamped', got {end_condition!r}")
    return np.concatenate([np.full(p + 1, t[0]), inner, np.full(p + 1, t[-1])])


# ------------------------------------------------------------ banded systems
def _collocation_entries(knots: NDArray, degree: int, t: NDArray, derivative: int = 0
                         ) -> tuple[NDArray, NDArray]:
    """Columns and values of the non-zero basis functions at ``t``: (m, p+1) each."""
    span = find_span(knots, degree, t)
    ders, _ = basis_derivatives(knots, degree, t, derivative, span)
    cols = span[:, None] - degree + np.arange(degree + 1)
    return cols, ders[:, derivative, :]


def solve_banded_rows(cols: NDArray, values: NDArray, rhs: NDArray) -> NDArray:
    """Solve ``A x = rhs`` where row ``r`` of ``A`` has ``values[r]`` at ``cols[r]``.

    Parameters
    ----------
    cols, values : (N, w) int, float
    rhs : (N, k) float

    Returns
    -------
    (N, k) float
    """
    n = cols.shape[0]
    rows = np.broadcast_to(np.arange(n)[:, None], cols.shape)
    lower = int(max(np.max(rows - cols), 0))
    upper = int(max(np.max(cols - rows), 0))
    ab = np.zeros((lower + upper + 1, n))
    ab[upper + rows - cols, cols] = values
    # scipy on first use: importing it costs 0.3 s
    import scipy.linalg

    try:
        x = scipy.linalg.solve_banded((lower, upper), ab, rhs, check_finite=False)
    except np.linalg.LinAlgError as exc:
        raise DegenerateGeometryError(
            "singular collocation matrix: the parameters do not satisfy the "
            "Schoenberg-Whitney condition for these knots") from exc
    if not np.all(np.isfinite(x)):
        raise DegenerateGeometryError("interpolation gave non-finite control points")
    return x


def _check_in_domain(t: NDArray, knots: NDArray, degree: int, n_control: int, name: str
                     ) -> NDArray:
    """``t`` clipped to the knots' domain; more than rounding outside it is an error."""
    lo, hi = knots[degree], knots[n_control]
    slack = 1e-12 * (hi - lo)
    if t[0] < lo - slack or t[-1] > hi + slack:
        raise InvalidGeometryError(
            f"{name} [{t[0]}, {t[-1]}] are outside the knots' domain [{lo}, {hi}]")
    return np.clip(t, lo, hi)


def _interpolation_knots(t: NDArray, degree: int, knots, n_control: int, name: str
                         ) -> tuple[NDArray, NDArray]:
    """Knots (given or eq. 9.8) and the parameters clipped to their domain."""
    if knots is None:
        return averaged_knots(t, degree), t
    knots = validate_knots(knots, degree, n_control, name)
    return knots, _check_in_domain(t, knots, degree, n_control, "parameters")


def _solve_collocation(knots: NDArray, degree: int, t: NDArray, rhs: NDArray) -> NDArray:
    """Control points ``(n, ...)`` interpolating ``rhs (n, ...)`` at ``t`` (many RHS at once)."""
    cols, values = _collocation_entries(knots, degree, t)
    flat = rhs.reshape(rhs.shape[0], -1)
    return solve_banded_rows(cols, values, flat).reshape(rhs.shape)


# -------------------------------------------------------------------- curves
def seam_tangent(q: NDArray, t: NDArray) -> NDArray:
    """Derivative at the seam of a closed sequence ``q (n, d)`` (``q[-1] == q[0]``, ``t[-1]``
    the period): of the quartic through ``Q_{n-3}, Q_{n-2}, Q_0, Q_1, Q_2`` (their
    parameters shifted by the period across the seam) when there are five distinct
    points, else of the parabola through ``Q_{n-2}, Q_0, Q_1`` (Bessel, section 9.3.4).

    The parabola's derivative is only second-order accurate, so a C2 cubic through
    samples ``h`` apart was off by about ten times its interior error in the spans at
    the seam; the quartic's is fourth-order accurate (Lagrange weights
    ``L_j'(0) = prod_{m != j, 0} (-x_m) / prod_{m != j} (x_j - x_m)``)."""
    n = q.shape[0]
    if n < 6:
        h0 = t[-1] - t[-2]
        h1 = t[1] - t[0]
        d0 = (q[0] - q[-2]) / h0
        d1 = (q[1] - q[0]) / h1
        return (h1 * d0 + h0 * d1) / (h0 + h1)
    period = float(t[-1] - t[0])
    t0 = float(t[0])
    x = [float(t[-3]) - period - t0, float(t[-2]) - period - t0, 0.0, float(t[1]) - t0,
         float(t[2]) - t0]
    weights = np.empty(5)              # five nodes: plain floats, no array call per product
    for j in range(5):
        if j == 2:
            weights[j] = sum(-1.0 / x[m] for m in range(5) if m != 2)
            continue
        numerator, denominator = 1.0, 1.0
        for m in range(5):
            if m != j and m != 2:
                numerator *= -x[m]
            if m != j:
                denominator *= x[j] - x[m]
        weights[j] = numerator / denominator
    return weights @ q[[n - 3, n - 2, 0, 1, 2]]


def interpolate_curve(points: ArrayLike, *, degree: int = 3, parameters: ArrayLike | None = None,
                      knots: ArrayLike | None = None,
                      end_derivatives: tuple[ArrayLike, ArrayLike] | None = None,
                      centripetal: bool = False, smooth_closure: bool = False) -> NurbsCurve:
    """Global interpolation of points by a clamped B-spline curve (A9.1, 9.2.2).

    Parameters
    ----------
    points : (n, d) float
        ``d = 2`` for curves in a parameter plane (pcurves), 3 for space curves.
        Consecutive points must differ.
    degree : int
        ``1 <= degree <= n - 1`` (``<= n + 1`` with end derivatives). The
        default cubic is C2 at every knot.
    parameters : (n,) float, optional
        Strictly increasing; default :func:`chord_length_parameters` on [0, 1]
        (``centripetal`` selects eq. 9.6).
    knots : (n_control + degree + 1,) float, optional
        Default :func:`averaged_knots` (eq. 9.8); with end derivatives eq. 9.22,
        or for the cubic the parameters as breakpoints (the C2 cubic spline of
        9.2.3). The parameters must lie in the knots' domain.
    end_derivatives : ((d,) float, (d,) float), optional
        First derivatives ``C'`` at the first and last parameter (with respect
        to the curve's parameter); adds one control point at each end.
    smooth_closure : bool
        For a closed sequence (first point == last point): impose the same
        derivative at both ends, that of the quartic through the two points on
        each side of the seam (Bessel's parabola through ``Q_{n-2}, Q_0, Q_1``
        below five distinct points), which makes the closure C1 (not C2).
        Without it a closed sequence gives a curve that closes (C0; the first
        and last control points are both set to the point exactly).

    Returns
    -------
    NurbsCurve
        Non-rational, ``C(ubar_k) = Q_k`` to rounding.

    Raises
    ------
    InvalidGeometryError
        Bad shapes, NaN, degree too high for the number of points, parameters
        outside the knots' domain, ``smooth_closure`` of an open sequence.
    DegenerateGeometryError
        Coincident consecutive points, or knots violating Schoenberg-Whitney.
    """
    q = _as_points(points)
    n = q.shape[0]
    if n < 2:
        raise InvalidGeometryError(f"need at least 2 points, got {n}")
    scale = float(np.abs(q).max()) + 1.0
    closed = bool(np.all(np.abs(q[0] - q[-1]) <= 1e-14 * scale))
    if smooth_closure and not closed:
        raise InvalidGeometryError("smooth_closure needs a closed sequence (first == last point)")
    if smooth_closure and end_derivatives is not None:
        raise InvalidGeometryError("give either end_derivatives or smooth_closure, not both")
    extra = 2 if (end_derivatives is not None or smooth_closure) else 0
    p = _check_degree(degree, n, n + extra)
    if parameters is None:
        t = chord_length_parameters(q, centripetal=centripetal)
    else:
        t = _check_parameters(parameters, n)
    _require_distinct(t)
    if smooth_closure:
        if n < 4:
            raise InvalidGeometryError(f"smooth_closure needs at least 4 points, got {n}")
        tangent = seam_tangent(q, t)
        end_derivatives = (tangent, tangent)
    if end_derivatives is None:
        knots, t = _interpolation_knots(t, p, knots, n, "knots")
        control = _solve_collocation(knots, p, t, q)
    else:
        control, knots = _interpolate_with_derivatives(q, t, p, knots, end_derivatives)
    if knots[0] == knots[p] and knots[-1] == knots[-p - 1] and t[0] == knots[0] \
            and t[-1] == knots[-1]:
        control[0], control[-1] = q[0], q[-1]       # clamped ends interpolate exactly
    return NurbsCurve(control, knots, p)


def _interpolate_with_derivatives(q: NDArray, t: NDArray, p: int, knots,
                                  end_derivatives) -> tuple[NDArray, NDArray]:
    """Rows: Q_0, D_0, Q_1..Q_{n-2}, D_{n-1}, Q_{n-1} (eqs. 9.19-9.21, A9.2 for the cubic)."""
    n, d = q.shape
    if p < 2:
        raise InvalidGeometryError("end derivatives need degree >= 2")
    derivs = np.asarray(end_derivatives, dtype=float)
    if derivs.shape != (2, d):
        raise InvalidGeometryError(
            f"end_derivatives must be two vectors of dimension {d}, got shape {derivs.shape}")
    if not np.all(np.isfinite(derivs)):
        raise InvalidGeometryError("end_derivatives contain NaN or infinite values")
    if knots is None:
        knots = (knots_from_breakpoints(t, 3, end_condition="clamped") if p == 3
                 else averaged_knots(t, p, end_derivatives=True))
    else:
        knots = validate_knots(knots, p, n + 2, "knots")
        t = _check_in_domain(t, knots, p, n + 2, "parameters")
    cols, values = _collocation_entries(knots, p, t)
    dcols, dvalues = _collocation_entries(knots, p, t[[0, -1]], 1)
    order = np.concatenate([[0], [n], np.arange(1, n - 1), [n + 1], [n - 1]])
    all_cols = np.concatenate([cols, dcols])[order]
    all_values = np.concatenate([values, dvalues])[order]
    rhs = np.concatenate([q, derivs])[order]
    return solve_banded_rows(all_cols, all_values, rhs), knots


# ------------------------------------------------------------------ surfaces
def interpolate_surface(points: ArrayLike, *, degree_u: int = 3, degree_v: int = 3,
                        params_u: ArrayLike | None = None, params_v: ArrayLike | None = None,
                        knots_u: ArrayLike | None = None, knots_v: ArrayLike | None = None,
                        centripetal: bool = False) -> NurbsSurface:
    """Tensor-product interpolation of a point grid (A9.4).

    ``S(ubar_k, vbar_l) = Q_kl``: first every column ``Q_{., l}`` is interpolated
    in ``u`` (one factorization, ``n_v * d`` right-hand sides), then every row of
    the result in ``v``.

    Parameters
    ----------
    points : (n_u, n_v, d) float
    degree_u, degree_v : int
    params_u : (n_u,) float, optional
        Default: chord-length parameters of each column averaged over the
        columns (eqs. 9.5 and 9.23 of A9.3), collapsed columns (poles) left out.
    params_v : (n_v,) float, optional
    knots_u, knots_v : full knot vectors, optional
        Default :func:`averaged_knots`.

    Returns
    -------
    NurbsSurface, non-rational, ``(n_u, n_v)`` control points.
    """
    q = _as_points(points, ndim=3)
    nu, nv, _ = q.shape
    p = _check_degree(degree_u, nu, nu, "degree_u")
    r = _check_degree(degree_v, nv, nv, "degree_v")
    if params_u is None:
        tu = _grid_parameters(q, centripetal)
    else:
        tu = _check_parameters(params_u, nu, "params_u")
    if params_v is None:
        tv = _grid_parameters(np.swapaxes(q, 0, 1), centripetal)
    else:
        tv = _check_parameters(params_v, nv, "params_v")
    _require_distinct(tu, "rows of points (u)")
    _require_distinct(tv, "columns of points (v)")
    ku, tu = _interpolation_knots(tu, p, knots_u, nu, "knots_u")
    kv, tv = _interpolation_knots(tv, r, knots_v, nv, "knots_v")
    rows = _solve_collocation(ku, p, tu, q)                              # (n_u, n_v, d)
    net = _solve_collocation(kv, r, tv, np.swapaxes(rows, 0, 1))         # (n_v, n_u, d)
    return NurbsSurface(np.swapaxes(net, 0, 1), ku, kv, p, r)


# ------------------------------------------------------------- least squares
def approximation_knots(params: ArrayLike, n_control: int, degree: int) -> NDArray:
    """Knots for least-squares fitting of ``m`` parameters with ``n_control`` poles.

    Eqs. 9.68-9.69: with ``d = m / (n_control - p)``, for ``j = 1..n_control-p-1``,
    ``i = floor(j d)``, ``alpha = j d - i``:
    ``u_{p+j} = (1 - alpha) ubar_{i-1} + alpha ubar_i``, so every knot span
    holds at least one parameter (the normal matrix is positive definite).

    Returns
    -------
    (n_control + degree + 1,) float
    """
    t = np.asarray(params, dtype=float)
    m, p = t.size, int(degree)
    d = m / (n_control - p)
    jd = np.arange(1, n_control - p) * d
    i = np.floor(jd).astype(int)
    alpha = jd - i
    inner = (1 - alpha) * t[i - 1] + alpha * t[i]
    return np.concatenate([np.full(p + 1, t[0]), inner, np.full(p + 1, t[-1])])


def approximate_curve(points: ArrayLike, n_control: int, *, degree: int = 3,
                      parameters: ArrayLike | None = None,
                      knots: ArrayLike | None = None) -> NurbsCurve:
    """Least-squares B-spline curve through the end points (section 9.4.1, A9.7).

    The end control points are the end points; the interior ones minimize
    ``sum_k |Q_k - C(ubar_k)|^2`` (eq. 9.63) through the normal equations
    ``(N^T N) P = R`` (eq. 9.67), a symmetric positive definite band system
    solved with :func:`scipy.linalg.solveh_banded` (when its Cholesky factorization
    fails from ill-conditioning, the dense least-squares problem is solved instead).

    Parameters
    ----------
    points : (m, d) float
    n_control : int
        ``degree + 1 <= n_control <= m``.
    degree : int
    parameters : (m,) float, optional
        Non-decreasing; default chord length on [0, 1] (repeated points allowed).
    knots : (n_control + degree + 1,) float, optional
        Default :func:`approximation_knots` (eqs. 9.68-9.69), or with
        ``n_control == m`` (interpolation) :func:`averaged_knots` (eq. 9.8),
        for which eq. 9.68 can leave a span empty.

    Returns
    -------
    NurbsCurve, non-rational, ``C(ubar_0) = Q_0`` and ``C(ubar_{m-1}) = Q_{m-1}``.
    """
    q = _as_points(points)
    m = q.shape[0]
    if m < 2:
        raise InvalidGeometryError(f"need at least 2 points, got {m}")
    if isinstance(n_control, bool) or int(n_control) != n_control or not 2 <= n_control <= m:
        raise InvalidGeometryError(
            f"n_control must be an integer in [2, {m}] (the number of points), got {n_control!r}")
    n_control = int(n_control)
    p = _check_degree(degree, m, n_control)
    t = chord_length_parameters(q) if parameters is None else _check_parameters(parameters, m)
    if knots is None and n_control == m:        # as many poles as points: interpolation
        _require_distinct(t)
        knots = averaged_knots(t, p)
    elif knots is None:
        knots = approximation_knots(t, n_control, p)
    else:
        knots = validate_knots(knots, p, n_control, "knots")
        t = _check_in_domain(t, knots, p, n_control, "parameters")
    control = np.empty((n_control, q.shape[1]))
    control[0], control[-1] = q[0], q[-1]
    if n_control > 2:
        control[1:-1] = _least_squares_interior(knots, p, t, q, n_control)
    return NurbsCurve(control, knots, p)


def _least_squares_interior(knots: NDArray, p: int, t: NDArray, q: NDArray,
                            n_control: int) -> NDArray:
    """Interior poles ``P_1..P_{n-2}`` from the banded normal equations (eqs. 9.63-9.67)."""
    cols, values = _collocation_entries(knots, p, t)                    # (m, p+1)
    first = np.where(cols == 0, values, 0.0).sum(axis=1)
    last = np.where(cols == n_control - 1, values, 0.0).sum(axis=1)
    residual = q - first[:, None] * q[0] - last[:, None] * q[-1]        # R_k, eq. 9.66
    unknown = (cols >= 1) & (cols <= n_control - 2)
    vals = np.where(unknown, values, 0.0)
    idx = np.clip(cols - 1, 0, n_control - 3)
    size = n_control - 2
    rhs = np.zeros((size, q.shape[1]))
    np.add.at(rhs, idx.reshape(-1), (vals[:, :, None] * residual[:, None, :]).reshape(-1, q.shape[1]))
    # upper band storage: ab[p + i - j, j] = M[i, j] for i <= j
    outer = vals[:, :, None] * vals[:, None, :]                         # (m, p+1, p+1)
    ii, jj = np.broadcast_arrays(idx[:, :, None], idx[:, None, :])
    upper = (jj >= ii) & unknown[:, :, None] & unknown[:, None, :]
    ab = np.zeros((p + 1, size))
    np.add.at(ab, (p + ii[upper] - jj[upper], jj[upper]), outer[upper])
    if size == 1:       # (scipy's tridiagonal path refuses a 1 x 1 system)
        if not ab[-1, 0] > 0:
            raise DegenerateGeometryError("singular least-squares system (Schoenberg-Whitney)")
        return rhs / ab[-1, 0]
    # scipy on first use: importing it costs 0.3 s
    import scipy.linalg

    try:
        return scipy.linalg.solveh_banded(ab, rhs, check_finite=False)
    except np.linalg.LinAlgError:
        pass
    # the normal equations square the condition number; near interpolation
    # (n_control close to m) Cholesky can fail: solve the least-squares problem
    # itself (QR/SVD), which only needs full column rank
    dense = np.zeros((t.size, size))
    rows = np.broadcast_to(np.arange(t.size)[:, None], idx.shape)
    np.add.at(dense, (rows[unknown], idx[unknown]), vals[unknown])
    solution, _, rank, _ = np.linalg.lstsq(dense, residual, rcond=None)
    if rank < size:
        raise DegenerateGeometryError(
            "singular least-squares system: some knot span holds no parameter "
            "(Schoenberg-Whitney)")
    return solution
