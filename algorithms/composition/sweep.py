"""Intersection segments of two local triangulations (004 §5): the kd-tree sweep that finds
the triangle pairs, and the merging of segments into bidirectional lists.

Candidate pairs (004 §4.4, §5)
------------------------------
A kd-tree is built over the *vertices* of the first triangulation. The triangles of
the second are queued along the longest axis of their overlap box (the sweep) and
each one's box is searched in the tree: every vertex of a first-side triangle whose
box meets it lies within that box widened by the largest triangle extent of the first
side, so an ``L_inf`` ball query around the box centre finds them all. The triangles
of the vertices hit (a vertex-to-triangle table: 004's "lightweight vertex-based
structure") are then tested box against box. :func:`sweep_pairs` returns exactly the
pairs whose boxes overlap -- the same set as the box-tree descent of
:func:`surfprep.algorithms.intersection.culling.candidate_pairs`, which
``benchmarks/compose.py`` measures it against.

Bidirectional lists (004 §5)
----------------------------
Segments of one triangulation pair share their end points bitwise where they meet
(an edge's crossing point is computed the same way from both triangles, see
:mod:`surfprep.algorithms.intersection.triangles`) and run the same way (along
``n_a x n_b``). :func:`link_segments` gives every segment its successor and
predecessor (``next`` / ``prev``, -1 at a hanging end) and reads the chains off them:
open chains from their first segment, closed loops from what is left.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["Chains", "link_segments", "sweep_pairs", "triangle_boxes"]


def triangle_boxes(vertices: NDArray, triangles: NDArray) -> NDArray:
    """``(m, 2, 3)`` axis-aligned boxes of triangles ``(m, 3)`` over ``vertices (n, 3)``."""
    corners = vertices[triangles]
    return np.stack([corners.min(axis=1), corners.max(axis=1)], axis=1)


def _vertex_triangles(triangles: NDArray, n_vertices: int) -> tuple[NDArray, NDArray]:
    """CSR table vertex -> triangles using it: ``(starts (n + 1,), triangle ids)``."""
    flat = triangles.ravel()
    order = np.argsort(flat, kind="stable")
    starts = np.searchsorted(flat[order], np.arange(n_vertices + 1))
    return starts, order // 3


def sweep_pairs(vertices_1: NDArray, triangles_1: NDArray, boxes_2: NDArray, *,
                pad: float = 0.0) -> NDArray:
    """Pairs of overlapping triangle boxes by a kd-tree over the vertices of side 1 and a
    sweep over the boxes of side 2 (the module doc).

    Parameters
    ----------
    vertices_1 : (n, 3) float
    triangles_1 : (m, 3) int
    boxes_2 : (k, 2, 3) float
        The boxes of the second side's triangles.
    pad : float >= 0
        Boxes overlap when their gap is at most ``pad`` on every axis.

    Returns
    -------
    (p, 2) int
        ``(triangle of side 1, triangle of side 2)``, sorted lexicographically.
    """
    from scipy.spatial import cKDTree
    if triangles_1.shape[0] == 0 or boxes_2.shape[0] == 0:
        return np.zeros((0, 2), dtype=np.int64)
    boxes_1 = triangle_boxes(vertices_1, triangles_1)
    reach = np.max(boxes_1[:, 1] - boxes_1[:, 0], axis=0) + pad          # (3,)
    axis = int(np.argmax(boxes_2[:, 1].max(axis=0) - boxes_2[:, 0].min(axis=0)))
    queue = np.argsort(0.5 * (boxes_2[:, 0, axis] + boxes_2[:, 1, axis]), kind="stable")
    centre = 0.5 * (boxes_2[queue, 0] + boxes_2[queue, 1])
    radius = np.max(0.5 * (boxes_2[queue, 1] - boxes_2[queue, 0]) + reach, axis=1)
    hits = cKDTree(vertices_1).query_ball_point(centre, radius, p=np.inf)
    counts = np.fromiter((len(h) for h in hits), dtype=np.int64, count=len(hits))
    if counts.sum() == 0:
        return np.zeros((0, 2), dtype=np.int64)
    vertex = np.concatenate([np.asarray(h, dtype=np.int64) for h in hits if h])
    tri_2 = np.repeat(queue, counts)
    starts, tri_of = _vertex_triangles(triangles_1, vertices_1.shape[0])
    uses = starts[vertex + 1] - starts[vertex]
    first = np.repeat(starts[vertex], uses)
    offset = np.arange(uses.sum()) - np.repeat(np.cumsum(uses) - uses, uses)
    tri_1 = tri_of[first + offset]
    tri_2 = np.repeat(tri_2, uses)
    key = np.unique(tri_1 * boxes_2.shape[0] + tri_2)
    tri_1, tri_2 = np.divmod(key, boxes_2.shape[0])
    a, b = boxes_1[tri_1], boxes_2[tri_2]
    meet = np.all((a[:, 0] - pad <= b[:, 1]) & (b[:, 0] - pad <= a[:, 1]), axis=1)
    return np.stack([tri_1[meet], tri_2[meet]], axis=1)


def _row_keys(points: NDArray) -> NDArray:
    """One integer per row of ``points (n, 3)``, equal where the rows are bitwise equal."""
    rows = np.ascontiguousarray(points, dtype=np.float64) + 0.0          # -0.0 -> 0.0
    return np.unique(rows.view(np.dtype((np.void, 24))).ravel(), return_inverse=True)[1]


@dataclass(frozen=True)
class Chains:
    """Segments merged into bidirectional lists.

    Attributes
    ----------
    next, prev : (s,) int
        Successor / predecessor of each segment (-1: a hanging end).
    chains : tuple of (k,) int
        The segments of each chain in order.
    closed : (c,) bool
        Whether each chain is a closed loop.
    """

    next: NDArray
    prev: NDArray
    chains: tuple
    closed: NDArray


def link_segments(segments: NDArray) -> Chains:
    """Merge segments ``(s, 2, 3)`` that run the same way into chains (the module doc).

    Where more than one segment starts at a segment's end point (a branch), the
    segment's successor is left open (-1): chains break there.
    """
    s = segments.shape[0]
    if s == 0:
        empty = np.zeros(0, dtype=np.int64)
        return Chains(empty, empty, (), np.zeros(0, dtype=bool))
    keys = _row_keys(segments.reshape(-1, 3)).reshape(s, 2)
    start, end = keys[:, 0], keys[:, 1]
    n_keys = int(keys.max()) + 1
    starting = np.bincount(start, minlength=n_keys)
    ending = np.bincount(end, minlength=n_keys)
    owner = np.full(n_keys, -1, dtype=np.int64)
    owner[start] = np.arange(s)
    single = (starting[end] == 1) & (ending[end] == 1) & (start != end)
    nxt = np.where(single, owner[end], -1)
    prev = np.full(s, -1, dtype=np.int64)
    prev[nxt[nxt >= 0]] = np.flatnonzero(nxt >= 0)
    chains, closed, seen = [], [], np.zeros(s, dtype=bool)
    for head in list(np.flatnonzero(prev < 0)) + list(range(s)):
        if seen[head]:
            continue
        order, k = [], head
        while k >= 0 and not seen[k]:
            seen[k] = True
            order.append(k)
            k = nxt[k]
        chains.append(np.asarray(order, dtype=np.int64))
        closed.append(bool(k == head))
    return Chains(nxt, prev, tuple(chains), np.asarray(closed, dtype=bool))
