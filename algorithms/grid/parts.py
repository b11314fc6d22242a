"""A face cut by straight lines in its parameters into parts the block layouts take.

Structured blocks cover a face with at most one hole (one block per outer corner
round it, :func:`..healing.decompose.decompose_ring`) whose outline is not too far
from convex (blocks round a centre joined by straight spokes,
:func:`..healing.decompose.decompose_face`). Two cuts bring other faces there, both
through :func:`~..face_split.split_face`, the parts' blocks meeting along the cut:

* :func:`separate_holes`: a face with more holes is cut between them: the holes'
  centres (in the face's ``(u, v)``) are split into two groups across the widest
  gap along their principal axis, and a straight cut perpendicular to that axis,
  halfway across the gap, runs from the outer loop to the outer loop between them;
  each part is cut again until none has more than one hole. A cut that would cross
  a hole, or leave the groups on one side, is turned (up to 50 degrees either way)
  or moved along the gap, or put in the next widest gap, or across the other axis;
  when none fits the face is refused with the reason.
* :func:`split_at_reflex`: a face of one loop is cut from its most reflex corner
  (the loop turning against its run by more than :data:`REFLEX_ANGLE`) along the
  bisector of the corner's inner angle to the loop beyond (an L is cut into two
  rectangles, a U into three parts by two cuts).

A cut's 3D curve is the straight line's image on the surface, interpolated on the
pcurve's own parameter.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..cuts import Cut, locate_on_loops
from ..face_split import split_face
from ..fitting import interpolate_curve
from ..healing.loop_sides import NotDecomposableError, end_tangent, restricted_curve, signed_area, uv_segment
from ..trimmed import TrimEdge, TrimLoop, TrimmedFace, loop_uv

__all__ = ["REFLEX_ANGLE", "separate_holes", "split_at_reflex"]

#: a corner is reflex when the loop turns against its run by more than this (radians)
REFLEX_ANGLE = np.radians(20.0)

#: points of a cut's image on the surface interpolated into its 3D curve
_CUT_SAMPLES = 33
#: turns of the cut tried, degrees, and shifts along the gap (fractions of it)
_TURNS = (0.0, 10.0, -10.0, 20.0, -20.0, 35.0, -35.0, 50.0, -50.0)
_SHIFTS = (0.0, -0.25, 0.25)
#: gaps between the holes' centres (along each axis, widest first) a cut is tried in
_GAPS = 6


def separate_holes(face: TrimmedFace) -> list[TrimmedFace]:
    """``face`` cut by straight lines in its parameters into parts holding at most one
    hole each (the module doc); a face with at most one hole is returned as it is.

    Raises
    ------
    NotDecomposableError
        No straight cut separates the holes (they interlock, or the outline is too
        narrow between them).
    """
    if len(face.loops) <= 2:
        return [face]
    outer = face.loops[face.outer_loop_index]
    holes = [loop_uv(loop) for k, loop in enumerate(face.loops) if k != face.outer_loop_index]
    outline = loop_uv(outer)
    centres = np.array([h.mean(axis=0) for h in holes])
    spread = centres - centres.mean(axis=0)
    axes = (np.linalg.svd(spread, full_matrices=False)[2] if np.ptp(spread) > 0
            else np.array([[1.0, 0.0], [0.0, 1.0]]))
    for axis in axes:                                   # the principal axis first
        along = spread @ axis
        order = np.argsort(along)
        for k in np.argsort(-np.diff(along[order]))[:_GAPS]:    # the widest gaps first
            first, second = order[:k + 1], order[k + 1:]
            for shift in _SHIFTS:
                t = 0.5 + shift
                middle = (1 - t) * centres[order[k]] + t * centres[order[k + 1]]
                for turn in _TURNS:
                    ends = _separating(outline, holes, centres, first, second, middle, axis, turn)
                    if ends is None:
                        continue
                    ends = [_on_loop(outer, p) for p in ends]
                    parts = split_face(face, [_straight_cut(face, *ends)])
                    return [piece for part in parts for piece in separate_holes(_restricted(part))]
    raise NotDecomposableError(f"{len(holes)} holes: no straight cut between them runs from the outline "
                               "to the outline clear of every hole")


def split_at_reflex(face: TrimmedFace) -> list[TrimmedFace] | None:
    """``face`` (one loop) cut in two from its most reflex corner along the bisector of
    the corner's inner angle to the loop beyond it (the module doc); None when no corner
    is reflex or the cut finds no loop ahead."""
    if len(face.loops) != 1:
        return None
    loop = face.loops[0]
    edges = [e for e in loop.edges if not e.degenerated]
    if len(edges) < 2:
        return None
    outline = loop_uv(loop)
    orientation = 1.0 if signed_area(outline) > 0 else -1.0
    best, corner = -REFLEX_ANGLE, None
    for k, (before, after) in enumerate(zip(edges[-1:] + edges[:-1], edges)):
        t_in, t_out = _uv_tangent(before, 1), _uv_tangent(after, 0)
        turn = orientation * np.arctan2(t_in[0] * t_out[1] - t_in[1] * t_out[0], t_in @ t_out)
        if turn < best:
            best, corner = turn, (k, t_in, t_out, after)
    if corner is None:
        return None
    _, t_in, t_out, after = corner
    start = after.pcurve.evaluate(np.array([after.t1 if after.reversed else after.t0]))[0]
    inward = -(-t_in / np.linalg.norm(t_in) + t_out / np.linalg.norm(t_out))
    if np.linalg.norm(inward) < 1e-12:
        return None
    inward /= np.linalg.norm(inward)
    span = float(np.ptp(outline, axis=0).max())
    ends = _chord(outline, start + 1e-6 * span * inward, inward)
    if ends is None or np.linalg.norm(ends[1] - start) < 1e-3 * span:
        return None
    end = _on_loop(loop, ends[1])
    parts = split_face(face, [_straight_cut(face, start, end)])
    return [_restricted(part) for part in parts] if len(parts) > 1 else None


def _uv_tangent(edge: TrimEdge, end: int) -> NDArray:
    """The loop's direction in ``(u, v)`` at the edge's start (0) or end (1), along the
    loop (the edge's pcurve turned round where the loop runs it backwards)."""
    pcurve = restricted_curve(edge.pcurve, edge.t0, edge.t1)
    return -end_tangent(pcurve, 1 - end) if edge.reversed else end_tangent(pcurve, end)


def _separating(outline, holes, centres, first, second, middle, axis, turn
                ) -> tuple[NDArray, NDArray] | None:
    """The ends of the straight cut through ``middle`` at ``turn`` degrees from the normal
    of ``axis``, when it runs from the outline to the outline clear of every hole with
    the holes ``first`` on one side and ``second`` on the other; else None."""
    c, s = np.cos(np.radians(turn)), np.sin(np.radians(turn))
    normal = np.array([-axis[1], axis[0]])
    direction = np.array([c * normal[0] - s * normal[1], s * normal[0] + c * normal[1]])
    ends = _chord(outline, middle, direction)
    if ends is None or any(_crosses(h, *ends) for h in holes):
        return None
    side = np.sign((centres - ends[0]) @ np.array([-direction[1], direction[0]]))
    if len(set(side[first])) != 1 or len(set(side[second])) != 1 or side[first[0]] == side[second[0]]:
        return None
    return ends


def _restricted(face: TrimmedFace) -> TrimmedFace:
    """``face`` with every edge's curves cut to its range (the pieces a split leaves
    share their whole curves; the block layouts take an edge's curves as the edge)."""
    def cut(e: TrimEdge) -> TrimEdge:
        if e.degenerated or (e.t0, e.t1) == e.pcurve.domain:
            return e
        def piece(curve):
            lo, hi = curve.domain                   # a range a rounding past the curve's ends
            return curve.restrict(max(e.t0, lo), min(e.t1, hi))
        t0, t1 = max(e.t0, e.pcurve.domain[0]), min(e.t1, e.pcurve.domain[1])
        return TrimEdge(None if e.curve3d is None else piece(e.curve3d), piece(e.pcurve), t0, t1,
                        e.reversed, e.tolerance, None if e.seam_pcurve is None else piece(e.seam_pcurve),
                        e.degenerated, e.vertex_tolerances)
    loops = tuple(TrimLoop(tuple(cut(e) for e in loop.edges)) for loop in face.loops)
    return TrimmedFace(face.surface, loops, face.outer_loop_index, face.reversed, face.name,
                       tuple(cut(e) for e in face.internal))


def _chord(outline: NDArray, point: NDArray, direction: NDArray) -> tuple[NDArray, NDArray] | None:
    """Where the line through ``point`` along ``direction`` meets the closed polyline
    ``outline (n, 2)`` nearest before and after ``point``, or None."""
    a, b = outline, np.roll(outline, -1, axis=0)
    edge = b - a
    denominator = direction[0] * edge[:, 1] - direction[1] * edge[:, 0]
    ok = np.abs(denominator) > 1e-300
    rel = a - point
    t = np.where(ok, (rel[:, 0] * edge[:, 1] - rel[:, 1] * edge[:, 0]) / np.where(ok, denominator, 1.0), np.nan)
    s = np.where(ok, (rel[:, 0] * direction[1] - rel[:, 1] * direction[0]) / np.where(ok, denominator, 1.0),
                 np.nan)
    hit = ok & (s >= 0.0) & (s < 1.0)
    before, after = t[hit & (t < 0)], t[hit & (t > 0)]
    if not before.size or not after.size:
        return None
    return point + before.max() * direction, point + after.min() * direction


def _crosses(polyline: NDArray, p: NDArray, q: NDArray) -> bool:
    """The segment ``p q`` crosses the closed polyline."""
    a, b = polyline, np.roll(polyline, -1, axis=0)

    def orient(x, y, z):
        return (y[..., 0] - x[..., 0]) * (z[..., 1] - x[..., 1]) - (y[..., 1] - x[..., 1]) * (z[..., 0] - x[..., 0])
    d1, d2 = orient(p, q, a), orient(p, q, b)
    d3, d4 = orient(a, b, p), orient(a, b, q)
    return bool(np.any((d1 * d2 <= 0) & (d3 * d4 <= 0)))


def _on_loop(loop, point: NDArray) -> NDArray:
    """The point of the loop's pcurves nearest ``point`` (a crossing found on the
    sampled loop, moved onto the loop itself)."""
    _, ei, t = locate_on_loops([loop], point, np.inf)
    return loop.edges[ei].pcurve.evaluate(np.array([t]))[0]


def _straight_cut(face: TrimmedFace, a: NDArray, b: NDArray) -> Cut:
    """The straight segment ``a b`` in ``(u, v)`` with its image on the surface as its
    3D curve, interpolated on the same parameter ([0, 1])."""
    s = np.linspace(0.0, 1.0, _CUT_SAMPLES)
    uv = (1 - s)[:, None] * a + s[:, None] * b
    points = face.surface.evaluate(uv[:, 0], uv[:, 1])
    return Cut(uv_segment(a, b), interpolate_curve(points, parameters=s))
