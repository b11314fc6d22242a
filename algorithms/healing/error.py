"""Error of a local approximant (001 §7, eq. 19; 000 §29.3.6).

The approximant ``s`` is measured at the points

* ``e_{I,J} = s((ξ_I + ξ_{I+1}) / 2, η_J)``,
* ``f_{I,J} = s(ξ_I, (η_J + η_{J+1}) / 2)``,
* ``g_{I,J} = s((ξ_I + ξ_{I+1}) / 2, (η_J + η_{J+1}) / 2)`` (eq. 19),

where bicubic interpolants deviate most, by their shortest distance to the
original geometry. A point is measured only when the grid points around it
(both ends of its edge for ``e`` and ``f``, all four corners for ``g``) are
projections onto the originals, not artificial ones: the others lie over a
hole and have nothing to be close to. The error is the largest distance; the
RMS is reported too (003).

Distances (:func:`distance_to_triangles`): the exact closest point on the
nearest clipped triangles of each source, and, on a parametric source, Newton
point inversion (:func:`..projection.project_to_surface`) started at the
parameters of that point (eq. 10), so the foot is found near the part of the
surface that was triangulated (a trimmed face's mesh) without a global search.
:func:`distance_to_sources` is the global version (every source, seeds from
a sample grid).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from ..intersection.mesh import TriangleMesh
from ..projection import project_to_surface
from ..surface import NurbsSurface
from . import error_kernels
from .clipping import ClippedTriangles, SurfaceSource

__all__ = [
    "ErrorSample",
    "closest_on_triangles",
    "distance_to_sources",
    "distance_to_triangles",
    "error_parameters",
    "measure_error",
]

_CANDIDATE_TRIANGLES = 12


@dataclass(frozen=True, eq=False)
class ErrorSample:
    """Distances of an approximant to the originals at the points of eq. (19).

    Attributes
    ----------
    uv : (k, 2) float
        Parameters of the measured points on the approximant.
    points : (k, 3) float
    distance : (k,) float
    max_error, rms_error : float
        NaN when no point could be measured (every cell over a hole).
    """

    uv: NDArray
    points: NDArray
    distance: NDArray
    max_error: float
    rms_error: float

    @property
    def n_points(self) -> int:
        return self.distance.size


def error_parameters(found: NDArray) -> NDArray:
    """Parameters of the points e, f, g of eq. (19) not over holes.

    Parameters
    ----------
    found : (M + 1, N + 1) bool
        Grid points that are projections onto the originals.

    Returns
    -------
    (k, 2) float
    """
    m, n = found.shape[0] - 1, found.shape[1] - 1
    xi, eta = np.linspace(0, 1, m + 1), np.linspace(0, 1, n + 1)
    xm, em = 0.5 * (xi[:-1] + xi[1:]), 0.5 * (eta[:-1] + eta[1:])
    e_ok = found[:-1, :] & found[1:, :]
    f_ok = found[:, :-1] & found[:, 1:]
    g_ok = e_ok[:, :-1] & e_ok[:, 1:]
    parts = []
    for us, vs, ok in ((xm, eta, e_ok), (xi, em, f_ok), (xm, em, g_ok)):
        uu, vv = np.meshgrid(us, vs, indexing="ij")
        parts.append(np.stack([uu[ok], vv[ok]], axis=1))
    return np.concatenate(parts)


def closest_on_triangles(points: NDArray, tri: NDArray) -> tuple[NDArray, NDArray]:
    """Closest points of triangles to points, pairwise.

    Parameters
    ----------
    points : (k, 3) float
    tri : (k, 3, 3) float

    Returns
    -------
    foot : (k, 3) float
    barycentric : (k, 3) float
    """
    p0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    g11, g12, g22 = (np.einsum("ij,ij->i", e1, e1), np.einsum("ij,ij->i", e1, e2),
                     np.einsum("ij,ij->i", e2, e2))
    r1, r2 = np.einsum("ij,ij->i", points - p0, e1), np.einsum("ij,ij->i", points - p0, e2)
    det = g11 * g22 - g12 * g12
    solid = det > 1e-14 * g11 * g22            # a sliver or point: its edges decide
    inv = np.where(solid, 1.0 / np.where(solid, det, 1.0), 0.0)
    s_, t_ = (g22 * r1 - g12 * r2) * inv, (g11 * r2 - g12 * r1) * inv
    bary = np.stack([1 - s_ - t_, s_, t_], axis=1)
    inside = solid & np.all(bary >= 0, axis=1)
    best_d = np.where(inside, np.linalg.norm(points - np.einsum("kc,kcd->kd", bary, tri), axis=1),
                      np.inf)
    best_b = bary.copy()
    for i, j in ((0, 1), (1, 2), (2, 0)):
        a, b = tri[:, i], tri[:, j]
        ab = b - a
        s = np.clip(np.einsum("ij,ij->i", points - a, ab)
                    / np.maximum(np.einsum("ij,ij->i", ab, ab), np.finfo(float).tiny), 0, 1)
        d = np.linalg.norm(points - (a + s[:, None] * ab), axis=1)
        better = ~inside & (d < best_d)
        cand = np.zeros_like(bary)
        cand[:, i], cand[:, j] = 1 - s, s
        best_d = np.where(better, d, best_d)
        best_b = np.where(better[:, None], cand, best_b)
    return np.einsum("kc,kcd->kd", best_b, tri), best_b


def _mesh_closest(mesh: TriangleMesh, points: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """Distance, triangle and barycentric weights of the closest mesh point to each point."""
    tri = mesh.triangle_points()
    k = min(_CANDIDATE_TRIANGLES, tri.shape[0])
    _, cand = cKDTree(tri.mean(axis=1)).query(points, k=k)
    cand = cand.reshape(points.shape[0], k)
    rep = np.repeat(points, k, axis=0)
    foot, bary = closest_on_triangles(rep, tri[cand.ravel()])
    dist = np.linalg.norm(rep - foot, axis=1).reshape(-1, k)
    best = np.argmin(dist, axis=1)
    rows = np.arange(points.shape[0])
    return dist[rows, best], cand[rows, best], bary.reshape(-1, k, 3)[rows, best]


def _source_distance(source: SurfaceSource, points: NDArray, tol: float) -> NDArray:
    if source.mesh is None:
        return project_to_surface(source.surface, points, tol=tol, n_seeds=2).distance
    dist, tri, bary = _mesh_closest(source.mesh, points)
    if source.surface is None:
        return dist
    uv = np.einsum("kc,kcd->kd", bary, source.mesh.triangle_uv()[tri])
    exact = project_to_surface(source.surface, points, tol=tol, guess=uv).distance
    return np.minimum(dist, exact)


def distance_to_sources(points: NDArray, sources: tuple[SurfaceSource, ...], *,
                        tol: float) -> NDArray:
    """Shortest distance of each point to any of the sources.

    Parameters
    ----------
    points : (k, 3) float
    sources : tuple of SurfaceSource
    tol : float
        Convergence of the point inversion, model units.

    Returns
    -------
    (k,) float
    """
    best = np.full(points.shape[0], np.inf)
    if points.shape[0] == 0:
        return best
    for source in sources:
        best = np.minimum(best, _source_distance(source, points, tol))
    return best


def distance_to_triangles(points: NDArray, clipped: ClippedTriangles, *, tol: float
                          ) -> NDArray:
    """Shortest distance of each point to the clipped sources, through their triangles.

    Per source, its triangles nearest each point (by centroid, searched among
    that source's triangles only: a plane cut into a few large triangles is not
    crowded out by a finely triangulated neighbour) give the closest point of
    the triangulation; on a parametric source its barycentric ``(u, v)``
    (eq. 10) starts Newton point inversion on the exact surface (whose foot may
    leave the triangulated part of a trimmed source: so no source is ruled out by
    its triangles' distance). The sources are taken nearest first, and a point
    farther from a surface's control-net box than the best distance found so far is
    not inverted on it (the surface lies in the box; 65 % of the inversions of a heal
    of occt_k1_catia_theorem.stp): the result is the same.

    Parameters
    ----------
    points : (k, 3) float
    clipped : ClippedTriangles
    tol : float
        Convergence of the point inversion, model units.

    Returns
    -------
    (k,) float, ``inf`` where there is no triangle.
    """
    best = np.full(points.shape[0], np.inf)
    if points.shape[0] == 0 or clipped.n_triangles == 0:
        return best
    per_source = []
    for s_id in np.unique(clipped.source):
        dist, uv = _source_triangles(points, clipped, np.flatnonzero(clipped.source == s_id))
        per_source.append((float(np.median(dist)), int(s_id), dist, uv))
    # nearest sources first: a point farther from a source's control-net box than the
    # best distance found so far cannot come closer to that surface (it lies in the
    # convex hull of its control points, its triangles too), so it is not inverted
    for _, s_id, dist, uv in sorted(per_source, key=lambda item: item[:2]):
        surface = clipped.sources[s_id].surface
        exact = np.all(np.isfinite(uv), axis=1)
        if surface is not None and np.any(exact):
            box = surface.bounding_box()
            below = np.linalg.norm(np.maximum(np.maximum(box[0] - points, 0.0),
                                              points - box[1]), axis=1)
            beyond = exact & (below >= best)
            dist[beyond] = np.inf
            exact &= ~beyond
            if np.any(exact):
                # chords, not the surface, where the surface is known
                dist[exact] = project_to_surface(surface, points[exact], tol=tol,
                                                 guess=uv[exact]).distance
        np.minimum(best, dist, out=best)
    return best


def _source_triangles(points: NDArray, clipped: ClippedTriangles, ids: NDArray
                      ) -> tuple[NDArray, NDArray]:
    """``(distance (k,), (u, v) (k, 2))``: each point's distance to one source's clipped
    triangles ``ids`` and the barycentric ``(u, v)`` of the foot (NaN without
    parameters)."""
    k_pts = points.shape[0]
    k = min(_CANDIDATE_TRIANGLES, ids.size)
    _, cand = cKDTree(clipped.points[ids].mean(axis=1)).query(points, k=k)
    cand = ids[cand.reshape(k_pts, k)]
    if error_kernels.AVAILABLE:
        dist, pick, bary = error_kernels.nearest_on_candidates(points, clipped.points, cand)
    else:                               # pragma: no cover - numba is installed in CI
        dist, pick, bary = _nearest_numpy(points, clipped.points, cand)
    chosen = cand[np.arange(k_pts), pick]
    uv = np.einsum("pk,pkc->pc", bary, clipped.uv[chosen])
    return dist, uv


def _nearest_numpy(points: NDArray, tri: NDArray, cand: NDArray
                   ) -> tuple[NDArray, NDArray, NDArray]:
    """:func:`.error_kernels.nearest_on_candidates` by :func:`closest_on_triangles`."""
    k_pts, k = cand.shape
    rows = np.repeat(np.arange(k_pts), k)
    foot, bary = closest_on_triangles(points[rows], tri[cand.ravel()])
    dist = np.linalg.norm(points[rows] - foot, axis=1).reshape(k_pts, k)
    pick = np.argmin(dist, axis=1)
    flat = np.arange(k_pts) * k + pick
    return dist[np.arange(k_pts), pick], pick, bary[flat]


def measure_error(surface: NurbsSurface, found: NDArray, clipped: ClippedTriangles,
                  *, tol: float) -> ErrorSample:
    """The error of §7 (module docstring).

    Parameters
    ----------
    surface : NurbsSurface
        The approximant over ``[0, 1]^2``.
    found : (M + 1, N + 1) bool
    clipped : ClippedTriangles
        The sources near the approximant and their triangles.
    tol : float
        Convergence of the point inversion, model units.
    """
    uv = error_parameters(found)
    points = surface.evaluate(uv[:, 0], uv[:, 1]) if uv.size else np.zeros((0, 3))
    distance = distance_to_triangles(points, clipped, tol=tol)
    if distance.size == 0:
        return ErrorSample(uv, points, distance, float("nan"), float("nan"))
    return ErrorSample(uv, points, distance, float(distance.max()),
                       float(np.sqrt(np.mean(distance ** 2))))
