"""Adjacency of the faces to heal: which faces are four-sided, which edges are free,
which free loops are four-sided holes, which faces duplicate others (001 §8).

Edges are compared in space, by samples of their 3D curves: two edges of
different faces are *paired* when every sample of each lies within ``gap_tol``
of the other's polyline. An edge paired with none is *free*. Free edges whose
ends meet (within ``gap_tol``) form loops; a loop of exactly four edges taken
from at least two faces is a hole to fill (a loop of one face's own four edges
is that face's open border, not a hole). The OpenCascade side of the result
(sewing, free edges of a shape, validity) is :mod:`surfprep.plugin.occ.shapes`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from ..curve import NurbsCurve
from ..projection import distance_to_curve, distance_to_surface
from ..trimmed import TrimmedFace

__all__ = [
    "EDGE_SAMPLES",
    "FaceEdge",
    "box_pairs",
    "dense_edge",
    "duplicate_faces",
    "edge_positions",
    "face_edges",
    "four_sided_boundary",
    "hole_loops",
    "pair_edges",
    "pair_gaps",
    "polyline_distance",
]

#: samples per edge for the pairing test
EDGE_SAMPLES = 17
#: an edge using less of its 3D curve than the whole by this share of its domain uses part
_PART = 1e-9
_PAIR_CHUNK = 128             # edge pairs per batch of the pairing test


@dataclass(frozen=True, eq=False)
class FaceEdge:
    """One edge of one face: ``face`` index, position ``k`` in its outer loop (an inner
    loop's edges count from -1 down), the 3D curve and its samples ``(EDGE_SAMPLES, 3)``."""

    face: int
    k: int
    curve: NurbsCurve
    samples: NDArray

    @property
    def ends(self) -> NDArray:
        return self.samples[[0, -1]]


def four_sided_boundary(face: TrimmedFace) -> list[NurbsCurve] | None:
    """The four 3D edge curves of a face bounded by one loop of four real edges, else None."""
    if len(face.loops) != 1 or len(face.loops[0].edges) != 4:
        return None
    edges = face.loops[0].edges
    if any(e.degenerated or e.curve3d is None or e.is_seam for e in edges):
        return None
    return [e.curve3d for e in edges]


def face_edges(faces: list[TrimmedFace | None]) -> list[FaceEdge]:
    """Every real edge of the faces' loops, sampled: the outer loop's (``k`` its position
    there), then the inner loops' (``k`` counting from -1 down, as
    :func:`surfprep.plugin.heal.cut.inner_edges`).

    The inner loops count: the walls of a slot through a face meet that face along
    its inner loop (occt_cornetta.stp, occt_k1_alias.stp). Left out, the walls' edges
    looked free, chained into a four-sided "hole" at the slot's mouth, and its patch
    put a third face on each of those edges. An edge using part of its 3D curve (the
    pieces of a face split along a cut) is sampled over that part, its curve restricted
    to it."""
    out = []
    for i, face in enumerate(faces):
        if face is None or not face.loops:
            continue
        outer = face.loops[face.outer_loop_index].edges
        inner = [e for n, loop in enumerate(face.loops) if n != face.outer_loop_index
                 for e in loop.edges]
        numbered = list(enumerate(outer)) + [(-1 - n, e) for n, e in enumerate(inner)]
        for k, e in numbered:
            if e.degenerated or e.curve3d is None or e.is_seam:
                continue
            curve = e.curve3d
            lo, hi = curve.domain
            t0, t1 = max(e.t0, lo), min(e.t1, hi)
            if max(t0 - lo, hi - t1) > _PART * (hi - lo):   # part of its curve (a split face)
                curve = curve.restrict(t0, t1)
            else:
                t0, t1 = lo, hi
            out.append(FaceEdge(i, k, curve, curve.evaluate(np.linspace(t0, t1, EDGE_SAMPLES))))
    return out


def edge_positions(face: TrimmedFace) -> dict[int, tuple[int, int]]:
    """``FaceEdge.k`` -> ``(loop index, position in the loop)`` for every edge of ``face``
    (the numbering of :func:`face_edges`: the outer loop's from 0, the inner loops'
    from -1 down)."""
    out = {p: (face.outer_loop_index, p)
           for p in range(len(face.loops[face.outer_loop_index].edges))}
    k = -1
    for n, loop in enumerate(face.loops):
        if n == face.outer_loop_index:
            continue
        for p in range(len(loop.edges)):
            out[k] = (n, p)
            k -= 1
    return out


def polyline_distance(points: NDArray, line: NDArray) -> NDArray:
    a, b = line[:-1], line[1:]
    ab = b - a
    denom = np.maximum(np.einsum("kc,kc->k", ab, ab), np.finfo(float).tiny)
    t = np.clip(np.einsum("mkc,kc->mk", points[:, None] - a[None], ab) / denom, 0.0, 1.0)
    return np.min(np.linalg.norm(points[:, None] - (a[None] + t[..., None] * ab[None]), axis=2),
                  axis=1)


def dense_edge(edge: FaceEdge, n: int = 129) -> NDArray:
    t0, t1 = edge.curve.domain
    return edge.curve.evaluate(np.linspace(t0, t1, n))


def _polyline_distances(points: NDArray, lines: NDArray) -> NDArray:
    """Batched :func:`polyline_distance`: points ``(P, k, 3)`` to polylines ``(P, L, 3)``,
    pair by pair; returns ``(P, k)``."""
    a, ab = lines[:, :-1], np.diff(lines, axis=1)                     # (P, L-1, 3)
    denom = np.maximum(np.einsum("psc,psc->ps", ab, ab), np.finfo(float).tiny)
    rel = points[:, :, None] - a[:, None]                              # (P, k, L-1, 3)
    t = np.clip(np.einsum("pksc,psc->pks", rel, ab) / denom[:, None], 0.0, 1.0)
    off = rel - t[..., None] * ab[:, None]
    return np.sqrt(np.min(np.einsum("pksc,pksc->pks", off, off), axis=2))


def _pairs_within(samples: NDArray, dense: NDArray, i: NDArray, j: NDArray, gap_tol: float
                  ) -> NDArray:
    """(len(i),) bool: samples of edge ``i`` all within ``gap_tol`` of edge ``j``'s polyline."""
    out = np.zeros(i.size, bool)
    for start in range(0, i.size, _PAIR_CHUNK):
        sl = slice(start, start + _PAIR_CHUNK)
        out[sl] = _polyline_distances(samples[i[sl]], dense[j[sl]]).max(axis=1) <= gap_tol
    return out


def pair_edges(edges: list[FaceEdge], gap_tol: float) -> list[tuple[int, int]]:
    """Index pairs of edges of different faces lying on each other within ``gap_tol``.

    Candidates are the pairs of overlapping boxes (grown by ``gap_tol``); each is
    tested first at the two ends and the middle of both edges, then at all
    samples of each edge against the other's dense polyline, in batches."""
    if not edges:
        return []
    samples = np.stack([e.samples for e in edges])                     # (n, k, 3)
    lo, hi = samples.min(axis=1) - gap_tol, samples.max(axis=1) + gap_tol
    face = np.array([e.face for e in edges])
    i, j = box_pairs(lo, hi)
    keep = face[i] != face[j]
    i, j = i[keep], j[keep]
    if i.size == 0:
        return []
    dense = np.stack([dense_edge(e) for e in edges])                 # (n, 129, 3)
    probe = samples[:, [0, samples.shape[1] // 2, -1]]
    keep = _pairs_within(probe, dense, i, j, gap_tol) & _pairs_within(probe, dense, j, i, gap_tol)
    i, j = i[keep], j[keep]
    keep = _pairs_within(samples, dense, i, j, gap_tol) & _pairs_within(samples, dense, j, i,
                                                                         gap_tol)
    return [(int(a), int(b)) for a, b in zip(i[keep], j[keep])]


def pair_gaps(edges: list[FaceEdge], pairs: list[tuple[int, int]]) -> NDArray:
    """``(len(pairs),)``: the largest distance between the two edges of each pair, both
    ways, from each edge's samples to the other's 3D curve by closest-point projection
    (exact: the polyline of :func:`pair_edges` is off the curve by its chord sag)."""
    out = np.zeros(len(pairs))
    for n, (a, b) in enumerate(pairs):
        out[n] = max(distance_to_curve(edges[b].curve, edges[a].samples).max(),
                     distance_to_curve(edges[a].curve, edges[b].samples).max())
    return out


def box_pairs(lo: NDArray, hi: NDArray) -> tuple[NDArray, NDArray]:
    """Index pairs ``i < j`` of overlapping boxes ``(n, 3)``, row by row (as
    ``nonzero(triu(overlap, 1))``), the overlap matrix built in row blocks."""
    out_i, out_j = [], []
    for start in range(0, lo.shape[0], _PAIR_CHUNK):
        rows = slice(start, start + _PAIR_CHUNK)
        overlap = np.all((lo[rows, None] <= hi[None]) & (lo[None] <= hi[rows, None]), axis=2)
        r, c = np.nonzero(overlap)
        r = r + start
        keep = c > r
        out_i.append(r[keep])
        out_j.append(c[keep])
    return np.concatenate(out_i), np.concatenate(out_j)


def hole_loops(edges: list[FaceEdge], free: list[int], gap_tol: float, *,
               min_faces: int = 2) -> list[list[FaceEdge]]:
    """Loops of free edges from at least ``min_faces`` faces (any number of edges up to
    64, or one edge closed on itself), in loop order: where every end on the loop meets
    exactly one other free edge's end within ``gap_tol``."""
    if not free:
        return []
    ends = np.concatenate([edges[k].ends for k in free])          # (2 f, 3)
    parent = np.arange(ends.shape[0])

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for x, y in cKDTree(ends).query_pairs(gap_tol):
        parent[find(x)] = find(y)
    vertex = np.array([find(x) for x in range(ends.shape[0])]).reshape(-1, 2)
    incident: dict[int, list[int]] = {}
    for n, (v0, v1) in enumerate(vertex):
        incident.setdefault(int(v0), []).append(n)
        incident.setdefault(int(v1), []).append(n)
    loops, seen = [], set()
    for start in range(len(free)):
        if start in seen:
            continue
        loop = _walk(start, vertex, incident)
        seen.update(loop or [start])
        if loop and len({edges[free[n]].face for n in loop}) >= min_faces:
            loops.append([edges[free[n]] for n in loop])
    return loops


def _walk(start: int, vertex: NDArray, incident: dict[int, list[int]]) -> list[int] | None:
    """The cycle through edge ``start`` when every vertex on it has two free edges."""
    loop, current, at = [start], start, int(vertex[start, 1])
    while True:
        nxt = [n for n in incident[at] if n != current]
        if len(incident[at]) != 2:
            return None
        if not nxt:                     # one edge closed on itself (a tube's rim)
            return loop if vertex[start, 0] == vertex[start, 1] else None
        current = nxt[0]
        if current == start:
            return loop
        if current in loop or len(loop) > 64:
            return None
        loop.append(current)
        v0, v1 = int(vertex[current, 0]), int(vertex[current, 1])
        at = v1 if v0 == at else v0


def duplicate_faces(faces: list[TrimmedFace | None], edges: list[FaceEdge],
                    pairs: list[tuple[int, int]], gap_tol: float) -> list[tuple[int, int]]:
    """``(kept, dropped)`` face pairs where one face lies on the other within ``gap_tol``:
    every edge of the dropped face pairs with an edge of the kept one and
    points spread over the dropped face's surface lie on the kept surface."""
    by_face: dict[int, list[int]] = {}
    for n, e in enumerate(edges):
        by_face.setdefault(e.face, []).append(n)
    partners: dict[tuple[int, int], set[int]] = {}
    for i, j in pairs:
        a, b = edges[i].face, edges[j].face
        partners.setdefault((a, b), set()).add(i)
        partners.setdefault((b, a), set()).add(j)
    out, dropped = [], set()
    for (a, b), covered in sorted(partners.items()):
        if a >= b or a in dropped or b in dropped:
            continue
        if len(covered) < len(by_face[a]) or len(partners.get((b, a), ())) < len(by_face[b]):
            continue
        if _lies_on(faces[b], faces[a], gap_tol):
            out.append((a, b))
            dropped.add(b)
    return out


def _lies_on(face: TrimmedFace, other: TrimmedFace, gap_tol: float) -> bool:
    u0, u1, v0, v1 = face.surface.domain
    t = np.linspace(0.2, 0.8, 4)
    pts = face.surface.evaluate_grid(u0 + t * (u1 - u0), v0 + t * (v1 - v0)).reshape(-1, 3)
    return bool(distance_to_surface(other.surface, pts).max() <= gap_tol)
