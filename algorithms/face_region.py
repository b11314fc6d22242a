"""Which ``(u, v)`` lie inside a trimmed face: the one point-in-trimmed-face of surfprep.

A trimmed face's loops are sampled densely in ``(u, v)`` (every edge's pcurve at
``EDGE_SAMPLES`` points, more for edges long in the parameter plane) into one
set of polygon segments (:func:`loop_segments`). A point is inside when a ray
from it in +u crosses the segments an odd number of times (even-odd rule: the
outer loop and the holes at once); the segments are bucketed by their v-range
so each point meets only the segments of its bucket, counted by a compiled
kernel (:class:`LoopIndex`, :mod:`.face_region_kernels`). :func:`inside_loops`
is that test on polygons given directly.

:class:`FaceRegion` holds a :class:`~.trimmed.TrimmedFace` with everything the
test needs built once on first use: the segments and their loop index, a
nearest-segment tree of them in ``(u, v)`` and one of the trimming edges in
space (:class:`SegmentTree`). :meth:`FaceRegion.contains` adds the boundary:
points within ``ON_BOUNDARY`` times the domain diagonal of a loop count as
inside, and, given a tolerance, so do points whose image lies within it (plus
twice the face's largest edge tolerance) of a trimming edge in space (a curve
running along the shared edge of two faces is on both). A face without loops,
or whose loops run along its parameter rectangle, is the rectangle.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .face_region_kernels import ray_crossings
from .surface import NurbsSurface
from .trimmed import TrimmedFace

__all__ = [
    "EDGE_SAMPLES",
    "JOIN_ENDS",
    "NEAR_BOUNDARY",
    "ON_BOUNDARY",
    "FaceRegion",
    "LoopIndex",
    "SegmentTree",
    "inside_loops",
    "is_rectangle",
    "loop_segments",
]

#: a (u, v) this close to a trimming loop (relative to the domain diagonal) is inside
ON_BOUNDARY = 1e-9
#: (u, v) this close to a loop (relative to the domain diagonal) are measured in space
NEAR_BOUNDARY = 1e-2

#: samples per trimming edge for the point-in-face test
EDGE_SAMPLES = 64
#: edge ends closer than this (relative to the domain diagonal) are one polygon vertex
JOIN_ENDS = 1e-12


def loop_segments(face: TrimmedFace) -> tuple[NDArray, NDArray, NDArray]:
    """Polygon segments of all trimming loops (pcurves sampled densely).

    Returns ``segments (m, 2, 2)`` in ``(u, v)``, the edge (index into
    ``face.edges``) of each ``(m,) int`` and its pcurve parameters at both ends
    ``(m, 2) float``.
    """
    segments, owners, params = [], [], []
    u0, u1, v0, v1 = face.surface.domain
    diagonal = max(np.hypot(u1 - u0, v1 - v0), 1e-300)
    for k, edge in enumerate(face.edges):
        t = np.linspace(edge.t0, edge.t1, EDGE_SAMPLES)
        uv = edge.pcurve.evaluate(t)
        # edges long in the parameter plane get more samples
        rel = np.linalg.norm(np.diff(uv, axis=0), axis=1).sum() / diagonal
        if rel > 0.25:
            t = np.linspace(edge.t0, edge.t1, int(EDGE_SAMPLES * min(16, 4 * rel)))
            uv = edge.pcurve.evaluate(t)
        segments.append(np.stack([uv[:-1], uv[1:]], axis=1))
        owners.append(np.full(t.size - 1, k))
        params.append(np.stack([t[:-1], t[1:]], axis=1))
    if not segments:
        return np.zeros((0, 2, 2)), np.zeros(0, dtype=np.int64), np.zeros((0, 2))
    _join_edge_ends(segments, JOIN_ENDS * diagonal)
    return np.concatenate(segments), np.concatenate(owners), np.concatenate(params)


def _join_edge_ends(segments: list[NDArray], eps: float) -> None:
    """Make the ends of consecutive edges one point (in place): two pcurves meeting at
    a vertex end a rounding error apart (an arc from 3 pi / 2 to 2 pi ends at
    ``v + 1e-16``, the next one starts at ``v``), and a ray at exactly that ``v``
    passes between them and the even-odd count is off by one. Ends within ``eps``
    of each other take the value of the first of them."""
    ends = np.concatenate([[s[0, 0], s[-1, 1]] for s in segments])      # (2 edges, 2)
    first = np.arange(ends.shape[0])
    # scipy on first use: importing it costs 0.3 s
    from scipy.spatial import cKDTree

    for i, j in sorted(cKDTree(ends).query_pairs(eps)):
        first[j] = min(first[j], first[i])
    for k, s in enumerate(segments):
        s[0, 0], s[-1, 1] = ends[first[2 * k]], ends[first[2 * k + 1]]


def is_rectangle(seg: NDArray, domain, eps: float) -> bool:
    """True when every loop segment lies on a side of the parameter rectangle."""
    u0, u1, v0, v1 = domain
    on = lambda x, lo, hi: (np.abs(x - lo) <= eps) | (np.abs(x - hi) <= eps)
    pts = seg.reshape(-1, 2)
    same_u = on(seg[:, 0, 0], u0, u1) & (np.abs(seg[:, 0, 0] - seg[:, 1, 0]) <= eps)
    same_v = on(seg[:, 0, 1], v0, v1) & (np.abs(seg[:, 0, 1] - seg[:, 1, 1]) <= eps)
    return bool(np.all(same_u | same_v) and pts.size)


@dataclass(frozen=True, eq=False)
class SegmentTree:
    """Segments ``start + s vec`` (``s`` in [0, 1]) with a k-d tree of their midpoints,
    built once, for nearest-segment distances of many point batches."""

    start: NDArray
    vec: NDArray
    tree: Any

    @classmethod
    def from_segments(cls, start: NDArray, vec: NDArray) -> SegmentTree:
        from scipy.spatial import cKDTree
        return cls(start, vec, cKDTree(start + 0.5 * vec))

    @classmethod
    def from_polylines(cls, lines: Sequence[NDArray]) -> SegmentTree:
        lines = [np.vstack([q, q]) if q.shape[0] == 1 else q for q in lines]
        return cls.from_segments(np.concatenate([q[:-1] for q in lines]),
                                 np.concatenate([np.diff(q, axis=0) for q in lines]))

    def distance(self, x: NDArray, k: int = 8) -> NDArray:
        """Distance ``(n,)`` from each point ``x (n, dim)`` to the nearest of the ``k``
        segments whose midpoints are nearest (the segments are short and even)."""
        return self.nearest(x, k)[0]

    def nearest(self, x: NDArray, k: int = 8) -> tuple[NDArray, NDArray]:
        """Distance ``(n,)`` and foot point ``(n, dim)`` on the nearest of the ``k``
        segments whose midpoints are nearest each point ``x (n, dim)``."""
        if x.shape[0] == 0:
            return np.zeros(0), np.zeros((0, x.shape[1]))
        k = min(k, self.start.shape[0])
        _, idx = self.tree.query(x, k=k)
        idx = idx.reshape(x.shape[0], k)
        pa, pd = self.start[idx], self.vec[idx]
        dd = np.einsum("nkc,nkc->nk", pd, pd)
        t = np.clip(np.einsum("nkc,nkc->nk", x[:, None] - pa, pd) / np.where(dd > 0, dd, 1.0),
                    0, 1)
        foot = pa + t[..., None] * pd                                   # (n, k, dim)
        dist = np.linalg.norm(foot - x[:, None], axis=-1)
        best = dist.argmin(axis=1)
        rows = np.arange(x.shape[0])
        return dist[rows, best], foot[rows, best]


@dataclass(frozen=True, eq=False)
class LoopIndex:
    """A face's loop segments bucketed by v (for the even-odd ray test) and a
    segment tree in ``(u, v)``, built once per face."""

    a: NDArray                 # (m, 2) segment starts
    b: NDArray                 # (m, 2) segment ends
    lo: float                  # v of the first bucket
    width: float               # bucket height
    bins: int
    seg_sorted: NDArray        # segment indices grouped by bucket
    indptr: NDArray            # (bins + 1,) bucket starts in seg_sorted
    hi: float
    uv_tree: SegmentTree

    @classmethod
    def build(cls, seg: NDArray) -> LoopIndex:
        a, b = np.ascontiguousarray(seg[:, 0]), np.ascontiguousarray(seg[:, 1])
        bins = int(max(1, min(4096, 2 * np.sqrt(seg.shape[0]))))
        vlo, vhi = np.minimum(a[:, 1], b[:, 1]), np.maximum(a[:, 1], b[:, 1])
        lo, hi = float(vlo.min()), float(vhi.max())
        width = (hi - lo) / bins if hi > lo else 1.0
        first = np.clip(((vlo - lo) / width).astype(np.int64), 0, bins - 1)
        last = np.clip(((vhi - lo) / width).astype(np.int64), 0, bins - 1)
        count = last - first + 1
        seg_of = np.repeat(np.arange(seg.shape[0]), count)
        bin_of = np.repeat(first, count) + (np.arange(count.sum())
                                            - np.repeat(np.cumsum(count) - count, count))
        order = np.argsort(bin_of, kind="stable")
        indptr = np.concatenate([[0], np.cumsum(np.bincount(bin_of, minlength=bins))])
        return cls(a, b, lo, width, bins, seg_of[order], indptr, hi,
                   SegmentTree.from_segments(a, b - a))

    def crossings(self, uv: NDArray) -> NDArray:
        """Crossings ``(n,) int`` of a ray in +u from each point with the segments,
        testing only the segments of the point's v-bucket
        (:func:`.face_region_kernels.ray_crossings`, compiled)."""
        return ray_crossings(uv, self.a, self.b, self.lo, self.hi, self.width, self.bins,
                             self.seg_sorted, self.indptr)


def inside_loops(points: NDArray, loops: Sequence[NDArray]) -> NDArray:
    """Even-odd test of parameter points against closed polygons.

    Parameters
    ----------
    points : (m, 2) float
    loops : sequence of (n_k, 2) float
        Closed polygons (the last point joins the first), e.g. samples of a
        face's trimming loops in ``(u, v)``: the outer loop and its holes.
        Polygons of fewer than three points are left out.

    Returns
    -------
    (m,) bool
        Inside an odd number of loops (:meth:`LoopIndex.crossings`).
    """
    points = np.asarray(points, dtype=float)
    edges = [np.stack([lp, np.roll(lp, -1, axis=0)], axis=1)
             for lp in (np.asarray(x, dtype=float) for x in loops) if lp.shape[0] >= 3]
    if not edges:
        return np.zeros(points.shape[0], bool)
    return LoopIndex.build(np.concatenate(edges)).crossings(points) % 2 == 1


@dataclass(frozen=True, eq=False)
class FaceRegion:
    """A trimmed face prepared for point-in-face tests and distances to its boundary.

    Everything is built on first use and kept (the face is immutable).

    Attributes
    ----------
    face : TrimmedFace
    """

    face: TrimmedFace

    @property
    def surface(self) -> NurbsSurface:
        return self.face.surface

    @cached_property
    def _segments(self) -> tuple[NDArray, NDArray, NDArray]:
        return loop_segments(self.face)

    def boundary_segments(self) -> NDArray:
        """``(m, 2, 2)`` segments of the sampled trimming loops in ``(u, v)``."""
        return self._segments[0]

    def segment_edges(self) -> tuple[NDArray, NDArray]:
        """Edge index ``(m,)`` (into ``face.edges``) and pcurve parameters ``(m, 2)``
        of each boundary segment."""
        return self._segments[1], self._segments[2]

    @cached_property
    def _polylines(self) -> list[NDArray]:
        lines = []
        for edge in self.face.edges:
            uv = edge.pcurve.evaluate(np.linspace(edge.t0, edge.t1, 2 * EDGE_SAMPLES))
            lines.append(self.surface.evaluate(uv[:, 0], uv[:, 1]))
        return lines

    def boundary_polylines(self) -> list[NDArray]:
        """Samples ``(k, 3)`` in space of every trimming edge, one polyline each."""
        return self._polylines

    @cached_property
    def boundary_sag(self) -> float:
        """A hundredth of the longest chord of :meth:`boundary_polylines`: how far the
        polylines may stray from the edges they sample."""
        return 0.01 * max(float(np.linalg.norm(np.diff(p, axis=0), axis=1).max(initial=0.0))
                          for p in self._polylines)

    def edge_tolerance(self) -> float:
        """The largest edge tolerance of the face's trimming edges (0 without edges)."""
        return max((e.tolerance for e in self.face.edges), default=0.0)

    @cached_property
    def _loop_index(self) -> LoopIndex | None:
        seg = self.boundary_segments()
        u0, u1, v0, v1 = self.surface.domain
        eps = ON_BOUNDARY * np.hypot(u1 - u0, v1 - v0)
        rect = seg.shape[0] == 0 or is_rectangle(seg, self.surface.domain, 1e3 * eps)
        return None if rect else LoopIndex.build(seg)

    def loop_index(self) -> LoopIndex | None:
        """The trimming loops bucketed for the ray test (None: the face is its rectangle)."""
        return self._loop_index

    @cached_property
    def _loop_tree(self) -> SegmentTree | None:
        index = self.loop_index()
        if index is not None:
            return index.uv_tree
        seg = self.boundary_segments()
        return SegmentTree.from_segments(seg[:, 0], seg[:, 1] - seg[:, 0]) if seg.shape[0] else None

    def loop_tree(self) -> SegmentTree | None:
        """Segment tree of the loop polygon in ``(u, v)`` (the loop index's own when the
        face has one; None without loops)."""
        return self._loop_tree

    @cached_property
    def _edge_tree(self) -> SegmentTree | None:
        lines = self.boundary_polylines()
        return SegmentTree.from_polylines(lines) if lines else None

    def edge_distance(self, points: NDArray) -> NDArray:
        """Distance ``(n,)`` of ``points (n, 3)`` to the sampled trimming edges in space
        (:meth:`boundary_polylines`)."""
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        tree = self._edge_tree
        return np.full(points.shape[0], np.inf) if tree is None else tree.distance(points)

    def contains(self, uv: NDArray, tol: float = 0.0) -> NDArray:
        """``(n,) bool``: which ``uv (n, 2)`` lie inside the face (module docstring).

        Even-odd rule on the sampled loops; points within ``ON_BOUNDARY`` times the
        domain diagonal of a loop count as inside, and so do points whose image lies
        within ``tol`` plus twice the face's largest edge tolerance of a trimming
        edge in space (tested only for points within ``NEAR_BOUNDARY`` times the
        diagonal of a loop in ``(u, v)``). A face without loops, or whose loops run
        along its parameter rectangle, is the rectangle.
        """
        uv = np.asarray(uv, dtype=float).reshape(-1, 2)
        u0, u1, v0, v1 = self.surface.domain
        eps = ON_BOUNDARY * np.hypot(u1 - u0, v1 - v0)
        in_box = ((uv[:, 0] >= u0 - eps) & (uv[:, 0] <= u1 + eps) & (uv[:, 1] >= v0 - eps)
                  & (uv[:, 1] <= v1 + eps))
        index = self.loop_index()
        if index is None:
            return in_box
        odd = index.crossings(uv) % 2 == 1
        inside = in_box & odd
        # the distance to the loops is needed only for the points outside by the ray test
        test = np.flatnonzero(in_box & ~odd)
        if test.size:
            near = index.uv_tree.distance(uv[test])
            inside[test] = near <= eps
            if tol > 0:
                # close to a loop in (u, v): measure in space against the trimming edges
                band = test[(near > eps) & (near <= NEAR_BOUNDARY * np.hypot(u1 - u0, v1 - v0))]
                if band.size:
                    p = self.surface.evaluate(uv[band, 0], uv[band, 1])
                    limit = tol + 2.0 * self.edge_tolerance()
                    inside[band] = self.edge_distance(p) <= limit
        return inside
