"""Trimming loops of a face prepared for fast point-in-face tests (used by
:func:`surfprep.plugin.intersect_operands.inside_face`).

* :func:`loop_segments`: every trimming edge's pcurve sampled into polygon
  segments in ``(u, v)`` (``EDGE_SAMPLES`` per edge, more for edges long in the
  parameter plane), with the edge and pcurve parameters of each segment;
* :class:`LoopIndex`: the segments bucketed by v for the even-odd ray test and a
  k-d tree of them for distances, built once per face;
* :class:`SegmentTree`: nearest-segment distances of many point batches
  (``(u, v)`` or space) against segments fixed once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..algorithms.loop_kernels import ray_crossings
from .faces import TrimmedFace

__all__ = ["EDGE_SAMPLES", "LoopIndex", "SegmentTree", "is_rectangle", "loop_segments"]

#: samples per trimming edge for the point-in-face test
EDGE_SAMPLES = 64


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
    return np.concatenate(segments), np.concatenate(owners), np.concatenate(params)


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
        (:func:`surfprep.algorithms.loop_kernels.ray_crossings`, compiled)."""
        return ray_crossings(uv, self.a, self.b, self.lo, self.hi, self.width, self.bins,
                             self.seg_sorted, self.indptr)
