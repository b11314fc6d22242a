"""Cuts: curves to cut a trimmed face along (:func:`.face_split.split_face`), and which of
them divide it.

A :class:`Cut` is a curve in a face's ``(u, v)`` with its 3D curve when known. Before a
face is cut, the cuts that divide nothing are left out: a cut running along the face's
boundary (two faces of one model meeting another along their shared edge, two solids
touching; the loop's edge is split where such a cut ends inside it:
:func:`split_where_cuts_end`) and a cut repeating another (the same curve reported
twice); and a cut ending a tolerance away from a corner of the face's loop is moved onto the corner, so
no sliver of the edge is left.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidGeometryError
from .curve import NurbsCurve
from .face_region import FaceRegion
from .trimmed import LOOP_SAMPLES_PER_EDGE, TrimEdge, TrimLoop, TrimmedFace, curve3d_points

__all__ = ["CUT_SAMPLES", "Cut", "cut_point_at", "distinct_cuts", "locate_on_loops", "near_in_space",
           "parts_along_boundary", "snap_to_corner", "split_where_cuts_end"]

#: samples of a cut's pcurve for the topology (crossings, containment)
CUT_SAMPLES = 257


@dataclass(frozen=True, eq=False)
class Cut:
    """A curve to cut a face along.

    Attributes
    ----------
    pcurve : NurbsCurve (2D)
        The curve in the face's ``(u, v)``, over its whole domain.
    curve3d : NurbsCurve (3D) or None
        The same curve in space, on the same parameter.
    """

    pcurve: NurbsCurve
    curve3d: NurbsCurve | None = None

    def __post_init__(self) -> None:
        if self.pcurve.dimension != 2:
            raise InvalidGeometryError(f"a cut's pcurve must be 2D, got dimension {self.pcurve.dimension}")
        if self.curve3d is not None and self.curve3d.dimension != 3:
            raise InvalidGeometryError("a cut's 3D curve must be 3D")

    @property
    def range(self) -> tuple[float, float]:
        return self.pcurve.domain

    def samples(self) -> NDArray:
        t0, t1 = self.range
        return self.pcurve.evaluate(np.linspace(t0, t1, CUT_SAMPLES))


def cut_point_at(cut: Cut, face: TrimmedFace, t: float) -> NDArray:
    """The cut's point in space at its parameter ``t``."""
    if cut.curve3d is not None:
        return cut.curve3d.evaluate(np.array([t]))[0]
    uv = cut.pcurve.evaluate(np.array([t]))
    return face.surface.evaluate(uv[:, 0], uv[:, 1])[0]


def snap_to_corner(edge: TrimEdge, surface, t: float, eps: float, tol3d: float | None) -> float:
    """``t`` moved to the edge's end when its point lies that close to it (within ``tol3d``
    in space, else ``eps`` in the parameters): a cut ending at a corner of the loop,
    found a tolerance away from it, would leave a sliver of the edge."""
    ends = np.array([edge.t0, edge.t1])
    if tol3d is not None:
        pts = curve3d_points(edge, surface, np.array([t, edge.t0, edge.t1]))
        near, limit = np.linalg.norm(pts[1:] - pts[0], axis=1), tol3d
    else:
        uv = edge.pcurve.evaluate(np.array([t, edge.t0, edge.t1]))
        near, limit = np.linalg.norm(uv[1:] - uv[0], axis=1), eps
    k = int(np.argmin(near))
    return float(ends[k]) if near[k] <= limit else t


def distinct_cuts(cuts: list[Cut], face: TrimmedFace, eps: float, tol3d: float | None) -> list[Cut]:
    """The cuts without repeats: a cut whose every sample lies within ``tol3d`` in space
    (``eps`` in the parameters) of a cut kept before it is the same curve found twice
    (as an intersection can report it from two methods or two passes) and is left out."""
    kept: list[tuple[Cut, NDArray]] = []
    for cut in cuts:
        uv = cut.samples()
        points = (face.surface.evaluate(uv[:, 0], uv[:, 1]) if tol3d is not None else uv)
        limit = tol3d if tol3d is not None else eps
        same = False
        for _, other in kept:
            ends = min(np.linalg.norm(points[[0, -1]] - other[[0, -1]], axis=1).max(),
                       np.linalg.norm(points[[0, -1]] - other[[-1, 0]], axis=1).max())
            if ends > limit:
                continue
            gaps = np.min(np.linalg.norm(points[::16, None] - other[None], axis=2), axis=1)
            if np.all(gaps <= limit + _chord(other)):
                same = True
                break
        if not same:
            kept.append((cut, points))
    return [cut for cut, _ in kept]


def locate_on_loops(loops: list[TrimLoop], point: NDArray, eps: float,
            near=lambda best: False) -> tuple[int, int, float] | None:
    """The loop, edge and edge parameter nearest to a point of the domain: within ``eps``
    in the parameters, or where ``near(best)`` accepts it (a test in space)."""
    best = None
    coarse = []                                   # per edge: samples, nearest one, its distance
    for li, loop in enumerate(loops):
        for ei, e in enumerate(loop.edges):
            t = np.linspace(e.t0, e.t1, 4 * LOOP_SAMPLES_PER_EDGE)
            uv = e.pcurve.evaluate(t)
            d = np.linalg.norm(uv - point, axis=1)
            k = int(np.argmin(d))
            # the nearest point lies within a sample spacing of the nearest sample
            reach = float(np.max(np.linalg.norm(np.diff(uv, axis=0), axis=1))) if t.size > 1 else 0.0
            coarse.append((li, ei, e, t, k, float(d[k]), reach))
    closest = min(c[5] for c in coarse) if coarse else np.inf
    for li, ei, e, t, k, d_k, reach in coarse:
        if d_k - reach > closest:
            continue                              # no point of this edge can be the nearest
        # refine on the segment either side by ternary search of the distance
        lo, hi = t[max(k - 1, 0)], t[min(k + 1, t.size - 1)]
        bracket = (lo, hi)
        for _ in range(40):
            m = np.array([lo + (hi - lo) / 3, hi - (hi - lo) / 3])
            d1, d2 = np.linalg.norm(e.pcurve.evaluate(m) - point, axis=1)
            lo, hi = (lo, m[1]) if d1 < d2 else (m[0], hi)
        tt = 0.5 * (lo + hi)
        # then Newton on |c(t) - p|^2 to the rounding (the search stops ~1e-10 of the span
        # short), kept if it is no farther
        dist = float(np.linalg.norm(e.pcurve.evaluate(np.array([tt]))[0] - point))
        for _ in range(3):
            c = e.pcurve.derivatives(np.array([tt]), 2)[0]
            r = c[0] - point
            slope = float(c[1] @ c[1] + r @ c[2])
            if slope <= 0.0:
                break
            trial = float(np.clip(tt - float(r @ c[1]) / slope, *bracket))
            d_trial = float(np.linalg.norm(e.pcurve.evaluate(np.array([trial]))[0] - point))
            if d_trial > dist:
                break
            tt, dist = trial, d_trial
        if best is None or dist < best[3]:
            best = (li, ei, tt, dist)
    if best is None or best[3] > eps and not near(best):
        return None
    return best[0], best[1], best[2]


def near_in_space(face: TrimmedFace, loops: list[TrimLoop], cut: Cut, end: int, tol3d: float | None):
    """A test that a boundary point found for a cut's end lies within ``tol3d`` of it in space."""
    if tol3d is None:
        return lambda best: False
    point = cut_point_at(cut, face, cut.range[end])

    def near(best) -> bool:
        edge = loops[best[0]].edges[best[1]]
        return float(np.linalg.norm(curve3d_points(edge, face.surface, np.array([best[2]]))[0] - point)) <= tol3d

    return near


def split_where_cuts_end(face: TrimmedFace, loops: list[TrimLoop], cuts: list[Cut], eps: float,
                         tol3d: float | None, others: list[Cut] = ()) -> list[TrimLoop]:
    """``loops`` with their edges split where ``cuts`` (cuts running along the boundary)
    end inside an edge rather than at a corner: where a face of another solid touches
    this one along part of an edge, the edge's piece beside it is then an edge of its
    own, which the other face's edge can share (a T-junction otherwise). An end within
    ``tol3d`` of an end of ``others`` (the cuts across the face) is left to that cut,
    which splits the loop there itself: two splits a tolerance apart would leave a
    sliver."""
    loops = list(loops)
    taken = np.array([cut_point_at(c, face, t) for c in others for t in c.range]).reshape(-1, 3)
    for cut in cuts:
        line = cut.samples()
        for end, point in ((0, line[0]), (1, line[-1])):
            if tol3d is not None and taken.size and np.min(np.linalg.norm(
                    taken - cut_point_at(cut, face, cut.range[end]), axis=1)) <= tol3d:
                continue
            where = locate_on_loops(loops, point, eps, near_in_space(face, loops, cut, end, tol3d))
            if where is None:
                continue
            li, ei, t = where
            edge = loops[li].edges[ei]
            if edge.degenerated or snap_to_corner(edge, face.surface, t, eps, tol3d) in (edge.t0, edge.t1):
                continue
            first = TrimEdge(edge.curve3d, edge.pcurve, edge.t0, t, edge.reversed, edge.tolerance,
                             edge.seam_pcurve, False, edge.vertex_tolerances)
            second = TrimEdge(edge.curve3d, edge.pcurve, t, edge.t1, edge.reversed, edge.tolerance,
                              edge.seam_pcurve, False, edge.vertex_tolerances)
            pair = (second, first) if edge.reversed else (first, second)
            edges = loops[li].edges
            loops[li] = TrimLoop(edges[:ei] + pair + edges[ei + 1:])
    return loops


def _chord(points: NDArray) -> float:
    """Half the longest step between consecutive samples: how far a point of the curve can
    lie from the nearest sample."""
    return 0.5 * float(np.max(np.linalg.norm(np.diff(points, axis=0), axis=1))) if len(points) > 1 else 0.0


def parts_along_boundary(face: TrimmedFace, loops: list[TrimLoop], cut: Cut, eps: float,
                         tol3d: float | None) -> tuple[list[Cut], list[Cut]]:
    """A cut split into its stretches along the face's boundary and across the face:
    ``(along, across)``. A curve of another solid's face can run along this face's
    trimming edge for part of its length and then leave it into the face (where faces
    of a fused result meet at a reflex corner): the part along divides nothing, the
    part across does. Near the boundary means within ``tol3d`` in space (``eps`` in
    the parameters) on :data:`CUT_SAMPLES` samples; a stretch of two samples or fewer near
    it, or no longer than twice that distance, counts as across (a curve crossing the
    boundary, steeply or at a shallow angle), a gap of two or fewer between
    stretches near it as near (a chord of the sampled loops), and a change between the
    two is found to 1e-12 of the range by bisection. A short stretch near the boundary
    inside the cut is a tangential touch (a cylinder's circle inscribed in a square
    face): the cut is split at the point nearest the boundary, so each piece runs from
    the boundary to the boundary (the touch is a vertex of the face's loop)."""
    region = FaceRegion(TrimmedFace(face.surface, tuple(loops), 0, face.reversed))
    t0, t1 = cut.range
    t = np.linspace(t0, t1, CUT_SAMPLES)
    limit = tol3d if tol3d is not None else eps

    def points_at(ts: NDArray) -> NDArray:
        """The cut's points in space (with ``tol3d``) or in the parameters."""
        if tol3d is None:
            return cut.pcurve.evaluate(ts)
        return (cut.curve3d.evaluate(ts) if cut.curve3d is not None
                else face.surface.evaluate(*cut.pcurve.evaluate(ts).T))

    def distance_of(points: NDArray) -> NDArray:
        if tol3d is not None:
            return region.edge_distance(points)
        index = region.loop_index()
        if index is not None:
            return index.uv_tree.distance(points)
        u0, u1, v0, v1 = face.surface.domain
        return np.min(np.abs(np.stack([points[:, 0] - u0, points[:, 0] - u1, points[:, 1] - v0,
                                       points[:, 1] - v1])), axis=0)

    def distance(ts: NDArray) -> NDArray:
        return distance_of(points_at(ts))
    points = points_at(t)
    on = distance_of(points) <= limit
    touches = []
    for value in (True, False):                   # short stretches of either kind count with their neighbours
        edges = np.diff(np.concatenate([[0], (on != value).astype(np.int8), [0]]))
        for lo, hi in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
            short = hi - lo <= 2 and (not value or (lo > 0 and hi < on.size))
            shallow = (value is False and hi - lo < on.size
                       and np.linalg.norm(points[hi - 1] - points[lo]) <= 2.0 * limit)
            if short or shallow:
                on[lo:hi] = value
                if value is False and lo > 0 and hi < on.size:
                    touches.append(_nearest_boundary(distance, t[lo - 1], t[hi]))
    if not on.any() and not touches:
        return [], [cut]
    if on.all():
        return [cut], []
    # the parameters where the kind changes, refined by bisection, and the touches
    change = [t0, *touches]
    for k in np.flatnonzero(on[1:] != on[:-1]):
        lo, hi, first = t[k], t[k + 1], bool(on[k])
        while hi - lo > 1e-12 * max(abs(t1 - t0), 1.0):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if bool(distance(np.array([mid]))[0] <= limit) == first else (lo, mid)
        change.append(0.5 * (lo + hi))
    change = sorted(change) + [t1]
    along, across = [], []
    for a, b in itertools.pairwise(change):
        if b - a <= 1e-12 * max(abs(t1 - t0), 1.0):
            continue
        piece = Cut(cut.pcurve.restrict(a, b), None if cut.curve3d is None else cut.curve3d.restrict(a, b))
        kind = bool(on[min(np.searchsorted(t, 0.5 * (a + b)), on.size - 1)])
        (along if kind else across).append(piece)
    return along, across


def _nearest_boundary(distance, lo: float, hi: float) -> float:
    """The parameter in ``[lo, hi]`` where ``distance`` (to the boundary) is least:
    golden-section search to 1e-13 of the bracket... of its width."""
    ratio = 0.5 * (np.sqrt(5.0) - 1.0)
    width = hi - lo
    a, b = lo + (1 - ratio) * width, lo + ratio * width
    fa, fb = distance(np.array([a, b]))
    while hi - lo > 1e-13 * max(width, 1e-300):
        if fa < fb:
            hi, b, fb = b, a, fa
            a = lo + (1 - ratio) * (hi - lo)
            fa = float(distance(np.array([a]))[0])
        else:
            lo, a, fa = a, b, fb
            b = lo + ratio * (hi - lo)
            fb = float(distance(np.array([b]))[0])
    return 0.5 * (lo + hi)


