"""Closest points on NURBS surfaces (point inversion, section 6.1 of [PT]), vectorized.

The method is described in :mod:`surfprep.algorithms.projection`; the shared
seeds and Newton iteration are in :mod:`.newton`. Here: the surface's local
derivatives (``S``, ``[S_u, S_v]``, the second derivatives: eqs. 6.6-6.7), its
seed grid, and the public functions.

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   section 6.1 (point inversion and projection, eqs. 6.3-6.8).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..creases import CreasePieces
from ..surface import NurbsSurface
from .newton import (
    MIN_SAMPLES,
    best_per_query,
    check_count,
    check_points,
    equidistributed,
    pick_seeds,
    projection_tolerance,
    sample_counts,
    seed_grid,
    solve,
    span_extents,
    span_samples,
)

__all__ = ["NONUNIFORM", "ProjectionResult", "distance_to_surface", "project_to_surface"]

#: a sample grid whose longest cell leg is this many times the median gets seeds from a
#: second grid spread by chord length added (:func:`_surface_seeds`)
NONUNIFORM = 8.0


@dataclass(frozen=True)
class ProjectionResult:
    """Closest points on a surface.

    Attributes
    ----------
    uv : (..., 2) float
        Parameters of the foot points, inside the domain.
    points : (..., 3) float
        Foot points ``S(uv)``.
    distance : (...) float
        ``|P - S(uv)|``.
    converged : (...) bool
        The convergence test passed (False: iteration limit or no descent
        before the test passed; the result is still the best point found).
    """

    uv: NDArray
    points: NDArray
    distance: NDArray
    converged: NDArray


# ------------------------------------------------------------------ surfaces
def _surface_local(surface: NurbsSurface) -> tuple[Callable, Callable]:
    def local(x):
        d = surface.derivatives(x[:, 0], x[:, 1], 2)
        jac = np.stack([d[:, 1, 0], d[:, 0, 1]], axis=2)
        hess = np.stack([np.stack([d[:, 2, 0], d[:, 1, 1]], axis=2),
                         np.stack([d[:, 1, 1], d[:, 0, 2]], axis=2)], axis=3)
        return d[:, 0, 0], jac, hess

    def value(x):
        return surface.evaluate(x[:, 0], x[:, 1])

    return local, value


def project_to_surface(surface: NurbsSurface, points: ArrayLike, *, tol: float | None = None,
                       max_iter: int = 30, n_seeds: int = 3,
                       samples_per_span: int | None = None,
                       guess: ArrayLike | None = None) -> ProjectionResult:
    """Closest points of a surface to many points (point inversion, section 6.1 of [PT]).

    Parameters
    ----------
    surface : NurbsSurface
    points : (..., 3) float
    tol : float, optional
        Model units: convergence of the 3D step and of the tangential residual
        (eq. 6.8). Default :data:`DEFAULT_RELATIVE_TOL` times the control-net
        bounding-box diagonal.
    max_iter : int
        Newton iterations per seed.
    n_seeds : int
        Seeds per point from the sample grid (nearest sample plus non-adjacent
        ones); 1 is fastest, more guard against wrong local minima.
    samples_per_span : int, optional
        Grid samples per knot span and direction. Default: at least
        ``max(256, 2 (degree + 1) spans)`` per direction, shared among the spans
        in proportion to the length of their control polygon (at least
        ``degree + 1`` each), fewer when the grid would exceed 200 000 samples.
    guess : (..., 2) float, optional
        Start parameters instead of the sample grid (a local projection, for
        marching methods that know where the foot is).

    Returns
    -------
    ProjectionResult
        ``uv (..., 2)``, ``points (..., 3)``, ``distance (...)``, ``converged (...)``.
    """
    p = check_points(points, surface.dimension)
    shape = p.shape[:-1]
    targets = p.reshape(-1, surface.dimension)
    tol = projection_tolerance(tol, surface)
    max_iter = check_count(max_iter, "max_iter", 1)
    n_seeds = check_count(n_seeds, "n_seeds", 1)
    u0, u1, v0, v1 = surface.domain
    lo, hi = np.array([u0, v0]), np.array([u1, v1])
    pieces = CreasePieces([surface.knots_u, surface.knots_v], [surface.degree_u, surface.degree_v])
    if guess is not None:
        x0 = np.asarray(guess, dtype=float)
        if x0.shape != shape + (2,) or not np.all(np.isfinite(x0)):
            raise InvalidGeometryError(f"guess must be finite of shape {shape + (2,)}, "
                                       f"got {x0.shape}")
        rows = np.arange(targets.shape[0])
        x0 = np.clip(x0.reshape(-1, 2), lo, hi)
    else:
        rows, x0 = _surface_seeds(surface, targets, n_seeds, samples_per_span, pieces)
    local, value = _surface_local(surface)
    rows, x0 = pieces.split_seeds(rows, x0)
    x, foot, distance, converged = solve(local, value, targets[rows], x0, pieces, tol, max_iter)
    best = best_per_query(rows, distance)
    return ProjectionResult(uv=x[best].reshape(shape + (2,)),
                            points=foot[best].reshape(shape + (surface.dimension,)),
                            distance=distance[best].reshape(shape),
                            converged=converged[best].reshape(shape))


def _surface_seeds(surface: NurbsSurface, targets: NDArray, n_seeds: int,
                   samples_per_span: int | None, pieces: CreasePieces) -> tuple[NDArray, NDArray]:
    """Newton starts ``(rows, uv)`` from the sample grid (samples even in the parameter
    within each span, spans shared by control-polygon extent). A rational surface can
    cross most of a span in a sliver of its parameters (large weight ratios): there
    the grid's cells are as long as the model and a basin can be missed, so when the
    grid's longest cell leg is :data:`NONUNIFORM` times its median, seeds from a
    second grid spread by chord length are added (every start is solved and the best
    foot per point kept, so the first grid's answers can only improve)."""
    def build():
        net = surface.control_points
        extents = [span_extents(net, surface.knots_u, surface.degree_u),
                   span_extents(np.swapaxes(net, 0, 1), surface.knots_v, surface.degree_v)]
        per_u, per_v = sample_counts(extents, [surface.degree_u, surface.degree_v],
                                      samples_per_span, MIN_SAMPLES)
        su = span_samples(surface.knots_u, surface.degree_u, per_u)
        sv = span_samples(surface.knots_v, surface.degree_v, per_v)
        return ((su, sv), surface.evaluate_grid(su, sv),
                [pieces.axis_index(0, su), pieces.axis_index(1, sv)])

    seeds = seed_grid(surface, ("surface", samples_per_span), build)
    rows, uv = _picked(seeds, targets, n_seeds)
    su, sv = seeds.params
    chords = (np.linalg.norm(np.diff(seeds.grid, axis=0), axis=-1).max(axis=1),
              np.linalg.norm(np.diff(seeds.grid, axis=1), axis=-1).max(axis=0))
    if not any(c.size and c.max() > NONUNIFORM * np.median(c) for c in chords):
        return rows, uv

    def spread():
        cu = equidistributed(su, chords[0], surface.knots_u, surface.degree_u)
        cv = equidistributed(sv, chords[1], surface.knots_v, surface.degree_v)
        return ((cu, cv), surface.evaluate_grid(cu, cv),
                [pieces.axis_index(0, cu), pieces.axis_index(1, cv)])

    more_rows, more_uv = _picked(seed_grid(surface, ("surface by chord", samples_per_span),
                                           spread), targets, n_seeds)
    return np.concatenate([rows, more_rows]), np.concatenate([uv, more_uv])


def _picked(seeds, targets: NDArray, n_seeds: int) -> tuple[NDArray, NDArray]:
    su, sv = seeds.params
    rows, sample = pick_seeds(seeds, targets, n_seeds)
    iu, iv = np.unravel_index(sample, (su.size, sv.size))
    return rows, np.stack([su[iu], sv[iv]], axis=1)


def distance_to_surface(surface: NurbsSurface, points: ArrayLike, *,
                        tol: float | None = None) -> NDArray:
    """Distances ``(...)`` from ``points (..., 3)`` to the surface (:func:`project_to_surface`).

    The dense check of later features: sample a result, measure its distance
    to the surface it must lie on, compare with the tolerance.
    """
    return project_to_surface(surface, points, tol=tol).distance
