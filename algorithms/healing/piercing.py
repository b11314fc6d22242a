"""Projection of the Coons grid onto the original geometry along its normals
(001 §4, eqs. 9-11; 000 §29.3.3).

Every grid point ``x_{I,J}`` owns the segment ``a_{I,J} b_{I,J}`` through it
along its normal. The segments are intersected with the clipped triangles
(Möller-Trumbore on the candidate pairs of a box tree, all pairs at once);
of several hits the one closest to ``x`` is kept ("independent of the
orientation of the Coons patch"). Its position on the segment is ``t`` of
eq. (11), ``p = (1 - t) a + t b``, so ``x`` is at ``t = 1/2``.

A hit on a triangle of a parametric surface is then mapped onto the surface:
its barycentric coordinates (eq. 9) combine the corners' ``(u, v)`` (eq. 10),
and, beyond the paper, Newton's method on ``S(u, v) = a + t (b - a)`` in
``(u, v, t)`` started there puts the point where the segment pierces the exact
surface (a closest-point projection of ``S(ū, v̄)`` would not move it: it is
on the surface already). Where Newton fails (the segment leaves the surface
over its edge, or grazes it) the mapped point ``S(ū, v̄)`` of the paper is kept.
Hits on plain triangulations are used as they are.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..intersection.culling import candidate_pairs
from ..surface import NurbsSurface
from . import piercing_kernels
from .clipping import ClippedTriangles

__all__ = ["SegmentHits", "intersect_segments", "moller_trumbore", "project_grid"]

_EDGE_SLACK = 1e-9          # barycentric slack: hits on shared edges are not lost
_NEWTON_STEPS = 12


@dataclass(frozen=True, eq=False)
class SegmentHits:
    """Closest hit of every segment.

    Attributes
    ----------
    found : (P,) bool
    t : (P,) float
        Position on the segment (eq. 11), NaN where nothing was hit.
    triangle : (P,) int
        Index of the hit triangle, -1 where nothing was hit.
    barycentric : (P, 3) float
        Weights of the triangle's corners (eq. 9), NaN where nothing was hit.
    """

    found: NDArray
    t: NDArray
    triangle: NDArray
    barycentric: NDArray


def _all_hits(a: NDArray, b: NDArray, triangles: NDArray
              ) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Every segment-triangle hit: segment, triangle, ``t`` and barycentric weights."""
    empty = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 3)))
    if triangles.shape[0] == 0 or a.shape[0] == 0:
        return empty
    seg_boxes = np.stack([np.minimum(a, b), np.maximum(a, b)], axis=1)
    tri_boxes = np.stack([triangles.min(axis=1), triangles.max(axis=1)], axis=1)
    scale = float(np.ptp(tri_boxes.reshape(-1, 3), axis=0).max())
    pairs = candidate_pairs(seg_boxes, tri_boxes, pad=1e-12 * scale)
    if pairs.shape[0] == 0:
        return empty
    s, k = pairs[:, 0], pairs[:, 1]
    if piercing_kernels.AVAILABLE:               # the same arithmetic, pair by pair
        t, w1, w2, ok = piercing_kernels.hits_on_pairs(a, b, triangles, s, k, _EDGE_SLACK)
    else:                                        # pragma: no cover - numba is installed in CI
        t, w1, w2, ok = moller_trumbore(a[s], b[s] - a[s], triangles[k])
    w1, w2 = np.clip(w1[ok], 0, 1), np.clip(w2[ok], 0, 1)
    total = np.maximum(1.0, w1 + w2)
    w1, w2 = w1 / total, w2 / total
    return s[ok], k[ok], t[ok], np.stack([1 - w1 - w2, w1, w2], axis=1)


def _nearest_midpoint(groups: NDArray, t: NDArray) -> NDArray:
    """Index of the entry with ``t`` nearest 1/2 in every group (groups ascending)."""
    order = np.lexsort((np.abs(t - 0.5), groups))
    if order.size == 0:
        return order
    return order[np.r_[True, groups[order][1:] != groups[order][:-1]]]


def intersect_segments(a: NDArray, b: NDArray, triangles: NDArray) -> SegmentHits:
    """Hits of segments ``a b`` with triangles, the one closest to the midpoint kept.

    Parameters
    ----------
    a, b : (P, 3) float
    triangles : (T, 3, 3) float

    Returns
    -------
    SegmentHits
    """
    n = a.shape[0]
    out_t = np.full(n, np.nan)
    out_tri = np.full(n, -1, np.int64)
    out_bary = np.full((n, 3), np.nan)
    s, k, t, bary = _all_hits(a, b, triangles)
    first = _nearest_midpoint(s, t)
    seg = s[first]
    out_t[seg], out_tri[seg], out_bary[seg] = t[first], k[first], bary[first]
    return SegmentHits(out_tri >= 0, out_t, out_tri, out_bary)


def moller_trumbore(origin: NDArray, direction: NDArray, tri: NDArray
                    ) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Segment parameter, two barycentric weights and hit mask of pairs (vectorized).

    The numpy form of :func:`.piercing_kernels.hits_on_pairs` (its reference).

    Parameters
    ----------
    origin, direction : (M, 3) float
        Segment ``origin + t direction``, ``t`` in ``[0, 1]``.
    tri : (M, 3, 3) float

    Returns
    -------
    t, w1, w2 : (M,) float
    ok : (M,) bool
    """
    e1 = tri[:, 1] - tri[:, 0]
    e2 = tri[:, 2] - tri[:, 0]
    h = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, h)
    size = (np.linalg.norm(e1, axis=1) * np.linalg.norm(e2, axis=1)
            * np.linalg.norm(direction, axis=1))
    solid = np.abs(det) > 1e-12 * size
    inv = np.where(solid, 1.0 / np.where(solid, det, 1.0), 0.0)
    sv = origin - tri[:, 0]
    w1 = inv * np.einsum("ij,ij->i", sv, h)
    q = np.cross(sv, e1)
    w2 = inv * np.einsum("ij,ij->i", direction, q)
    t = inv * np.einsum("ij,ij->i", e2, q)
    eps = _EDGE_SLACK
    ok = (solid & (w1 >= -eps) & (w2 >= -eps) & (w1 + w2 <= 1 + eps)
          & (t >= 0) & (t <= 1))
    return t, w1, w2, ok


def pierce_surface(surface: NurbsSurface, origin: NDArray, direction: NDArray, uv0: NDArray,
                   t0: NDArray, tol: float) -> tuple[NDArray, NDArray, NDArray]:
    """Newton on ``S(u, v) - (origin + t direction) = 0`` in ``(u, v, t)``.

    Parameters
    ----------
    surface : NurbsSurface
    origin, direction : (P, 3) float
    uv0 : (P, 2) float
    t0 : (P,) float
    tol : float
        Model units: converged when the residual is below it.

    Returns
    -------
    uv : (P, 2) float
    t : (P,) float
    ok : (P,) bool
        Converged inside the domain with ``t`` in ``[0, 1]``.
    """
    u0, u1, v0, v1 = surface.domain
    lo, hi = np.array([u0, v0]), np.array([u1, v1])
    uv, t = uv0.copy(), t0.copy()
    active = np.arange(t.size)
    for _ in range(_NEWTON_STEPS):
        if active.size == 0:
            break
        d = surface.derivatives(uv[active, 0], uv[active, 1], 1)
        f = d[:, 0, 0] - origin[active] - t[active, None] * direction[active]
        # points already within a tenth of tol stop (their next step would be smaller)
        moving = np.linalg.norm(f, axis=1) > 0.1 * tol
        active, d, f = active[moving], d[moving], f[moving]
        if active.size == 0:
            break
        jac = np.stack([d[:, 1, 0], d[:, 0, 1], -direction[active]], axis=2)
        det = np.linalg.det(jac)
        good = np.abs(det) > 1e-300
        step = np.zeros((active.size, 3))
        if np.any(good):
            with np.errstate(all="ignore"):
                step[good] = np.linalg.solve(jac[good], -f[good][..., None])[..., 0]
        step[~np.all(np.isfinite(step), axis=1)] = 0.0
        uv[active] = np.clip(uv[active] + step[:, :2], lo, hi)
        t[active] = t[active] + step[:, 2]
    p = surface.evaluate(uv[:, 0], uv[:, 1])
    residual = np.linalg.norm(p - origin - t[:, None] * direction, axis=1)
    ok = (residual <= tol) & (t >= 0) & (t <= 1) & np.all(np.isfinite(uv), axis=1)
    return uv, t, ok


def project_grid(a: NDArray, b: NDArray, clipped: ClippedTriangles, *, tol: float,
                 preferred: int | None = None) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Projections ``y`` of the grid onto the sources (eqs. 9-11 and the Newton polish).

    The hit nearest the midpoint is chosen after the polish, among the nearest
    hit on each source, so that where two sources cross the choice is made on
    the exact surfaces, not on their triangulations.

    Parameters
    ----------
    a, b : (P, 3) float
        Upper and lower offset points of the grid, flattened.
    clipped : ClippedTriangles
    tol : float
        Residual accepted by the Newton polish, model units.
    preferred : int, optional
        Index of a source whose hit wins over hits on the others, nearer the
        midpoint or not (the face an approximant replaces: other faces are
        only for where the segment misses it; with a long ``d`` a segment may
        otherwise pick a far-away face that crosses it nearer ``x``).

    Returns
    -------
    points : (P, 3) float
        ``y`` where found, NaN elsewhere.
    t : (P,) float
        Position on the segment (eq. 11), NaN where nothing was hit.
    found : (P,) bool
    source : (P,) int
        Index of the source hit, -1 where nothing was hit.
    """
    n = a.shape[0]
    seg, tri, t, bary = _all_hits(a, b, clipped.points)
    src = clipped.source[tri]
    keep = _nearest_midpoint(seg * len(clipped.sources) + src, t)   # best hit per source
    seg, tri, t, bary, src = seg[keep], tri[keep], t[keep], bary[keep], src[keep]
    points = np.einsum("pk,pkc->pc", bary, clipped.points[tri])
    uv = np.einsum("pk,pkc->pc", bary, clipped.uv[tri])
    for k in np.unique(src):
        surface = clipped.sources[k].surface
        sel = np.flatnonzero((src == k) & np.all(np.isfinite(uv), axis=1))
        if surface is None or sel.size == 0:
            continue
        rows = seg[sel]
        new_uv, new_t, ok = pierce_surface(surface, a[rows], b[rows] - a[rows], uv[sel],
                                           t[sel], tol)
        final_uv = np.where(ok[:, None], new_uv, uv[sel])
        points[sel] = surface.evaluate(final_uv[:, 0], final_uv[:, 1])
        t[sel] = np.where(ok, new_t, t[sel])
    rank = t if preferred is None else np.where(src == preferred, t, t + 2.0)
    best = _nearest_midpoint(seg, rank)     # |rank - 1/2| > 1 off the preferred source
    out_points = np.full(a.shape, np.nan)
    out_t = np.full(n, np.nan)
    out_src = np.full(n, -1, np.int64)
    rows = seg[best]
    out_points[rows], out_t[rows], out_src[rows] = points[best], t[best], src[best]
    return out_points, out_t, out_src >= 0, out_src
