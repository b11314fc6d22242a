"""Closest points on NURBS curves (point inversion, eqs. 6.3-6.5 of [PT]), vectorized.

The method is the one of :mod:`surfprep.algorithms.projection` for surfaces (seeds from a sample
k-d tree, vectorized Newton held at the domain ends, candidates across
discontinuities of the derivative) in one parameter; see its docstring.

References
----------
[PT] Piegl & Tiller, *The NURBS Book*, 2nd ed., section 6.1.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..creases import CreasePieces
from ..curve import NurbsCurve
from .newton import (
    MIN_SAMPLES,
    best_per_query,
    check_count,
    check_points,
    pick_seeds,
    projection_tolerance,
    sample_counts,
    seed_grid,
    solve,
    span_extents,
    span_samples,
)

__all__ = ["CurveProjectionResult", "distance_to_curve", "project_to_curve"]


@dataclass(frozen=True)
class CurveProjectionResult:
    """Closest points on a curve: ``t (...)``, ``points (..., d)``, ``distance (...)``,
    ``converged (...)`` as in :class:`ProjectionResult`."""

    t: NDArray
    points: NDArray
    distance: NDArray
    converged: NDArray


def _curve_local(curve: NurbsCurve) -> tuple[Callable, Callable]:
    def local(x):
        d = curve.derivatives(x[:, 0], 2)
        return d[:, 0], d[:, 1, :, None], d[:, 2, :, None, None]

    def value(x):
        return curve.evaluate(x[:, 0])

    return local, value


def project_to_curve(curve: NurbsCurve, points: ArrayLike, *, tol: float | None = None,
                     max_iter: int = 30, n_seeds: int = 3,
                     samples_per_span: int | None = None,
                     guess: ArrayLike | None = None) -> CurveProjectionResult:
    """Closest points of a curve to many points (eqs. 6.3-6.5 of [PT]).

    Parameters
    ----------
    curve : NurbsCurve
    points : (..., d) float, ``d`` the curve's dimension (2 or 3)
    tol, max_iter, n_seeds : as in :func:`project_to_surface`
    samples_per_span : int, optional
        Default: at least ``max(1024, 4 (degree + 1) spans)``, shared as for surfaces.
    guess : (...) float, optional
        Start parameters instead of the samples.

    Returns
    -------
    CurveProjectionResult
        ``t (...)``, ``points (..., d)``, ``distance (...)``, ``converged (...)``.
    """
    p = check_points(points, curve.dimension)
    shape = p.shape[:-1]
    targets = p.reshape(-1, curve.dimension)
    tol = projection_tolerance(tol, curve)
    max_iter = check_count(max_iter, "max_iter", 1)
    n_seeds = check_count(n_seeds, "n_seeds", 1)
    lo, hi = (np.array([x]) for x in curve.domain)
    pieces = CreasePieces([curve.knots], [curve.degree])
    if guess is not None:
        x0 = np.asarray(guess, dtype=float)
        if x0.shape != shape or not np.all(np.isfinite(x0)):
            raise InvalidGeometryError(f"guess must be finite of shape {shape}, got {x0.shape}")
        rows, x0 = np.arange(targets.shape[0]), np.clip(x0.reshape(-1, 1), lo, hi)
    else:
        def build():
            extents = span_extents(curve.control_points, curve.knots, curve.degree)
            (counts,) = sample_counts([extents], [curve.degree], samples_per_span,
                                       4 * MIN_SAMPLES, density=4)
            st = span_samples(curve.knots, curve.degree, counts)
            return (st,), curve.evaluate(st), [pieces.axis_index(0, st)]

        seeds = seed_grid(curve, ("curve", samples_per_span), build)
        rows, sample = pick_seeds(seeds, targets, n_seeds)
        x0 = seeds.params[0][sample][:, None]
    local, value = _curve_local(curve)
    rows, x0 = pieces.split_seeds(rows, x0)
    x, foot, distance, converged = solve(local, value, targets[rows], x0, pieces, tol, max_iter)
    best = best_per_query(rows, distance)
    return CurveProjectionResult(t=x[best, 0].reshape(shape),
                                 points=foot[best].reshape(shape + (curve.dimension,)),
                                 distance=distance[best].reshape(shape),
                                 converged=converged[best].reshape(shape))


def distance_to_curve(curve: NurbsCurve, points: ArrayLike, *,
                      tol: float | None = None) -> NDArray:
    """Distances ``(...)`` from ``points (..., d)`` to the curve (:func:`project_to_curve`)."""
    return project_to_curve(curve, points, tol=tol).distance
