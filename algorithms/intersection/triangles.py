"""Vectorized triangle-triangle intersection over arrays of candidate pairs.

The method of 000 §29.4.3: the edges of each triangle are intersected with the
plane of the other, and the points found are tested for lying inside the other
triangle by the signs of its sub-triangle areas (barycentric coordinates,
Fig. 29.15). Of the (up to four) points that pass, the two extreme ones along
the line ``n_a x n_b`` are the segment; all ``k`` pairs are done at once.

Robustness rules
----------------
* **Sign rule (symbolic perturbation).** A corner exactly on the other
  plane (signed distance 0) is decided as if mesh a were translated by an
  infinitesimal ``delta (1, eps, eps^2)``: a corner of a on plane b counts as
  positive when ``n_b . (1, eps, eps^2) > 0`` (the first non-zero component of
  ``n_b``), a corner of b on plane a when ``n_a . (1, eps, eps^2) < 0``. The
  decision depends on the corner and the plane only, not on which triangle the
  corner belongs to nor on its orientation, so when a mesh edge lies exactly in
  the other plane, exactly one of the two triangles sharing it crosses the plane
  and reports the segment along it: one segment, never two, never none.
* **Canonical edge points.** An edge's crossing point is always computed from
  its positive vertex ``P`` towards its negative vertex ``N``,
  ``P + d_P / (d_P - d_N) (N - P)``, with distances that depend only on the
  vertex and the other plane, so the two triangles sharing the edge produce
  bitwise-identical points and the chain of segments does not break.
* **Inside test.** Closed, with a relative slack of ``1e-10`` in barycentric
  coordinates: a point on an edge shared by two triangles is inside both,
  never inside neither, so rounding cannot open a gap in the chain.
* **Coplanar pairs** (both triangles within rounding of each other's plane)
  are not intersected; those that overlap (2D separating-axis test) are
  reported separately.
* **Touching.** When the intersection is a single point (length below
  ``1e-12`` of the pair's size) it is a *touching point*, reported apart from
  the segments (000 drops them; a later stage can use them to see tangential
  contact). Contacts the perturbation moves apart (a corner or an edge of one
  triangle lying exactly on the other, from either side) are found by a
  separate closed test on the corners with zero distance and reported as
  touching points too (both ends of an edge contact).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from . import vectors

__all__ = ["TriangleHits", "intersect_triangles"]

_INSIDE_SLACK = 1e-10
_POINT_LENGTH = 1e-12
_COPLANAR = 64 * np.finfo(float).eps
_EDGE_I = np.array([0, 1, 2])
_EDGE_J = np.array([1, 2, 0])


@dataclass(frozen=True, eq=False)
class TriangleHits:
    """Intersections of ``k`` triangle pairs ``(a[i], b[i])``.

    Attributes
    ----------
    segments : (s, 2, 3) float
        Segment end points, oriented along ``n_a x n_b`` (the triangles'
        right-hand normals), so consecutive segments of a curve run the same way.
    index : (s,) int
        The input pair of each segment.
    bary_a, bary_b : (s, 2, 3) float
        Barycentric coordinates of each end point in triangle a and in triangle b
        (sum 1; the coordinates in a triangle whose edge gave the point are exact
        on that edge).
    source : (s, 2) int
        Where each end point comes from: 0 an edge of triangle a crossing
        triangle b, 1 an edge of b crossing a.
    edge : (s, 2) int
        The local edge (0: corners 0-1, 1: 1-2, 2: 2-0) of that triangle.
    touch_points : (t, 3) float
        Pairs whose intersection is a single point: the point.
    touch_index : (t,) int
    touch_bary_a, touch_bary_b : (t, 3) float
    coplanar_index : (c,) int
        Pairs lying in a common plane (to rounding) and overlapping there.
    """

    segments: NDArray
    index: NDArray
    bary_a: NDArray
    bary_b: NDArray
    source: NDArray
    edge: NDArray
    touch_points: NDArray
    touch_index: NDArray
    touch_bary_a: NDArray
    touch_bary_b: NDArray
    coplanar_index: NDArray


def _check(t: ArrayLike, name: str) -> NDArray:
    a = np.asarray(t, dtype=float)
    if a.size == 0:
        return np.zeros((0, 3, 3))
    if a.ndim != 3 or a.shape[1:] != (3, 3):
        raise InvalidGeometryError(f"{name} must have shape (k, 3, 3), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InvalidGeometryError(f"{name} contains NaN or infinite values")
    return a


def _dot(a: NDArray, b: NDArray) -> NDArray:
    return np.sum(a * b, axis=-1)


def _barycentric(tri: NDArray, normal: NDArray, p: NDArray) -> NDArray:
    """Barycentric coordinates (k, c, 3) of points p (k, c, 3) projected into triangles."""
    t = tri[:, None]                                         # (k, 1, 3, 3)
    n = normal[:, None]
    w = np.stack([_dot(n, vectors.cross(t[:, :, 1] - p, t[:, :, 2] - p)),
                  _dot(n, vectors.cross(t[:, :, 2] - p, t[:, :, 0] - p)),
                  _dot(n, vectors.cross(t[:, :, 0] - p, t[:, :, 1] - p))], axis=-1)
    return w / _dot(normal, normal)[:, None, None]


def _edge_points(tri: NDArray, dist: NDArray, positive: NDArray
                 ) -> tuple[NDArray, NDArray, NDArray]:
    """The two points where a triangle crossing a plane meets it.

    Parameters
    ----------
    tri : (k, 3, 3) float
    dist : (k, 3) float
        Signed distances (scaled) of the corners from the other plane.
    positive : (k, 3) bool
        Side of each corner under the sign rule; mixed in every row.

    Returns
    -------
    points : (k, 2, 3) float
    bary : (k, 2, 3) float
        Exact barycentric coordinates on the crossing edges.
    edges : (k, 2) int
        Local edge ids.
    """
    k = tri.shape[0]
    crossing = positive[:, _EDGE_I] != positive[:, _EDGE_J]          # exactly two per row
    edges = np.argsort(~crossing, axis=1, kind="stable")[:, :2]
    i, j = _EDGE_I[edges], _EDGE_J[edges]
    rows = np.arange(k)[:, None]
    pos_i = positive[rows, i]
    vp, vn = np.where(pos_i, i, j), np.where(pos_i, j, i)
    dp, dn = dist[rows, vp], dist[rows, vn]
    t = dp / (dp - dn)
    pp, pn = tri[rows, vp], tri[rows, vn]
    points = pp + t[..., None] * (pn - pp)
    bary = np.zeros((k, 2, 3))
    bary[rows, np.arange(2), vp] = 1.0 - t
    bary[rows, np.arange(2), vn] = t
    return points, bary, edges


def _clip(a: NDArray, b: NDArray, na: NDArray, nb: NDArray, da: NDArray, db: NDArray,
          pos_a: NDArray, pos_b: NDArray) -> tuple:
    """Extreme inside points along ``na x nb`` of pairs crossing each other's planes.

    Returns ``(ends (k, 2, 3), bary_a (k, 2, 3), bary_b (k, 2, 3), source (k, 2),
    edge (k, 2), found (k,) bool, length (k,))``.
    """
    pa, ba_own, ea = _edge_points(a, da, pos_a)
    pb, bb_own, eb = _edge_points(b, db, pos_b)
    ba_in_b = _barycentric(b, nb, pa)                        # (k, 2, 3)
    bb_in_a = _barycentric(a, na, pb)
    points = np.concatenate([pa, pb], axis=1)                # (k, 4, 3)
    bary_a = np.concatenate([ba_own, bb_in_a], axis=1)
    bary_b = np.concatenate([ba_in_b, bb_own], axis=1)
    inside = np.concatenate([np.all(ba_in_b >= -_INSIDE_SLACK, axis=2),
                             np.all(bb_in_a >= -_INSIDE_SLACK, axis=2)], axis=1)
    source = np.repeat([[0, 0, 1, 1]], a.shape[0], axis=0)
    edge = np.concatenate([ea, eb], axis=1)
    s = _dot(points, vectors.cross(na, nb)[:, None])
    lo = np.argmin(np.where(inside, s, np.inf), axis=1)
    hi = np.argmax(np.where(inside, s, -np.inf), axis=1)
    pick = np.stack([lo, hi], axis=1)
    rows = np.arange(a.shape[0])[:, None]
    ends = points[rows, pick]
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    return (ends, bary_a[rows, pick], bary_b[rows, pick], source[rows, pick],
            edge[rows, pick], np.any(inside, axis=1), length)


def _coplanar_overlap(a: NDArray, b: NDArray, normal: NDArray) -> NDArray:
    """Closed 2D overlap of coplanar triangle pairs (separating axes of the 6 edges)."""
    drop = np.argmax(np.abs(normal), axis=1)
    keep = np.array([[1, 2], [0, 2], [0, 1]])[drop]                # (c, 2)
    index = np.broadcast_to(keep[:, None, :], (a.shape[0], 3, 2))
    a2 = np.take_along_axis(a, index, axis=2)                      # (c, 3, 2)
    b2 = np.take_along_axis(b, index, axis=2)
    edges = np.concatenate([a2[:, _EDGE_J] - a2, b2[:, _EDGE_J] - b2], axis=1)   # (c, 6, 2)
    axes = np.stack([-edges[..., 1], edges[..., 0]], axis=-1)
    proj_a = np.einsum("cad,cvd->cav", axes, a2)                   # (c, 6, 3)
    proj_b = np.einsum("cad,cvd->cav", axes, b2)
    separated = ((proj_a.max(axis=2) < proj_b.min(axis=2))
                 | (proj_b.max(axis=2) < proj_a.min(axis=2)))
    return ~np.any(separated, axis=1)


def _lex_sign(n: NDArray) -> NDArray:
    """Sign of ``n . (1, eps, eps^2)`` for infinitesimal eps: first non-zero component."""
    first = np.argmax(n != 0, axis=1)
    return np.sign(n[np.arange(n.shape[0]), first])


def _zero_contacts(a: NDArray, b: NDArray, na: NDArray, nb: NDArray, zero_a: NDArray,
                   zero_b: NDArray, span: NDArray) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Corners lying exactly on the other plane and inside the other triangle.

    For each pair, the extreme such corners along ``na x nb``: one touching point,
    or two when they span an edge contact.

    Returns
    -------
    points : (t, 3) float
    bary_a, bary_b : (t, 3) float
    pair : (t,) int
        Row of the input the point belongs to.
    """
    k = a.shape[0]
    points = np.concatenate([a, b], axis=1)                              # (k, 6, 3)
    eye = np.broadcast_to(np.eye(3), (k, 3, 3))
    bary_a = np.concatenate([eye, _barycentric(a, na, b)], axis=1)
    bary_b = np.concatenate([_barycentric(b, nb, a), eye], axis=1)
    inside = np.concatenate([np.all(bary_b[:, :3] >= -_INSIDE_SLACK, axis=2) & zero_a,
                             np.all(bary_a[:, 3:] >= -_INSIDE_SLACK, axis=2) & zero_b], axis=1)
    s = _dot(points, vectors.cross(na, nb)[:, None])
    lo = np.argmin(np.where(inside, s, np.inf), axis=1)
    hi = np.argmax(np.where(inside, s, -np.inf), axis=1)
    rows = np.arange(k)
    any_in = np.any(inside, axis=1)
    two = any_in & (np.linalg.norm(points[rows, hi] - points[rows, lo], axis=1)
                    > _POINT_LENGTH * span)
    pair = np.concatenate([rows[any_in], rows[two]])
    pick = np.concatenate([lo[any_in], hi[two]])
    order = np.argsort(pair, kind="stable")
    pair, pick = pair[order], pick[order]
    return points[pair, pick], bary_a[pair, pick], bary_b[pair, pick], pair


def intersect_triangles(tri_a: ArrayLike, tri_b: ArrayLike) -> TriangleHits:
    """Intersect triangle pairs ``(tri_a[i], tri_b[i])``, all at once (000 §29.4.3).

    Parameters
    ----------
    tri_a, tri_b : (k, 3, 3) float
        Corner points of the triangles of each pair (non-degenerate; a
        zero-area triangle is treated as coplanar with its partner).

    Returns
    -------
    TriangleHits
        Segments with their pair indices and barycentric coordinates in both
        triangles, touching points and overlapping coplanar pairs (see the
        module docstring for the rules).
    """
    a, b = _check(tri_a, "tri_a"), _check(tri_b, "tri_b")
    if a.shape != b.shape:
        raise InvalidGeometryError(f"tri_a and tri_b differ in shape: {a.shape} vs {b.shape}")
    na = vectors.cross(a[:, 1] - a[:, 0], a[:, 2] - a[:, 0])
    nb = vectors.cross(b[:, 1] - b[:, 0], b[:, 2] - b[:, 0])
    da = _dot(nb[:, None], a - b[:, :1])                     # (k, 3), scaled by |nb|
    db = _dot(na[:, None], b - a[:, :1])
    lo_a, hi_a = vectors.corner_min(a), vectors.corner_max(a)
    lo_b, hi_b = vectors.corner_min(b), vectors.corner_max(b)
    size = vectors.entry_max(np.abs(np.concatenate([lo_a, hi_a, lo_b, hi_b], axis=1)))
    span = vectors.entry_max(np.concatenate([hi_a - lo_a, hi_b - lo_b], axis=1))
    limit = _COPLANAR * (size + span)
    len_a, len_b = np.linalg.norm(na, axis=1), np.linalg.norm(nb, axis=1)
    coplanar = ((vectors.entry_max(np.abs(da)) <= limit * len_b)
                & (vectors.entry_max(np.abs(db)) <= limit * len_a))
    cop = np.flatnonzero(coplanar)
    cop = cop[_coplanar_overlap(a[cop], b[cop], na[cop])]

    # symbolic perturbation: mesh a translated by +delta e, e = (1, eps, eps^2)
    pa = (da > 0) | ((da == 0) & (_lex_sign(nb) > 0)[:, None])
    pb = (db > 0) | ((db == 0) & (_lex_sign(na) < 0)[:, None])
    mixed = pa.any(1) & ~pa.all(1) & pb.any(1) & ~pb.all(1) & ~coplanar
    idx = np.flatnonzero(mixed)
    ends, bary_a, bary_b, src, edge, found, length = _clip(
        a[idx], b[idx], na[idx], nb[idx], da[idx], db[idx], pa[idx], pb[idx])
    seg = found & (length > _POINT_LENGTH * span[idx])
    touch = found & ~seg
    # contacts the perturbation moved apart: corners exactly on the other plane
    rest = np.ones(a.shape[0], bool)
    rest[idx[found]] = False
    rest &= ~coplanar & (np.any(da == 0, axis=1) | np.any(db == 0, axis=1))
    idx2 = np.flatnonzero(rest)
    t_pts, t_ba, t_bb, t_idx = _zero_contacts(a[idx2], b[idx2], na[idx2], nb[idx2],
                                              da[idx2] == 0, db[idx2] == 0, span[idx2])
    return TriangleHits(
        segments=ends[seg], index=idx[seg], bary_a=bary_a[seg], bary_b=bary_b[seg],
        source=src[seg], edge=edge[seg],
        touch_points=np.concatenate([ends[touch, 0], t_pts]),
        touch_index=np.concatenate([idx[touch], idx2[t_idx]]),
        touch_bary_a=np.concatenate([bary_a[touch, 0], t_ba]),
        touch_bary_b=np.concatenate([bary_b[touch, 0], t_bb]),
        coplanar_index=cop)
