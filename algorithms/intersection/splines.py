"""Many cubic interpolants at once: one banded solve, one compiled evaluation (the
interpolants of the intersection curves of 000 §29.4).

The sampling rounds of :mod:`.sampling` interpolate every unfinished curve
(:func:`.interpolants.interpolate_samples`: the C2 cubic of
:func:`fitting.interpolate_curve` on the chord-length parameters, a closed
curve with its C1 closure) and evaluate the interpolants at check points
and in Newton projections. Per curve that is a collocation solve, a validated
:class:`NurbsCurve` and several small evaluations, whose fixed costs dominate
when curves have a few hundred samples. :func:`interpolate_many` builds the same
collocation rows for every curve, stacks them block-diagonally into one banded
system (blocks do not couple, so the solution is each curve's own to rounding)
and keeps the result as flat arrays; :meth:`SplineSet.derivatives` evaluates any
curves at any parameters in one compiled call (A2.3 and A3.2 of The NURBS Book).

Curves with fewer than four samples (degree below 3) are interpolated one by one
(:func:`.interpolants.interpolate_samples`) and stored alongside.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ...errors import DegenerateGeometryError, InvalidGeometryError
from ..basis import basis_derivatives, find_span
from ..basis_kernels import ders_one
from ..curve import NurbsCurve
from ..fitting import averaged_knots, knots_from_breakpoints, seam_tangent, solve_banded_rows
from ..jit import compiled, jit
from .interpolants import interpolate_samples

__all__ = ["SplineSet", "interpolate_many"]


@dataclass(frozen=True, eq=False)
class SplineSet:
    """Non-rational B-spline curves of one dimension as flat arrays.

    Attributes
    ----------
    knots : (K,) float
        All knot vectors, curve after curve (``knots[knot_start[i]:knot_start[i + 1]]``).
    control : (C, d) float
        All control points (``control[control_start[i]:control_start[i + 1]]``).
    degree : (c,) int
    knot_start, control_start : (c + 1,) int
    """

    knots: NDArray
    control: NDArray
    degree: NDArray
    knot_start: NDArray
    control_start: NDArray

    @classmethod
    def of(cls, curves: Sequence[NurbsCurve]) -> SplineSet:
        """The flat arrays of non-rational ``curves`` of one dimension (at least one).

        Raises
        ------
        InvalidGeometryError
            A rational curve, or curves of different dimensions.
        """
        if not curves:
            raise InvalidGeometryError("a SplineSet needs at least one curve")
        if any(c.is_rational for c in curves) or len({c.dimension for c in curves}) != 1:
            raise InvalidGeometryError("a SplineSet holds non-rational curves of one dimension")
        knots = [np.asarray(c.knots, dtype=float) for c in curves]
        control = [np.asarray(c.control_points, dtype=float) for c in curves]
        return cls(np.concatenate(knots), np.concatenate(control),
                   np.array([c.degree for c in curves], dtype=np.int64),
                   np.concatenate([[0], np.cumsum([k.size for k in knots])]).astype(np.int64),
                   np.concatenate([[0], np.cumsum([c.shape[0] for c in control])]
                                  ).astype(np.int64))

    def curve(self, i: int) -> NurbsCurve:
        """Curve ``i`` as a NurbsCurve."""
        k = self.knots[self.knot_start[i]:self.knot_start[i + 1]]
        c = self.control[self.control_start[i]:self.control_start[i + 1]]
        return NurbsCurve.construct_fast(c, k, int(self.degree[i]))

    def derivatives(self, index: NDArray, t: NDArray, order: int = 0) -> NDArray:
        """Derivatives ``(m, order + 1, d)`` of curves ``index (m,)`` at ``t (m,)``."""
        index = np.asarray(index, dtype=np.int64).reshape(-1)
        t = np.asarray(t, dtype=float).reshape(-1)
        if compiled(t.size * 16):
            return _evaluate_many(self.knots, self.knot_start, self.control, self.control_start,
                                  self.degree, index, t, int(order))
        out = np.zeros((t.size, order + 1, self.control.shape[1]))
        for i in np.unique(index):
            at = index == i
            out[at] = self.curve(int(i)).derivatives(t[at], order)
        return out

    def evaluate(self, index: NDArray, t: NDArray) -> NDArray:
        """Points ``(m, d)`` of curves ``index (m,)`` at ``t (m,)``."""
        return self.derivatives(index, t, 0)[:, 0]


@jit
def _evaluate_many(knots, knot_start, control, control_start, degree, index, t, order):
    m, d = t.size, control.shape[1]
    out = np.zeros((m, order + 1, d))
    p = -1
    ndu, a = np.empty((1, 1)), np.zeros((2, 1))
    left, right, ders = np.empty(1), np.empty(1), np.zeros((order + 1, 1))
    for j in range(m):
        c = index[j]
        if degree[c] != p:                  # scratch of this degree (C-contiguous)
            p = degree[c]
            ndu, a = np.empty((p + 1, p + 1)), np.zeros((2, p + 1))
            left, right, ders = np.empty(p + 1), np.empty(p + 1), np.zeros((order + 1, p + 1))
        kn = knots[knot_start[c]:knot_start[c + 1]]
        n = control_start[c + 1] - control_start[c]
        first, last = p, n - 1
        while kn[first] == kn[first + 1]:
            first += 1
        while kn[last] == kn[last + 1]:
            last -= 1
        span = np.searchsorted(kn, t[j], side="right") - 1
        span = min(max(span, first), last)
        ders[:, :] = 0.0
        ders_one(kn, p, t[j], span, min(order, p), ndu, a, left, right, ders)
        base = control_start[c] + span - p
        for k in range(order + 1):
            for e in range(d):
                s = 0.0
                for r in range(p + 1):
                    s += ders[k, r] * control[base + r, e]
                out[j, k, e] = s
    return out


def _rows(q: NDArray, t: NDArray, closed: bool) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Collocation rows of one cubic interpolant (as :func:`fitting.interpolate_curve`
    builds them): ``cols, values (N, 4)``, ``rhs (N, d)`` and the knots."""
    if closed:                  # C1 closure: D_0 = D_{n-1}, the seam tangent (eqs. 9.19-9.21)
        tangent = seam_tangent(q, t)
        knots = knots_from_breakpoints(t, 3, end_condition="clamped")
        span = find_span(knots, 3, t)
        values = basis_derivatives(knots, 3, t, 0, span)[0][:, 0]
        ends = t[[0, -1]]
        dspan = find_span(knots, 3, ends)
        dvalues = basis_derivatives(knots, 3, ends, 1, dspan)[0][:, 1]
        n = q.shape[0]
        order = np.concatenate([[0], [n], np.arange(1, n - 1), [n + 1], [n - 1]])
        cols = np.concatenate([span[:, None] - 3 + np.arange(4),
                               dspan[:, None] - 3 + np.arange(4)])[order]
        values = np.concatenate([values, dvalues])[order]
        rhs = np.concatenate([q, np.stack([tangent, tangent])])[order]
        return cols, values, rhs, knots
    knots = averaged_knots(t, 3)
    span = find_span(knots, 3, t)
    values = basis_derivatives(knots, 3, t, 0, span)[0][:, 0]
    return span[:, None] - 3 + np.arange(4), values, q, knots


def interpolate_many(values: Sequence[NDArray], parameters: Sequence[NDArray],
                     closed: Sequence[bool]) -> SplineSet:
    """The interpolants of :func:`.interpolants.interpolate_samples` for many sample sets.

    Parameters
    ----------
    values : sequence of (n_i, d) float
        Samples (a closed one without its first sample repeated); one ``d`` for all.
    parameters : sequence of (n_i,) or (n_i + 1,) float
        Strictly increasing (``+ 1`` when closed).
    closed : sequence of bool

    Returns
    -------
    SplineSet
        Curve ``i`` equal (to rounding) to ``interpolate_samples(values[i],
        parameters[i], closed[i])``.

    Raises
    ------
    InvalidGeometryError
        A parameter count that does not match the samples.
    DegenerateGeometryError
        Parameters not strictly increasing, or a singular system.
    """
    cols, vals, rhs, knots, degree, controls = [], [], [], [], [], []
    offset = 0
    for q, t, c in zip(values, parameters, closed):
        t = np.asarray(t, dtype=float)
        if np.any(np.diff(t) <= 0):
            raise DegenerateGeometryError("interpolation needs strictly increasing parameters")
        q = np.vstack([q, q[:1]]) if c else np.asarray(q, dtype=float)
        if t.shape != (q.shape[0],):
            raise InvalidGeometryError(
                f"{q.shape[0]} parameters needed for {len(q) - bool(c)} samples "
                f"({'closed' if c else 'open'}), got {t.shape}")
        if q.shape[0] < 4:          # below cubic: one by one
            curve = interpolate_samples(q[:-1] if c else q, t, c)
            knots.append(curve.knots)
            degree.append(curve.degree)
            controls.append(("own", curve.control_points))
            continue
        col, val, r, k = _rows(q, t, bool(c))
        cols.append(col + offset)
        vals.append(val)
        rhs.append(r)
        knots.append(k)
        degree.append(3)
        controls.append(("solved", (offset, r.shape[0], q[0], q[-1])))
        offset += r.shape[0]
    solved = _solve_blocks(cols, vals, rhs) if cols else None
    control = []
    for kind, item in controls:
        if kind == "own":
            control.append(item)
            continue
        start, size, first, last = item
        block = solved[start:start + size].copy()
        block[0], block[-1] = first, last          # clamped ends interpolate exactly
        control.append(block)
    knot_start = np.concatenate([[0], np.cumsum([k.size for k in knots])]).astype(np.int64)
    control_start = np.concatenate([[0], np.cumsum([c.shape[0] for c in control])]
                                   ).astype(np.int64)
    return SplineSet(np.concatenate(knots), np.concatenate(control),
                     np.asarray(degree, dtype=np.int64), knot_start, control_start)


def _solve_blocks(cols: list[NDArray], values: list[NDArray], rhs: list[NDArray]) -> NDArray:
    """One banded solve of the block-diagonal system of all curves' rows."""
    return solve_banded_rows(np.concatenate(cols), np.concatenate(values), np.concatenate(rhs))
