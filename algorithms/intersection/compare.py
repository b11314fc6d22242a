"""Distances between two answers to the same intersection problem (ours, OpenCascade's, exact).

All functions take sampled curves (anything with ``points (n, 3)`` and
``closed``, or plain ``(n, 3)`` arrays) and measure with k-d trees
(``scipy.spatial.cKDTree``), vectorized over the samples:

* :func:`hausdorff`: the symmetric Hausdorff distance of two point sets;
* :func:`polyline_distance`: each point's distance to a set of polylines
  (segments, not just vertices, so sparse sampling is not punished);
* :func:`curve_set_distance`: symmetric Hausdorff distance between two sets
  of curves measured to the polylines, and the one-sided distance of every
  curve of each set to the other set (a branch missed by one side shows as a
  large one-sided distance of that branch).

A curve with a cubic interpolant (``curve3d`` and ``parameters``, e.g. an
:class:`.result.IntersectionCurve`, whose samples are only as dense as the
interpolant needs) is measured as that curve: it is densified to
``DENSE_PER_SPAN`` points per span, and distances to it are finished by
Newton's method on ``curve3d`` from the nearest segment (the chords of its
samples would be off the curve by up to about ``h^2 kappa / 8``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from ...errors import InvalidGeometryError

__all__ = [
    "DENSE_PER_SPAN",
    "CurveSetDistance",
    "connected_branches",
    "curve_set_distance",
    "hausdorff",
    "polyline_distance",
]

#: points per span of a curve with an interpolant, as queries and as polyline
DENSE_PER_SPAN = 8
_NEWTON_STEPS = 4


def _points(x: ArrayLike) -> NDArray:
    p = np.asarray(getattr(x, "points", x), dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise InvalidGeometryError(f"points must have shape (n, 3), got {p.shape}")
    return p


def hausdorff(points_a: ArrayLike, points_b: ArrayLike) -> float:
    """Symmetric Hausdorff distance of two point sets ``(n, 3)``, ``(m, 3)``.

    ``max(max_a min_b |a - b|, max_b min_a |a - b|)``; ``inf`` when exactly one
    set is empty, 0 when both are.
    """
    a, b = _points(np.reshape(points_a, (-1, 3))), _points(np.reshape(points_b, (-1, 3)))
    if a.shape[0] == 0 or b.shape[0] == 0:
        return 0.0 if a.shape[0] == b.shape[0] else float("inf")
    d_ab = cKDTree(b).query(a)[0]
    d_ba = cKDTree(a).query(b)[0]
    return float(max(d_ab.max(), d_ba.max()))


def _interpolant(c) -> tuple[object, NDArray] | None:
    """``(curve3d, parameters)`` of a curve with an interpolant, else None."""
    curve3d = getattr(c, "curve3d", None)
    t = getattr(c, "parameters", None)
    if curve3d is None or t is None:
        return None
    return curve3d, np.asarray(t, dtype=float)


def _dense(c) -> tuple[NDArray, NDArray | None]:
    """Polyline ``(k, 3)`` of a curve (a closed one ends where it starts) and the
    interpolant parameter of each vertex (None without an interpolant)."""
    interp = _interpolant(c)
    if interp is None:
        p = _points(c)
        return (np.vstack([p, p[:1]]) if getattr(c, "closed", False) else p), None
    curve3d, t = interp
    s = np.arange(DENSE_PER_SPAN) / DENSE_PER_SPAN
    dense = np.append((t[:-1, None] + s[None, :] * np.diff(t)[:, None]).ravel(), t[-1])
    return curve3d.evaluate(dense), dense


def _segments(curves: Sequence) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray]:
    """All segments of all curves (closing chords too): start points and vectors
    ``(s, 3)``, owning curve ``(s,)``, interpolant parameters of both ends ``(s,)``
    (NaN without an interpolant)."""
    starts, vectors, owner, t0, t1 = [], [], [], [], []
    for i, c in enumerate(curves):
        q, t = _dense(c)
        if q.shape[0] == 1:
            q = np.vstack([q, q])
        if t is None:
            t = np.full(q.shape[0], np.nan)
        starts.append(q[:-1])
        vectors.append(np.diff(q, axis=0))
        owner.append(np.full(q.shape[0] - 1, i))
        t0.append(t[:-1])
        t1.append(t[1:])
    return tuple(np.concatenate(x) for x in (starts, vectors, owner, t0, t1))


def _newton_distance(curve3d, x: NDArray, t: NDArray, lo: float, hi: float) -> NDArray:
    """Distances ``(n,)`` of ``x (n, 3)`` to ``curve3d`` by Newton's method from ``t``."""
    for _ in range(_NEWTON_STEPS):
        d = curve3d.derivatives(t, 2)
        r = d[:, 0] - x
        speed = np.einsum("ij,ij->i", d[:, 1], d[:, 1])
        den = speed + np.einsum("ij,ij->i", r, d[:, 2])
        den = np.where(den > 0, den, speed)
        t = np.clip(t - np.einsum("ij,ij->i", r, d[:, 1]) / np.where(den > 0, den, 1.0), lo, hi)
    return np.linalg.norm(curve3d.evaluate(t) - x, axis=1)


def _nearest_segments(x: NDArray, start: NDArray, vec: NDArray, among: NDArray, k: int
                      ) -> tuple[NDArray, NDArray, NDArray]:
    """Per point of ``x (n, 3)``: distance to the nearest of the segments ``among``
    (the ``k`` with the nearest midpoints tested exactly), that segment and the
    fraction along it."""
    n = x.shape[0]
    _, idx = cKDTree(start[among] + 0.5 * vec[among]).query(x, k=k)
    idx = among[idx.reshape(n, k)]
    a, d = start[idx], vec[idx]                                 # (n, k, 3)
    dd = np.einsum("nkc,nkc->nk", d, d)
    t = np.where(dd > 0, np.einsum("nkc,nkc->nk", x[:, None] - a, d) / np.where(dd > 0, dd, 1),
                 0.0)
    t = np.clip(t, 0.0, 1.0)
    dist = np.linalg.norm(a + t[..., None] * d - x[:, None], axis=-1)
    best = np.argmin(dist, axis=1)
    rows = np.arange(n)
    return dist[rows, best], idx[rows, best], t[rows, best]


def polyline_distance(points: ArrayLike, curves: Sequence, k: int = 8) -> NDArray:
    """Distance ``(n,)`` of each point ``(n, 3)`` to the nearest segment of the polylines.

    Per curve, the ``k`` segments whose midpoints are nearest are tested exactly
    (segments of sampled curves are short and even, so the nearest one is among
    them). Curves with an interpolant are densified and the distance finished on
    the interpolant itself (module docstring).
    """
    x = _points(np.reshape(points, (-1, 3)))
    if len(curves) == 0:
        return np.full(x.shape[0], np.inf)
    start, vec, owner, t0, t1 = _segments(curves)
    k = min(k, start.shape[0])
    out = _nearest_segments(x, start, vec, np.arange(start.shape[0]), k)[0]
    # finish on the interpolants, curve by curve: where curves cross or pass close,
    # the k nearest segments of all curves together may all belong to other curves
    # than the nearest interpolant point (sparse samples sag), so each curve's own
    # nearest segments are looked up for the points its box may hold nearer
    for i in np.unique(owner[~np.isnan(t0)]):
        mine = np.flatnonzero(owner == i)
        ends = np.concatenate([start[mine], start[mine] + vec[mine]])
        lo, hi = ends.min(axis=0), ends.max(axis=0)
        box = np.linalg.norm(np.maximum(np.maximum(lo - x, x - hi), 0.0), axis=1)
        rows = np.flatnonzero(box <= out)
        if rows.size == 0:
            continue
        near, sg, fr = _nearest_segments(x[rows], start, vec, mine, min(k, mine.size))
        curve3d, params = _interpolant(curves[i])
        guess = t0[sg] + fr * (t1[sg] - t0[sg])
        exact = _newton_distance(curve3d, x[rows], guess, params[0], params[-1])
        out[rows] = np.minimum(out[rows], np.minimum(near, exact))
    return out


@dataclass(frozen=True)
class CurveSetDistance:
    """Result of :func:`curve_set_distance`.

    Attributes
    ----------
    hausdorff : float
        Symmetric Hausdorff distance between the two sets (points to polylines).
    a_to_b, b_to_a : (n_a,), (n_b,) float
        Largest distance of each curve of one set to the other set's polylines.
    """

    hausdorff: float
    a_to_b: NDArray
    b_to_a: NDArray

    def unmatched_a(self, tol: float) -> NDArray:
        """Indices of curves of a farther than ``tol`` from b (b missed them)."""
        return np.flatnonzero(self.a_to_b > tol)

    def unmatched_b(self, tol: float) -> NDArray:
        return np.flatnonzero(self.b_to_a > tol)


def curve_set_distance(curves_a: Sequence, curves_b: Sequence) -> CurveSetDistance:
    """Distances between two sets of sampled curves (see module docstring)."""
    a_to_b = np.array([polyline_distance(_dense(c)[0], curves_b).max() for c in curves_a])
    b_to_a = np.array([polyline_distance(_dense(c)[0], curves_a).max() for c in curves_b])
    both = np.concatenate([a_to_b, b_to_a])
    h = float(both.max()) if both.size else 0.0
    return CurveSetDistance(h, a_to_b, b_to_a)


def connected_branches(curves: Sequence, tol: float) -> int:
    """Number of connected pieces of a set of curves in space.

    Curves whose end points meet within ``tol`` (a loop cut at a seam, arcs
    meeting at a bifurcation) count as one; a closed curve is its own piece
    unless an open curve ends on one of its ends. Union-find over the curve
    ends with a k-d tree, so the count does not depend on how an answer
    splits its curves.
    """
    n = len(curves)
    if n == 0:
        return 0
    ends = np.stack([np.stack([_points(c)[0], _points(c)[-1]]) for c in curves]).reshape(-1, 3)
    owner = np.repeat(np.arange(n), 2)
    pairs = cKDTree(ends).query_pairs(tol, output_type="ndarray")
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    graph = coo_matrix((np.ones(len(pairs)), (owner[pairs[:, 0]], owner[pairs[:, 1]])),
                       shape=(n, n))
    return int(connected_components(graph, directed=False)[0])
