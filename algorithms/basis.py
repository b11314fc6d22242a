"""B-spline basis functions, vectorized over many parameter values, and the checks of the data
that defines them (knots, weights).

The functions here work on a full (flat) knot vector ``knots`` of length
``n + degree + 1`` for ``n`` control points, and on arrays of parameters at once:
the loops run over the degree (at most a few tens of numpy operations), never
over the points.

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   algorithms A2.1 (span), A2.2 (basis functions), A2.3 (derivatives).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import InvalidGeometryError
from . import basis_kernels
from .jit import compiled as worth_compiling

__all__ = [
    "basis_derivatives",
    "basis_functions",
    "check_offset",
    "check_weights",
    "collocation_matrix",
    "distinct_knots",
    "find_span",
    "frozen_array",
    "greville_abscissae",
    "owned_array",
    "span_range",
    "validate_knots",
]


def validate_knots(knots: ArrayLike, degree: int, n_control: int, name: str = "knots") -> NDArray:
    """Check a full knot vector and return it as a float array.

    Parameters
    ----------
    knots : (n_control + degree + 1,) float
        Non-decreasing knot values.
    degree : int
        Polynomial degree, >= 1.
    n_control : int
        Number of control points, >= degree + 1.

    Raises
    ------
    InvalidGeometryError
        With a message that says which condition failed.
    """
    if int(degree) != degree or degree < 1:
        raise InvalidGeometryError(f"{name}: degree must be an integer >= 1, got {degree!r}")
    knots = np.asarray(knots, dtype=float)
    if knots.ndim != 1:
        raise InvalidGeometryError(f"{name} must be one-dimensional, got shape {knots.shape}")
    if n_control < degree + 1:
        raise InvalidGeometryError(
            f"{name}: need at least degree + 1 = {degree + 1} control points, got {n_control}")
    if knots.size != n_control + degree + 1:
        raise InvalidGeometryError(
            f"{name}: expected n_control + degree + 1 = {n_control + degree + 1} knots "
            f"for {n_control} control points of degree {degree}, got {knots.size}")
    if not np.all(np.isfinite(knots)):
        raise InvalidGeometryError(f"{name} contain NaN or infinite values")
    if np.any(np.diff(knots) < 0):
        raise InvalidGeometryError(f"{name} must be non-decreasing")
    if knots[n_control] <= knots[degree]:
        raise InvalidGeometryError(
            f"{name}: empty parameter domain [{knots[degree]}, {knots[n_control]}]")
    inner = knots[1:-1]
    # non-decreasing: a value repeated more than degree + 1 times spans degree + 2 places
    if inner.size > degree + 1 and np.any(inner[degree + 1:] == inner[:-(degree + 1)]):
        _, counts = np.unique(inner, return_counts=True)
        raise InvalidGeometryError(
            f"{name}: an interior knot has multiplicity {counts.max()} > degree + 1 = {degree + 1}")
    return knots


def frozen_array(a: ArrayLike) -> NDArray:
    """A read-only float copy of ``a`` (the arrays of the immutable NURBS types)."""
    out = np.array(a, dtype=float, copy=True)
    out.setflags(write=False)
    return out


def owned_array(a: ArrayLike) -> NDArray:
    """``a`` made read-only in place when it is a C-contiguous float array owning its data
    (a fresh result), else a read-only copy (a view or another layout): the arrays of a
    trusted ``construct_fast``, laid out as :func:`frozen_array` lays them out."""
    out = np.asarray(a, dtype=float)
    if not (out.flags.c_contiguous and out.flags.owndata):
        out = np.array(out, dtype=float, order="C")
    out.setflags(write=False)
    return out


def check_weights(weights: NDArray | None, shape: tuple[int, ...], name: str) -> NDArray | None:
    """Refuse weights of another ``shape`` than the poles', or not finite and positive."""
    if weights is None:
        return None
    if weights.shape != shape:
        raise InvalidGeometryError(f"{name} must have shape {shape}, got {weights.shape}")
    if not np.all(np.isfinite(weights)) or np.any(weights <= 0):
        raise InvalidGeometryError(f"{name} must be finite and > 0")
    return weights


def check_offset(offset: ArrayLike, dimension: int) -> NDArray:
    """A translation as ``(dimension,)`` finite floats, or InvalidGeometryError."""
    out = np.asarray(offset, dtype=float)
    if out.shape != (dimension,) or not np.all(np.isfinite(out)):
        raise InvalidGeometryError(
            f"offset must be {dimension} finite numbers, got {np.asarray(offset)!r}")
    return out


def find_span(knots: NDArray, degree: int, t: ArrayLike) -> NDArray:
    """Index ``i`` of the knot span ``knots[i] <= t < knots[i + 1]`` for every ``t``.

    Parameters outside the domain ``[knots[degree], knots[n]]`` are assigned to
    the first or last non-empty span (the polynomial piece is extended), and the
    domain's right end belongs to the last non-empty span (A2.1 of [PT]).

    Returns
    -------
    (...) int, same shape as ``t``; values in ``[degree, n - 1]``.
    """
    t = np.asarray(t, dtype=float)
    span = np.searchsorted(knots, t, side="right") - 1
    first, last = span_range(knots, degree)
    return np.minimum(np.maximum(span, first), last)      # np.clip costs ~5 us a call


def span_range(knots: NDArray, degree: int) -> tuple[int, int]:
    """``(first, last)``: the indices of the first and the last non-empty knot span
    (``knots[i] < knots[i + 1]``, ``degree <= i <= n - 1``), where :func:`find_span`
    puts parameters before and after the domain."""
    last = knots.size - degree - 2
    while knots[last] == knots[last + 1]:
        last -= 1
    first = degree
    while knots[first] == knots[first + 1]:
        first += 1
    return first, last


def basis_functions(knots: NDArray, degree: int, t: ArrayLike,
                    span: NDArray | None = None) -> tuple[NDArray, NDArray]:
    """Non-zero basis functions ``N[span - degree + j](t)``, ``j = 0..degree`` (A2.2).

    Returns
    -------
    span : (m,) int
    values : (m, degree + 1) float
    """
    ders, span = basis_derivatives(knots, degree, t, 0, span)
    return span, ders[:, 0, :]


def basis_derivatives(knots: NDArray, degree: int, t: ArrayLike, order: int,
                      span: NDArray | None = None, *, compiled: bool = True
                      ) -> tuple[NDArray, NDArray]:
    """Basis functions and their derivatives up to ``order`` (A2.3 of [PT]), vectorized.

    Parameters
    ----------
    knots : (n + degree + 1,) float
    degree : int
    t : array_like, flattened to (m,)
    order : int >= 0
        Derivatives above ``degree`` are zero.
    span : (m,) int, optional
        Precomputed :func:`find_span` result.
    compiled : bool, default True
        Use the compiled kernel (a few microseconds a call). False runs the numpy
        form, vectorized over all of ``t`` (tens of microseconds a call, whatever
        ``m``): what a tensor grid's two per-direction calls want, since compiling
        buys them nothing and the first compiled call in a process loads numba
        (about half a second). Both run the same recurrences.

    Returns
    -------
    ders : (m, order + 1, degree + 1) float
        ``ders[i, k, j]`` is the k-th derivative of basis function
        ``span[i] - degree + j`` at ``t[i]``.
    span : (m,) int
    """
    p = int(degree)
    t = np.asarray(t, dtype=float).reshape(-1)
    if span is None:
        span = find_span(knots, p, t)
    if compiled and worth_compiling(t.size * (p + 1) * (int(order) + 1)):   # same recurrences, compiled
        return basis_kernels.basis_derivatives_compiled(knots, p, t, span,
                                                        max(int(order), 0)), span
    return _basis_derivatives_numpy(knots, p, t, order, span), span


def _basis_derivatives_numpy(knots: NDArray, p: int, t: NDArray, order: int,
                             span: NDArray) -> NDArray:
    """The numpy form of :func:`basis_derivatives`: ``(m, order + 1, p + 1)``."""
    top = min(max(int(order), 0), p)
    ndu = _basis_triangle(knots, p, t, span)                 # (p+1, p+1, m)
    ders = np.zeros((max(int(order), 0) + 1, p + 1, t.size))
    ders[0] = ndu[:, p]
    if top > 0:
        ders[1:top + 1] = _derivative_rows(ndu, p, top)
    return np.ascontiguousarray(ders.transpose(2, 0, 1))


def _basis_triangle(knots: NDArray, p: int, t: NDArray, span: NDArray) -> NDArray:
    """The ``ndu`` table of A2.3 with the point axis last (contiguous sweeps).

    ``ndu[r, c]`` for ``c >= r`` holds basis values of degree ``c``;
    ``ndu[c, r]`` for ``c > r`` the knot differences ``right + left``.
    """
    j = np.arange(1, p + 1)[:, None]
    left = t[None, :] - knots[span[None, :] + 1 - j]          # (p, m): left[j-1] = t - t_{span+1-j}
    right = knots[span[None, :] + j] - t[None, :]             # (p, m): right[j-1] = t_{span+j} - t
    ndu = np.empty((p + 1, p + 1, t.size))
    ndu[0, 0] = 1.0
    with np.errstate(divide="ignore", invalid="ignore"):     # entered once, not per term
        for jj in range(1, p + 1):                           # the r loop of A2.2 at once
            r = np.arange(jj)
            ndu[jj, :jj] = right[:jj] + left[jj - 1 - r]
            den = ndu[jj, :jj]
            temp = np.where(den != 0.0, ndu[:jj, jj - 1] / den, 0.0)   # (jj, m)
            saved = left[jj - 1 - r] * temp                  # saved after step r
            ndu[0, jj] = right[0] * temp[0]
            ndu[1:jj, jj] = saved[:-1] + right[1:jj] * temp[1:]
            ndu[jj, jj] = saved[-1]
    return ndu


def _derivative_rows(ndu: NDArray, p: int, top: int) -> NDArray:
    """Derivatives 1..top of the p+1 non-zero basis functions (second half of A2.3).

    Returns
    -------
    (top, p + 1, m) float
    """
    m = ndu.shape[2]
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_ndu = np.where(ndu != 0.0, 1.0 / ndu, 0.0)
    out = np.zeros((top, p + 1, m))
    for r in range(p + 1):
        a = np.zeros((2, p + 1, m))
        s1, s2 = 0, 1
        a[0, 0] = 1.0
        for k in range(1, top + 1):
            d = np.zeros(m)
            rk, pk = r - k, p - k
            if r >= k:
                a[s2, 0] = a[s1, 0] * inv_ndu[pk + 1, rk]
                d = a[s2, 0] * ndu[rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for jj in range(j1, j2 + 1):
                a[s2, jj] = (a[s1, jj] - a[s1, jj - 1]) * inv_ndu[pk + 1, rk + jj]
                d += a[s2, jj] * ndu[rk + jj, pk]
            if r <= pk:
                a[s2, k] = -a[s1, k - 1] * inv_ndu[pk + 1, r]
                d += a[s2, k] * ndu[r, pk]
            out[k - 1, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, top + 1):
        out[k - 1] *= factor
        factor *= p - k
    return out


def collocation_matrix(knots: NDArray, degree: int, t: ArrayLike, order: int = 0) -> NDArray:
    """Dense matrix ``B[i, j] = N_j^{(order)}(t[i])`` of all ``n`` basis functions.

    Returns
    -------
    (m, n) float
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    n = knots.size - degree - 1
    ders, span = basis_derivatives(knots, degree, t, order)
    out = np.zeros((t.size, n))
    cols = span[:, None] - degree + np.arange(degree + 1)
    np.put_along_axis(out, cols, ders[:, order, :], axis=1)
    return out


def greville_abscissae(knots: NDArray, degree: int) -> NDArray:
    """Greville abscissae ``(t[i+1] + ... + t[i+degree]) / degree``, one per control point.

    Returns
    -------
    (n,) float
    """
    n = knots.size - degree - 1
    c = np.concatenate([[0.0], np.cumsum(knots)])
    i = np.arange(n)
    return (c[i + degree + 1] - c[i + 1]) / degree


def distinct_knots(knots: NDArray, degree: int) -> tuple[NDArray, NDArray]:
    """Breakpoints of the domain and their multiplicities.

    Returns
    -------
    values : (k,) float
        Distinct knot values inside ``[knots[degree], knots[n]]``.
    multiplicities : (k,) int
        Multiplicity of each value in the full knot vector.
    """
    n = knots.size - degree - 1
    lo, hi = knots[degree], knots[n]
    values, counts = np.unique(knots, return_counts=True)
    keep = (values >= lo) & (values <= hi)
    return values[keep], counts[keep]
