"""Dense error of the approximation, eq. 29.3 (000 §29.2.3), measured both ways.

.. math:: \\max_{i,j} \\; \\min_{k,l} \\| s(u_i, v_j) - r(u_k, v_l) \\| < \\varepsilon  \\qquad (29.3)

``s`` is the original, ``r`` the new surface. Two dense samples are measured
by closest-point projection (:func:`~surfprep.algorithms.projection.project_to_surface`):

* **new on original**: ``r`` at ``per_span x per_span`` points of every
  interpolation cell (so at least that many per knot span, the interpolation
  parameters containing the knots), projected onto ``s`` starting from the
  original parameters interpolated from the relocation grid. A local
  projection can only overestimate the distance, so the figure is safe.
* **original on new** (eq. 29.3 as written): ``s`` at ``per_span x per_span``
  points per knot span of ``s``, and per direction at least
  :data:`MIN_ORIGINAL_SAMPLES` and ``per_span`` per interval of ``r`` (an
  original with one span and a finer ``r`` was sampled too coarsely: 30 %
  of the deviation could lie between the samples), projected onto ``r``
  with seeds.

The first also gives the error along the grid lines ``U = U_i`` (a pure v
interpolation) and ``V = V_j`` (pure u), which tells in which direction a cell
needs another knot.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import RegularGridInterpolator
from scipy.spatial import cKDTree

from ..projection import project_to_surface
from ..surface import NurbsSurface

__all__ = [
    "CHUNK",
    "MIN_ORIGINAL_SAMPLES",
    "DeviationMap",
    "deviation_map",
    "inverse_map",
    "original_on_new",
    "subdivide",
]

#: Points per projection call (memory stays below ~100 MB).
CHUNK = 50_000
#: Plain Newton steps of a foot point from its seed before the general projection.
NEWTON_STEPS = 4
#: A foot point is settled when the next step is below this fraction of the domain: at
#: the foot the distance is stationary, so a foot ``delta`` (in the parameters) off
#: the true one overestimates the distance by about ``(delta L)^2 / (2 R)`` (``L`` the
#: surface's size, ``R`` its smallest radius of curvature) -- 4e-11 mm on the 63.5 m
#: fuselage for a radius of 5 m -- where a nonzero distance (the fit's own error) makes
#: Gauss-Newton converge linearly and a tighter test sends points to the general
#: projection for nothing.
SETTLED_STEP = 1e-8
#: Samples of the original per direction at least in the eq. 29.3 direction.
MIN_ORIGINAL_SAMPLES = 60


def subdivide(values: NDArray, parts: int) -> NDArray:
    """Every interval of ``values (n,)`` split into ``parts`` equal steps: ``(parts (n-1) + 1,)``."""
    steps = np.linspace(0.0, 1.0, parts + 1)[:-1]
    return np.append((values[:-1, None] + steps * np.diff(values)[:, None]).ravel(), values[-1])


@dataclass(frozen=True)
class DeviationMap:
    """Distances of the new surface from the original on a dense grid of its cells.

    Attributes
    ----------
    distance : (a, b) float
        ``a = per_span (n_u - 1) + 1`` rows over the new u parameters, likewise b.
    per_span : int
    u_errors : (n_u - 1,) float
        Largest distance on the lines ``V = V_j`` inside each u interval.
    v_errors : (n_v - 1,) float
        Largest distance on the lines ``U = U_i`` inside each v interval.
    cell_errors : (n_u - 1, n_v - 1) float
        Largest distance inside each cell.
    """

    distance: NDArray
    per_span: int
    u_errors: NDArray
    v_errors: NDArray
    cell_errors: NDArray

    @property
    def max(self) -> float:
        return float(self.distance.max())


def deviation_map(original: NurbsSurface, new: NurbsSurface, params_u: NDArray,
                  params_v: NDArray, uv: NDArray, per_span: int = 10) -> DeviationMap:
    """Dense distances of ``new`` from ``original`` (see module docstring).

    Parameters
    ----------
    original, new : NurbsSurface
    params_u, params_v : (n_u,), (n_v,) float
        Interpolation parameters of ``new``.
    uv : (n_u, n_v, 2) float
        Original parameters of the interpolation points (start of the projections).
    per_span : int
    """
    gu, gv = subdivide(params_u, per_span), subdivide(params_v, per_span)
    points = new.evaluate_grid(gu, gv)                               # (a, b, 3)
    lookup = RegularGridInterpolator((params_u, params_v), uv)
    mesh = np.stack(np.meshgrid(gu, gv, indexing="ij"), axis=-1)
    guess = lookup(mesh.reshape(-1, 2)).reshape(mesh.shape)
    distance = _chunked(original, points.reshape(-1, 3), guess.reshape(-1, 2))[0]
    distance = distance.reshape(points.shape[:-1])
    nu, nv, p = len(params_u) - 1, len(params_v) - 1, per_span
    on_rows = distance[:, ::p]                                       # lines V = V_j
    on_cols = distance[::p, :]                                       # lines U = U_i
    u_err = np.array([on_rows[i * p:(i + 1) * p + 1].max() for i in range(nu)])
    v_err = np.array([on_cols[:, j * p:(j + 1) * p + 1].max() for j in range(nv)])
    blocks = np.maximum.reduceat(np.maximum.reduceat(distance, np.arange(0, nu * p, p), axis=0),
                                 np.arange(0, nv * p, p), axis=1)
    return DeviationMap(distance, per_span, u_err, v_err, blocks)


def original_on_new(original: NurbsSurface, new: NurbsSurface, params_u: NDArray,
                    params_v: NDArray, uv: NDArray, per_span: int = 10
                    ) -> tuple[NDArray, NDArray]:
    """Eq. 29.3: distances of dense samples of ``original`` from ``new``.

    The projections start from the inverse of the reparametrization map (the
    nearest of a dense sample of the map given by the interpolation nodes
    ``uv (n_u, n_v, 2)`` at the new parameters ``params_u x params_v``); a
    local projection can only overestimate the distance.

    Returns
    -------
    distance : (m,) float
    uv_new : (m, 2) float
        Foot points in ``new``'s domain (where it needs another knot).
    """
    grids = []
    for knots, degree, n, params in ((original.knots_u, original.degree_u, original.n_control[0],
                                      params_u),
                                     (original.knots_v, original.degree_v, original.n_control[1],
                                      params_v)):
        breaks = np.unique(knots[degree:n + 1])
        least = max(MIN_ORIGINAL_SAMPLES, per_span * (len(params) - 1))   # and per new cell
        parts = max(per_span, -(-least // (len(breaks) - 1)))
        grids.append(subdivide(breaks, parts))
    points = original.evaluate_grid(*grids).reshape(-1, original.dimension)
    queries = np.stack(np.meshgrid(*grids, indexing="ij"), axis=-1).reshape(-1, 2)
    guess = inverse_map(params_u, params_v, uv, queries)
    return _chunked(new, points, guess)


def inverse_map(params_u: NDArray, params_v: NDArray, uv: NDArray, queries: NDArray
                ) -> NDArray:
    """Approximate new parameters of original parameters ``queries (m, 2)``.

    The map new -> original is known at the interpolation nodes
    (``uv (n_u, n_v, 2)`` at ``params_u x params_v``); it is sampled 4 x 4 per
    cell (bilinearly) and each query takes the new parameters of the nearest
    sample (k-d tree in the original domain, axes scaled to the queries'
    extent). A start for a local projection, not an exact inverse.

    Returns
    -------
    (m, 2) float
    """
    fine_u, fine_v = subdivide(params_u, 4), subdivide(params_v, 4)
    mesh = np.stack(np.meshgrid(fine_u, fine_v, indexing="ij"), axis=-1).reshape(-1, 2)
    forward = RegularGridInterpolator((params_u, params_v), uv)(mesh)        # original uv
    scale = np.ptp(uv.reshape(-1, 2), axis=0) + 1e-300
    _, nearest = cKDTree(forward / scale).query(np.asarray(queries, float) / scale)
    return mesh[nearest]


def _chunked(surface: NurbsSurface, points: NDArray, guess: NDArray) -> tuple[NDArray, NDArray]:
    """Local projections of ``points (m, 3)`` from ``guess (m, 2)`` in chunks of
    :data:`CHUNK` (bounded memory): distances ``(m,)`` and foot parameters ``(m, 2)``.

    The seeds come from the reparametrization map and are close: a few plain
    Newton steps (:func:`_newton_feet`) settle most points; only those that did
    not settle go to the general projection. Either way the distance is that
    of a point on the surface, so it can only overestimate (a safe figure)."""
    distance, uv = np.empty(len(points)), np.empty((len(points), 2))
    for start in range(0, len(points), CHUNK):
        part = slice(start, start + CHUNK)
        d, foot, settled = _newton_feet(surface, points[part], guess[part])
        if not np.all(settled):
            rest = ~settled
            result = project_to_surface(surface, points[part][rest], guess=guess[part][rest])
            better = result.distance < d[rest]
            idx = np.nonzero(rest)[0][better]
            d[idx], foot[idx] = result.distance[better], result.uv[better]
        distance[part], uv[part] = d, foot
    return distance, uv


def _newton_feet(surface: NurbsSurface, points: NDArray, guess: NDArray
                 ) -> tuple[NDArray, NDArray, NDArray]:
    """Foot points by up to :data:`NEWTON_STEPS` Gauss-Newton steps on ``|p - s(u, v)|^2``
    from ``guess``: distances ``(m,)``, parameters ``(m, 2)`` and which settled (the next
    step below :data:`SETTLED_STEP` of the domain; a point whose step leaves the domain in
    one parameter steps in the other alone, along the edge, and settles there).

    A point leaves the iteration as soon as it settles, with the distance at the
    parameters where the step was found that small (a point on the surface: the figure
    can only overestimate), so each costs one evaluation per step it needs -- two or
    three from the reparametrization map's seeds, where every point used to take
    ``NEWTON_STEPS`` steps and an evaluation more."""
    u0, u1, v0, v1 = surface.domain
    lo, hi = np.array([u0, v0]), np.array([u1, v1])
    uv = np.clip(np.asarray(guess, float).copy(), lo, hi)
    distance = np.full(len(points), np.inf)
    settled = np.zeros(len(points), bool)
    active = np.arange(len(points))
    for k in range(NEWTON_STEPS + 1):
        d = surface.derivatives(uv[active, 0], uv[active, 1], 1)
        su, sv, r = d[:, 1, 0], d[:, 0, 1], points[active] - d[:, 0, 0]
        distance[active] = np.linalg.norm(r, axis=-1)
        if k == NEWTON_STEPS:
            break
        a11, a12, a22 = (su * su).sum(-1), (su * sv).sum(-1), (sv * sv).sum(-1)
        b1, b2 = (su * r).sum(-1), (sv * r).sum(-1)
        det = a11 * a22 - a12 * a12
        ok = det > 1e-300
        safe = np.where(ok, det, 1.0)
        delta = np.stack([(a22 * b1 - a12 * b2) / safe, (a11 * b2 - a12 * b1) / safe], -1)
        delta[~ok] = 0.0
        here = uv[active]
        moved = here + delta
        new = np.clip(moved, lo, hi)
        out = new != moved                                           # (k, 2): left the domain
        # held at the edge in one parameter: the step in the other alone (the foot of a
        # point beyond the surface's boundary lies on it); at a corner, none
        only_v = out[:, 0] & ~out[:, 1] & (a22 > 1e-300)
        only_u = out[:, 1] & ~out[:, 0] & (a11 > 1e-300)
        new[only_v, 1] = np.clip(here[only_v, 1] + b2[only_v] / a22[only_v], lo[1], hi[1])
        new[only_u, 0] = np.clip(here[only_u, 0] + b1[only_u] / a11[only_u], lo[0], hi[0])
        step = np.max(np.abs(new - here) / (hi - lo), axis=1)
        done = ok & (step < SETTLED_STEP)
        settled[active[done]] = True
        uv[active[~done]] = new[~done]
        active = active[~done]
        if not active.size:
            break
    return distance, uv, settled
