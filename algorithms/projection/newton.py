"""The machinery shared by the closest-point projections onto surfaces and curves.

Steps 1-4 of :mod:`surfprep.algorithms.projection` (its docstring walks the
method): the sample grid of a surface or curve cached on the instance
(:func:`seed_grid`, sample counts by control-polygon extent per knot span:
:func:`span_extents`, :func:`sample_counts`, :func:`span_samples`), the seeds
among its samples (:func:`pick_seeds`), Newton held at the domain's bounds for
all (point, seed) problems at once (:func:`solve`: the Hessian shifted to be
positive definite, halving line search, the convergence tests of eq. 6.8 of
[PT], crease pieces crossed), and the best result per query
(:func:`best_per_query`). :mod:`.onto_surface` and :mod:`.onto_curve` give it
the local derivatives of their geometry.

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   section 6.1 (point inversion and projection, eqs. 6.3-6.8).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..basis import distinct_knots
from ..creases import CreasePieces
from ..tolerance import check_tolerance

if TYPE_CHECKING:
    from scipy.spatial import cKDTree

__all__ = [
    "DEFAULT_RELATIVE_TOL",
    "MIN_SAMPLES",
    "SeedGrid",
    "best_per_query",
    "check_count",
    "check_points",
    "equidistributed",
    "pick_seeds",
    "projection_tolerance",
    "sample_counts",
    "seed_grid",
    "solve",
    "span_extents",
    "span_samples",
]

DEFAULT_RELATIVE_TOL = 1e-10
_MAX_HALVINGS = 30
_SAMPLE_BUDGET = 200_000
_CANDIDATES = 24
#: queries of at least this many points use every core for the k-d tree
_THREADED_QUERY = 5000
_MAX_CROSSINGS = 8
#: a foot this share of its piece's width from a crease is sought across it too
_CREASE_REACH = 0.02
MIN_SAMPLES = 256      # grid intervals per surface direction, at least


# ----------------------------------------------------------------- validation
def check_points(points: ArrayLike, dimension: int) -> NDArray:
    p = np.asarray(points, dtype=float)
    if p.ndim < 1 or p.shape[-1] != dimension:
        raise InvalidGeometryError(
            f"points must have shape (..., {dimension}), got {p.shape}")
    if not np.all(np.isfinite(p)):
        raise InvalidGeometryError("points contain NaN or infinite values")
    return p


def projection_tolerance(tol: float | None, geometry) -> float:
    box = geometry.bounding_box()
    diagonal = float(np.linalg.norm(box[1] - box[0]))
    if tol is None:
        return DEFAULT_RELATIVE_TOL * max(diagonal, np.finfo(float).tiny)
    return check_tolerance(tol)


def check_count(value: int, name: str, minimum: int) -> int:
    if isinstance(value, bool) or int(value) != value or value < minimum:
        raise InvalidGeometryError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


# -------------------------------------------------------------------- seeds
def span_samples(knots: NDArray, degree: int, counts: NDArray) -> NDArray:
    """``counts[i]`` equal steps in the i-th non-empty knot span of the domain: (s,) float."""
    breaks, _ = distinct_knots(knots, degree)
    span = np.repeat(np.arange(counts.size), counts)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    frac = (np.arange(span.size) - start[span]) / counts[span]
    inner = breaks[span] + np.diff(breaks)[span] * frac
    return np.concatenate([inner, breaks[-1:]])


#: share of the parameter in the equidistributed sample spacing (the rest chord length)
_PARAMETER_SHARE = 0.25


def equidistributed(params: NDArray, chords: NDArray, knots: NDArray, degree: int) -> NDArray:
    """As many samples as ``params (s,)`` spread evenly in a blend of chord length
    (``chords (s - 1,)``, the longest leg of each interval over the other direction)
    and parameter (:data:`_PARAMETER_SHARE`), the knots of the domain kept among
    them (creases lie there): (s',) float, increasing."""
    lo, hi = params[0], params[-1]
    total = chords.sum()
    if total <= 0 or hi <= lo:
        return params
    measure = (1 - _PARAMETER_SHARE) * np.concatenate([[0.0], np.cumsum(chords)]) / total \
        + _PARAMETER_SHARE * (params - lo) / (hi - lo)
    spread = np.interp(np.linspace(0.0, 1.0, params.size), measure, params)
    breaks, _ = distinct_knots(knots, degree)
    return np.unique(np.concatenate([spread, breaks]))


def span_extents(net: NDArray, knots: NDArray, degree: int) -> NDArray:
    """Length of the control polygon over each non-empty knot span, along axis 0 of
    ``net (n, ..., d)`` (the longest over the other axes, leg by leg): (S,) float."""
    n = net.shape[0]
    legs = np.linalg.norm(np.diff(net, axis=0), axis=-1).reshape(n - 1, -1).max(axis=1)
    cumulative = np.concatenate([[0.0], np.cumsum(legs)])
    spans = np.flatnonzero(knots[degree:n] < knots[degree + 1:n + 1]) + degree
    return cumulative[spans] - cumulative[spans - degree]


def _span_counts(extents: NDArray, degree: int, total: int) -> NDArray:
    """About ``total`` samples shared among the spans in proportion to their extent,
    at least ``degree + 1`` per span: (S,) int."""
    weight = extents / extents.sum() if extents.sum() > 0 else np.full(extents.size,
                                                                       1 / extents.size)
    return np.maximum(degree + 1, np.ceil(total * weight)).astype(int)


def sample_counts(extents: list[NDArray], degrees: list[int], per_span: int | None,
                   minimum: int, density: int = 2) -> list[NDArray]:
    """Samples per span and direction: ``per_span`` everywhere when given, else at least
    ``max(minimum, density (degree + 1) spans)`` per direction shared by control-polygon
    extent, reduced until the grid fits :data:`_SAMPLE_BUDGET`."""
    if per_span is not None:
        per_span = check_count(per_span, "samples_per_span", 1)
        return [np.full(e.size, per_span) for e in extents]
    totals = [max(minimum, density * (p + 1) * e.size) for e, p in zip(extents, degrees)]
    while True:
        counts = [_span_counts(e, p, t) for e, p, t in zip(extents, degrees, totals)]
        size = np.prod([c.sum() + 1 for c in counts])
        if size <= _SAMPLE_BUDGET or max(totals) <= 2:
            return counts
        i = int(np.argmax(totals))
        totals[i] = max(2, int(totals[i] * 0.7))


def _grid_spacing(grid: NDArray) -> float:
    """Longest edge or diagonal of a sample grid ``(a, [b,] d)`` cell: every point of
    the surface lies within this distance of some sample."""
    if grid.ndim == 2:
        return float(np.linalg.norm(np.diff(grid, axis=0), axis=-1).max(initial=0.0))
    steps = [grid[1:, :] - grid[:-1, :], grid[:, 1:] - grid[:, :-1],
             grid[1:, 1:] - grid[:-1, :-1], grid[1:, :-1] - grid[:-1, 1:]]
    return max(float(np.linalg.norm(s, axis=-1).max(initial=0.0)) for s in steps)


@dataclass(frozen=True, eq=False)
class SeedGrid:
    """The sample grid of a surface or curve for :func:`pick_seeds`, built once per
    geometry and sampling (:func:`seed_grid`): parameters per axis, the grid
    ``(a, [b,] d)``, its k-d tree, crease pieces per axis and :func:`_grid_spacing`."""

    params: tuple[NDArray, ...]
    grid: NDArray
    tree: cKDTree
    pieces: list[NDArray]
    spacing: float


#: attribute of a NurbsSurface / NurbsCurve instance holding its seed grids
_SEED_CACHE = "_projection_seed_grids"


def seed_grid(geometry, key, build: Callable[[], tuple[tuple[NDArray, ...], NDArray,
                                                      list[NDArray]]]) -> SeedGrid:
    """The :class:`SeedGrid` of ``geometry`` for sampling ``key``, cached on the
    instance (geometry is immutable, so its grid never goes stale; the cache lives
    in the instance ``__dict__`` as a ``functools.cached_property`` would, and dies
    with it). ``build()`` gives ``(params, grid, pieces)``."""
    cache = geometry.__dict__.get(_SEED_CACHE)
    if cache is None:
        cache = {}
        geometry.__dict__[_SEED_CACHE] = cache
    found = cache.get(key)
    if found is None:
        params, grid, pieces = build()
        for a in (*params, grid):
            a.setflags(write=False)
        # scipy on first use: importing it costs 0.3 s
        from scipy.spatial import cKDTree

        found = SeedGrid(params, grid, cKDTree(grid.reshape(-1, grid.shape[-1])), pieces,
                          _grid_spacing(grid))
        cache[key] = found
    return found


def pick_seeds(seeds: SeedGrid, points: NDArray, n_seeds: int) -> tuple[NDArray, NDArray]:
    """(query, sample) pairs for the Newton starts.

    The nearest sample (distance ``d0``) is always a seed. Any basin whose minimum
    is closer than ``d0`` holds a sample within ``d0 + h`` (``h`` the longest
    grid cell edge or diagonal), so up to ``n_seeds - 1`` more seeds are taken
    among the samples within that radius (of the ``_CANDIDATES`` nearest) that
    are local minima of the distance on the grid (no grid neighbour in the
    same crease-free piece closer) and not grid neighbours of the nearest
    sample, closest first.

    Parameters
    ----------
    seeds : SeedGrid
        Samples on a 1D or 2D parameter grid ``(a, [b,] d)`` with their tree and
        crease-free piece along each axis ((a,) and (b,) int).

    Returns
    -------
    rows : (s,) int, every query at least once
    sample : (s,) int, flat index into the grid
    """
    grid, pieces = seeds.grid, seeds.pieces
    shape = grid.shape[:-1]
    samples = grid.reshape(-1, grid.shape[-1])
    k = min(_CANDIDATES, samples.shape[0])
    # threads only pay for a large query: starting them costs more than 100 points
    # take (4.4 ms against 0.16 ms; break-even near 5000 points here)
    workers = -1 if points.shape[0] >= _THREADED_QUERY else 1
    dist, nearest = seeds.tree.query(points, k=k, workers=workers)
    dist, nearest = dist.reshape(points.shape[0], k), nearest.reshape(points.shape[0], k)
    if n_seeds == 1 or k == 1:
        return np.arange(points.shape[0]), nearest[:, 0]
    index = np.stack(np.unravel_index(nearest, shape), axis=-1)          # (m, k, dims)
    candidate = (np.abs(index - index[:, :1]).max(axis=2) > 1) \
        & (dist <= dist[:, :1] + seeds.spacing)
    offsets = np.array(list(itertools.product((-1, 0, 1), repeat=len(shape))))
    rows, cols = np.nonzero(candidate)
    for part in np.array_split(np.arange(rows.size), 1 + rows.size // 50_000):
        r, c = rows[part], cols[part]
        around = np.clip(index[r, c, None, :] + offsets, 0, np.array(shape) - 1)
        flat = np.ravel_multi_index(tuple(np.moveaxis(around, -1, 0)), shape)
        near = np.linalg.norm(samples[flat] - points[r, None, :], axis=-1)
        for i, piece in enumerate(pieces):     # neighbours across a crease do not count
            near[piece[around[..., i]] != piece[index[r, c, i]][:, None]] = np.inf
        near = near.min(axis=1)
        here = np.linalg.norm(samples[nearest[r, c]] - points[r], axis=-1)
        candidate[r, c] = here <= near
    candidate[:, 0] = True
    keep = candidate & (np.cumsum(candidate, axis=1) <= n_seeds)
    rows, cols = np.nonzero(keep)
    return rows, nearest[rows, cols]


def best_per_query(rows: NDArray, distance: NDArray) -> NDArray:
    """Index of the smallest distance among the candidates of each query (rows sorted)."""
    if rows.size == 0:
        return rows
    order = np.lexsort((distance, rows))
    first = np.r_[True, rows[order][1:] != rows[order][:-1]]
    return order[first]


# ----------------------------------------------------------------- Newton
def _solve_small(a: NDArray, b: NDArray) -> NDArray:
    """Solve ``a x = b`` for batches of 1x1 or 2x2 systems; a zero determinant gives 0."""
    if a.shape[-1] == 1:
        d = a[:, 0, 0]
        return np.where(d != 0, b[:, 0] / np.where(d != 0, d, 1.0), 0.0)[:, None]
    det = a[:, 0, 0] * a[:, 1, 1] - a[:, 0, 1] * a[:, 1, 0]
    safe = np.where(det != 0, det, 1.0)
    x0 = (a[:, 1, 1] * b[:, 0] - a[:, 0, 1] * b[:, 1]) / safe
    x1 = (a[:, 0, 0] * b[:, 1] - a[:, 1, 0] * b[:, 0]) / safe
    return np.where((det != 0)[:, None], np.stack([x0, x1], axis=1), 0.0)


def _smallest_eigenvalue(a: NDArray) -> NDArray:
    """Smallest eigenvalue of batches of symmetric 1x1 or 2x2 matrices: (m,) float."""
    if a.shape[-1] == 1:
        return a[:, 0, 0]
    half_trace = 0.5 * (a[:, 0, 0] + a[:, 1, 1])
    return half_trace - np.hypot(0.5 * (a[:, 0, 0] - a[:, 1, 1]), a[:, 0, 1])


def _newton_step(hessian: NDArray, gauss_newton: NDArray, gradient: NDArray,
                 free: NDArray) -> NDArray:
    """Step of the free parameters (fixed ones: 0).

    Newton's step when the Hessian restricted to the free parameters is
    positive definite; otherwise the Hessian shifted by ``2 |lambda_min|``
    (plus a little of ``trace(J^T J)``), which is positive definite, so the
    step descends and follows negative curvature out of saddle regions.
    """
    k = gradient.shape[1]
    both = free[:, :, None] & free[:, None, :]
    matrix = np.where(both, hessian, 0.0) + np.eye(k) * (~free)[:, :, None]
    scale = np.trace(gauss_newton, axis1=1, axis2=2) + np.finfo(float).tiny
    lowest = _smallest_eigenvalue(matrix)
    shift = np.where(lowest > 1e-12 * scale, 0.0, 2 * np.abs(lowest) + 1e-8 * scale)
    return _solve_small(matrix + shift[:, None, None] * np.eye(k),
                        -np.where(free, gradient, 0.0))


def _line_search(value: Callable, x: NDArray, step: NDArray, targets: NDArray, start: NDArray,
                 distance: NDArray, lo: NDArray, hi: NDArray):
    """Step halving: the first ``clip(x + step / 2^j)`` not farther from the target.

    Returns the new parameters, points and distances, and which problems found a step.
    """
    x_new, s_new, d_new = x.copy(), start.copy(), distance.copy()
    accepted = np.zeros(x.shape[0], dtype=bool)
    slack = 8 * np.finfo(float).eps * (np.abs(targets).max(axis=1) + distance)
    todo = np.arange(x.shape[0])
    factor = 1.0
    for _ in range(_MAX_HALVINGS):
        candidate = np.clip(x[todo] + factor * step[todo], lo[todo], hi[todo])
        s = value(candidate)
        d = np.linalg.norm(s - targets[todo], axis=1)
        ok = d <= distance[todo] + slack[todo]
        good = todo[ok]
        x_new[good], s_new[good], d_new[good], accepted[good] = candidate[ok], s[ok], d[ok], True
        todo = todo[~ok]
        if todo.size == 0:
            break
        factor *= 0.5
    return x_new, s_new, d_new, accepted


def _minimize(local: Callable, value: Callable, targets: NDArray, x0: NDArray, lo: NDArray,
              hi: NDArray, tol: float, max_iter: int):
    """Bounded Newton minimization of ``|F(x) - target|`` for every row (see module docs).

    ``local(x)`` gives ``F (m, d)``, ``J (m, d, k)``, ``H (m, d, k, k)``; ``value(x)`` gives F.
    ``lo``, ``hi`` (m, k): the box of each problem.

    Returns
    -------
    x (m, k), points (m, d), distance (m,), converged (m,) bool
    """
    x = x0.copy()
    points = value(x)
    distance = np.linalg.norm(points - targets, axis=1)
    converged = np.zeros(x.shape[0], dtype=bool)
    active = np.arange(x.shape[0])
    for _ in range(max_iter):
        if active.size == 0:
            break
        xa, pa, la, ha = x[active], targets[active], lo[active], hi[active]
        f, jac, hess = local(xa)
        r = f - pa
        gradient = np.einsum("md,mdk->mk", r, jac)                   # eq. 6.6
        gauss_newton = np.einsum("mdk,mdl->mkl", jac, jac)
        hessian = gauss_newton + np.einsum("md,mdkl->mkl", r, hess)  # eq. 6.7
        free = ~(((xa <= la) & (gradient > 0)) | ((xa >= ha) & (gradient < 0)))
        speed = np.linalg.norm(jac, axis=1)
        tangential = np.where(free & (speed > 0),
                              np.abs(gradient) / np.where(speed > 0, speed, 1.0), 0.0)
        passed = (tangential.max(axis=1) <= tol) | (np.linalg.norm(r, axis=1) <= tol)  # eq. 6.8
        step = _newton_step(hessian, gauss_newton, gradient, free)
        x_new, f_new, d_new, accepted = _line_search(value, xa, step, pa, f, distance[active],
                                                     la, ha)
        small = accepted & (np.linalg.norm(f_new - f, axis=1) <= tol)
        x[active], points[active], distance[active] = x_new, f_new, d_new
        converged[active] = passed | small
        active = active[~(passed | small | ~accepted)]
    return x, points, distance, converged


# ------------------------------------------------------------------- creases
def solve(local: Callable, value: Callable, targets: NDArray, x0: NDArray, pieces: CreasePieces,
           tol: float, max_iter: int):
    """:func:`_minimize` piece by piece: a problem that ends on a crease with descent
    beyond it continues in the neighbouring piece (up to ``_MAX_CROSSINGS`` times)."""
    piece = pieces.index(x0)
    x, points, distance, converged = _minimize(local, value, targets, x0, *pieces.bounds(piece),
                                               tol, max_iter)
    todo = np.arange(x.shape[0])
    for _ in range(_MAX_CROSSINGS):
        cross, moved, start = pieces.crossings(local, x[todo], targets[todo], piece[todo])
        todo, moved, start = todo[cross], moved[cross], start[cross]
        if todo.size == 0:
            break
        xr, pr, dr, cr = _minimize(local, value, targets[todo], start, *pieces.bounds(moved),
                                   tol, max_iter)
        better = dr <= distance[todo]
        todo = todo[better]
        x[todo], points[todo], distance[todo] = xr[better], pr[better], dr[better]
        converged[todo], piece[todo] = cr[better], moved[better]
    # a foot in a valley just beside a crease may hide a lower one just across it
    # (the seeds' grid can miss that basin): started from the crease's other side too
    todo, moved, start = pieces.beside(x, piece, _CREASE_REACH)
    if todo.size:
        xr, pr, dr, cr = _minimize(local, value, targets[todo], start, *pieces.bounds(moved),
                                   tol, max_iter)
        better = dr < distance[todo]
        todo = todo[better]
        x[todo], points[todo], distance[todo] = xr[better], pr[better], dr[better]
        converged[todo] = cr[better]
    return x, points, distance, converged
