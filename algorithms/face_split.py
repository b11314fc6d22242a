"""Splitting a trimmed face along curves in its parameter domain (002 §1, the first step of
cutting faces by their intersection curves).

A *cut* is a curve in the face's ``(u, v)`` (a pcurve, with its 3D curve when known):
either open, running from the face's boundary to its boundary, or closed, lying
inside the face. :func:`split_face` returns the regions the cuts divide the face
into, each a :class:`~surfprep.algorithms.trimmed.TrimmedFace` on the same surface
whose loops are made of pieces of the old loops (the same edges over shorter
ranges) and of the cuts (each cut bounds two regions, run once each way).

The arrangement is traced as a planar graph: the cuts' ends split the loops into
runs; leaving a run at a cut's end the trace turns onto the cut (the region on the
left of the loop stays on the left of the cut), and leaving a cut it goes on along
the loop. Every cycle traced counter-clockwise bounds a region; clockwise cycles
(a hole of the face, the outside of a closed cut) are holes of the smallest region
that contains them. Cuts may not cross each other or touch the boundary elsewhere
than at their ends (a cut with a crossing must be split there first: refused with
the reason), and two cuts may not end at the same boundary point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidGeometryError
from .curve import NurbsCurve
from .face_region import inside_loops
from .trimmed import (
    DEFAULT_TOLERANCE,
    LOOP_SAMPLES_PER_EDGE,
    TrimEdge,
    TrimLoop,
    TrimmedFace,
    curve3d_points,
    edge_deviation,
)

__all__ = ["Cut", "split_face"]

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


def _rectangle_loop(face: TrimmedFace) -> TrimLoop:
    """The surface's whole rectangle as a counter-clockwise loop of four edges (the
    pcurves on the surface's own parameters, the iso-lines as 3D curves; a side of no
    length is a degenerated edge)."""
    surface = face.surface
    u0, u1, v0, v1 = surface.domain
    box = surface.bounding_box()
    tiny = 1e-12 * float(np.linalg.norm(box[1] - box[0]))
    sides = (((u0, v0), (u1, v0), "v", v0, u0, u1, False), ((u1, v0), (u1, v1), "u", u1, v0, v1, False),
             ((u0, v1), (u1, v1), "v", v1, u0, u1, True), ((u0, v0), (u0, v1), "u", u0, v0, v1, True))
    edges = []
    for a, b, held, value, t0, t1, backwards in sides:
        pcurve = NurbsCurve(np.array([a, b], float), np.array([t0, t0, t1, t1]), 1)
        curve3d = surface.isocurve(value, "u" if held == "u" else "v")
        ends = curve3d.evaluate(np.array([t0, 0.5 * (t0 + t1), t1]))
        degenerate = float(np.max(np.linalg.norm(ends - ends[0], axis=1))) <= tiny
        edges.append(TrimEdge(None if degenerate else curve3d, pcurve, t0, t1, backwards,
                              degenerated=degenerate))
    return TrimLoop(tuple(edges))


@dataclass
class _Mark:
    """A cut's end on a loop: edge ``edge`` of loop ``loop`` at parameter ``t``."""

    loop: int
    edge: int
    t: float
    cut: int
    end: int                       # 0 the cut's start, 1 its end
    along: float = 0.0             # position along the loop (edge index + fraction in loop order)
    gap: float = 0.0               # distance in space between the boundary's point and the cut's end


def _locate(loops: list[TrimLoop], point: NDArray, eps: float,
            near=lambda best: False) -> tuple[int, int, float] | None:
    """The loop, edge and edge parameter nearest to a point of the domain: within ``eps``
    in the parameters, or where ``near(best)`` accepts it (a test in space)."""
    best = None
    for li, loop in enumerate(loops):
        for ei, e in enumerate(loop.edges):
            t = np.linspace(e.t0, e.t1, 4 * LOOP_SAMPLES_PER_EDGE)
            uv = e.pcurve.evaluate(t)
            d = np.linalg.norm(uv - point, axis=1)
            k = int(np.argmin(d))
            # refine on the segment either side by a few bisections of the distance
            lo, hi = t[max(k - 1, 0)], t[min(k + 1, t.size - 1)]
            for _ in range(40):
                m1, m2 = lo + (hi - lo) / 3, hi - (hi - lo) / 3
                d1, d2 = (np.linalg.norm(e.pcurve.evaluate(np.array([m]))[0] - point) for m in (m1, m2))
                lo, hi = (lo, m2) if d1 < d2 else (m1, hi)
            tt = 0.5 * (lo + hi)
            dist = float(np.linalg.norm(e.pcurve.evaluate(np.array([tt]))[0] - point))
            if best is None or dist < best[3]:
                best = (li, ei, tt, dist)
    if best is None or best[3] > eps and not near(best):
        return None
    return best[0], best[1], best[2]


def _crossing(a: NDArray, b: NDArray, skip_ends: bool) -> bool:
    """Do two polylines cross (their end segments left out when ``skip_ends``)?"""
    p, r = a[:-1], np.diff(a, axis=0)
    q, s = b[:-1], np.diff(b, axis=0)
    if skip_ends:
        p, r, q, s = p[1:-1], r[1:-1], q[1:-1], s[1:-1]
    if p.size == 0 or q.size == 0:
        return False
    rxs = r[:, None, 0] * s[None, :, 1] - r[:, None, 1] * s[None, :, 0]
    qp = q[None, :, :] - p[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[..., 0] * s[None, :, 1] - qp[..., 1] * s[None, :, 0]) / rxs
        u = (qp[..., 0] * r[:, None, 1] - qp[..., 1] * r[:, None, 0]) / rxs
    hit = (rxs != 0) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
    return bool(np.any(hit))


def _signed_area(uv: NDArray) -> float:
    x, y = uv[:, 0], uv[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _param(edge: TrimEdge, fraction: float) -> float:
    """The edge parameter ``fraction`` of the way along it in loop direction."""
    return edge.t1 - fraction * (edge.t1 - edge.t0) if edge.reversed else edge.t0 + fraction * (edge.t1 - edge.t0)


def _runs(loop: TrimLoop, marks: list[_Mark]) -> list[tuple[list[TrimEdge], _Mark, _Mark]]:
    """The loop split at its marks: the runs of edge pieces from each mark to the next.

    Positions along the loop run from 0 to ``n`` (edge ``k`` covers ``[k, k + 1)`` in
    loop direction); a run from ``a`` to the next mark ``b`` (``b + n`` when it wraps)
    takes each edge's share of it.
    """
    edges = loop.edges
    n = len(edges)
    marks = sorted(marks, key=lambda m: m.along)
    runs = []
    for k, start in enumerate(marks):
        stop = marks[(k + 1) % len(marks)]
        a, b = start.along, stop.along
        if b <= a:
            b += n
        pieces: list[TrimEdge] = []
        position = a
        while position < b - 1e-12:
            k_edge = int(np.floor(position + 1e-12))
            edge = edges[k_edge % n]
            lo = position - k_edge
            hi = min(b - k_edge, 1.0)
            if hi - lo > 1e-12:
                ta, tb = _param(edge, lo), _param(edge, hi)
                pieces.append(TrimEdge(edge.curve3d, edge.pcurve, min(ta, tb), max(ta, tb), edge.reversed,
                                       edge.tolerance, edge.seam_pcurve, edge.degenerated,
                                       edge.vertex_tolerances))
            position = k_edge + hi if hi < 1.0 else k_edge + 1.0
        runs.append((pieces, start, stop))
    return runs


def _near_in_space(face: TrimmedFace, loops: list[TrimLoop], cut: Cut, end: int, tol3d: float | None):
    """A test that a boundary point found for a cut's end lies within ``tol3d`` of it in space."""
    if tol3d is None:
        return lambda best: False
    point = _cut_point(cut, face, end)

    def near(best) -> bool:
        edge = loops[best[0]].edges[best[1]]
        return float(np.linalg.norm(curve3d_points(edge, face.surface, np.array([best[2]]))[0] - point)) <= tol3d

    return near


def split_face(face: TrimmedFace, cuts: list[Cut], *, tol: float | None = None,
               tol3d: float | None = None) -> list[TrimmedFace]:
    """The regions of a face cut along curves in its domain (see the module doc).

    Parameters
    ----------
    face : TrimmedFace
    cuts : list of Cut
        Open cuts from the boundary to the boundary, closed cuts inside the face.
    tol : float, optional
        How close (in the parameters) a cut's end must be to the boundary, and a closed
        cut's ends to each other; default 1e-7 of the domain's span.
    tol3d : float, optional
        A cut's end is also on the boundary when the nearest boundary point lies within
        this distance of it in space (model units: an intersection curve clipped to a
        trimmed face ends on the trim to the intersection's tolerance).

    Returns
    -------
    list of TrimmedFace
        One per region, on the face's surface, outer loop first (counter-clockwise),
        holes after it; the cuts' pieces carry the cut's pcurve and 3D curve.

    Raises
    ------
    InvalidGeometryError
        A cut's end off the boundary, cuts crossing each other, two cuts ending at one
        boundary point.
    """
    u0, u1, v0, v1 = face.surface.domain
    span = max(u1 - u0, v1 - v0)
    eps = 1e-7 * span if tol is None else float(tol)
    loops = list(face.loops) if face.loops else [_rectangle_loop(face)]
    polylines = [cut.samples() for cut in cuts]
    for i in range(len(cuts)):
        for j in range(i + 1, len(cuts)):
            if _crossing(polylines[i], polylines[j], skip_ends=True):
                raise InvalidGeometryError(f"cuts {i} and {j} cross each other: split them at the "
                                           "crossing first")
    # each cut end: on the boundary (where), or joined to another cut's end inside the face
    ends: dict[tuple[int, int], tuple[int, int, float] | None] = {}
    closed_cuts = []
    for c, line in enumerate(polylines):
        if np.linalg.norm(line[0] - line[-1]) <= eps:
            closed_cuts.append(c)
            continue
        for end, point in ((0, line[0]), (1, line[-1])):
            ends[c, end] = _locate(loops, point, eps, _near_in_space(face, loops, cuts[c], end, tol3d))
    link: dict[tuple[int, int], tuple[int, int]] = {}
    free = [key for key, where in ends.items() if where is None]
    for key in free:
        if key in link:
            continue
        point = polylines[key[0]][0 if key[1] == 0 else -1]
        partner = next((other for other in free if other != key and other not in link
                        and np.linalg.norm(polylines[other[0]][0 if other[1] == 0 else -1] - point) <= eps),
                       None)
        if partner is None:
            raise InvalidGeometryError(f"cut {key[0]} {'starts' if key[1] == 0 else 'ends'} at "
                                       f"{point.tolist()}, not on the face's boundary")
        link[key], link[partner] = partner, key
    chains = _chains(cuts, ends, link, closed_cuts)
    marks: list[_Mark] = []
    for k, (chain, is_closed) in enumerate(chains):
        if is_closed:
            continue
        for end in (0, 1):
            c, forward = chain[0] if end == 0 else chain[-1]
            cut_end = (0 if forward else 1) if end == 0 else (1 if forward else 0)
            li, ei, t = ends[c, cut_end]
            e = loops[li].edges[ei]
            frac = (t - e.t0) / (e.t1 - e.t0)
            gap = float(np.linalg.norm(curve3d_points(e, face.surface, np.array([t]))[0]
                                       - _cut_point(cuts[c], face, cut_end)))
            marks.append(_Mark(li, ei, t, k, end, ei + (1.0 - frac if e.reversed else frac), gap))
    seen = {}
    for m in marks:
        key = (m.loop, round(m.along / max(eps, 1e-15)))
        if key in seen:
            raise InvalidGeometryError(f"cuts {seen[key]} and {m.cut} end at the same boundary point")
        seen[key] = m.cut
    # the cycles: traced from the runs, plus untouched loops and closed chains
    by_loop: dict[int, list[_Mark]] = {}
    for m in marks:
        by_loop.setdefault(m.loop, []).append(m)
    runs = {}                                              # start mark id -> (pieces, start, stop)
    for li, ms in by_loop.items():
        for pieces, start, stop in _runs(loops[li], ms):
            runs[id(start)] = (pieces, start, stop)
    other_end = {}
    for m in marks:
        for n in marks:
            if n is not m and n.cut == m.cut:
                other_end[id(m)] = n
    cycles: list[list[TrimEdge]] = []
    used: set[int] = set()
    for key in runs:
        if key in used:
            continue
        cycle: list[TrimEdge] = []
        current = key
        while current not in used:
            used.add(current)
            pieces, start, stop = runs[current]
            cycle.extend(_loosened(piece, max(start.gap, stop.gap)) for piece in pieces)
            far = other_end[id(stop)]
            cycle.extend(_chain_edges(cuts, chains[stop.cut][0], face, stop.gap, far.gap,
                                      backwards=stop.end == 1))
            current = id(far)
        cycles.append(cycle)
    for li, loop in enumerate(loops):
        if li not in by_loop:
            cycles.append(list(loop.edges))
    for chain, is_closed in chains:
        if is_closed:
            cycles.append(_chain_edges(cuts, chain, face, 0.0, 0.0, backwards=False))
            cycles.append(_chain_edges(cuts, chain, face, 0.0, 0.0, backwards=True))
    return _regions(face, cycles)


def _chains(cuts: list[Cut], ends: dict, link: dict, closed_cuts: list[int]
            ) -> list[tuple[list[tuple[int, bool]], bool]]:
    """Cuts joined end to end inside the face: ``([(cut, forward), ...], closed)`` each, open
    chains running from a boundary end to a boundary end."""
    chains: list[tuple[list[tuple[int, bool]], bool]] = [([(c, True)], True) for c in closed_cuts]
    visited: set[int] = set(closed_cuts)

    def follow(c: int, forward: bool) -> tuple[list[tuple[int, bool]], bool]:
        chain = []
        first = c
        while True:
            chain.append((c, forward))
            visited.add(c)
            far = (c, 1 if forward else 0)
            if far not in link:
                return chain, False                       # reached the boundary
            c, end = link[far]
            forward = end == 0
            if c == first:
                return chain, True                        # round a closed chain
    for (c, end), where in ends.items():
        if where is not None and c not in visited:
            chains.append(follow(c, end == 0))
    for c in range(len(cuts)):
        if c not in visited:
            chains.append(follow(c, True))
    return chains


def _chain_edges(cuts: list[Cut], chain: list[tuple[int, bool]], face: TrimmedFace, gap_start: float,
                 gap_end: float, *, backwards: bool) -> list[TrimEdge]:
    """The edges of a chain of cuts in order, run backwards when asked; the chain's ends
    tolerate the gaps to the boundary, its joints the gaps between the pieces."""
    order = list(reversed(chain)) if backwards else list(chain)
    gap_first, gap_last = (gap_end, gap_start) if backwards else (gap_start, gap_end)
    out = []
    for k, (c, forward) in enumerate(order):
        if backwards:
            forward = not forward
        cut = cuts[c]
        t0, t1 = cut.range
        probe = TrimEdge(cut.curve3d, cut.pcurve, t0, t1)
        tolerance = max(DEFAULT_TOLERANCE, 1.01 * edge_deviation(probe, face.surface))
        start_gap = gap_first if k == 0 else _joint_gap(cuts, order[k - 1], (c, forward), face)
        end_gap = gap_last if k == len(order) - 1 else _joint_gap(cuts, (c, forward), order[k + 1], face)
        at_t0, at_t1 = (start_gap, end_gap) if forward else (end_gap, start_gap)
        out.append(TrimEdge(cut.curve3d, cut.pcurve, t0, t1, not forward, tolerance,
                            vertex_tolerances=(max(DEFAULT_TOLERANCE, 1.01 * at_t0),
                                               max(DEFAULT_TOLERANCE, 1.01 * at_t1))))
    return out


def _joint_gap(cuts: list[Cut], before: tuple[int, bool], after: tuple[int, bool], face: TrimmedFace) -> float:
    """Distance in space between where one piece of a chain ends and the next begins."""
    a = _cut_point(cuts[before[0]], face, 1 if before[1] else 0)
    b = _cut_point(cuts[after[0]], face, 0 if after[1] else 1)
    return float(np.linalg.norm(a - b))


def _cut_point(cut: Cut, face: TrimmedFace, end: int) -> NDArray:
    """The cut's start (``end`` 0) or end point in space."""
    t = np.array([cut.range[end]])
    if cut.curve3d is not None:
        return cut.curve3d.evaluate(t)[0]
    uv = cut.pcurve.evaluate(t)
    return face.surface.evaluate(uv[:, 0], uv[:, 1])[0]


def _loosened(edge: TrimEdge, gap: float) -> TrimEdge:
    """A boundary piece whose corners tolerate the gap to the cut that ends there."""
    if gap <= 0.0:
        return edge
    lo, hi = edge.vertex_tolerances
    return TrimEdge(edge.curve3d, edge.pcurve, edge.t0, edge.t1, edge.reversed, edge.tolerance,
                    edge.seam_pcurve, edge.degenerated,
                    (max(lo, 1.01 * gap), max(hi, 1.01 * gap)))


def _regions(face: TrimmedFace, cycles: list[list[TrimEdge]]) -> list[TrimmedFace]:
    """Counter-clockwise cycles as regions, clockwise ones as holes of the smallest region
    containing them."""
    samples = [_loop_samples(cycle) for cycle in cycles]
    areas = [_signed_area(uv) for uv in samples]
    outer = [k for k, a in enumerate(areas) if a > 0]
    holes = [k for k, a in enumerate(areas) if a <= 0]
    members: dict[int, list[int]] = {k: [] for k in outer}
    for h in holes:
        point = samples[h][len(samples[h]) // 2:len(samples[h]) // 2 + 1]
        containing = [k for k in outer if inside_loops(point, [samples[k]])[0]
                      and areas[k] > -areas[h]]
        if not containing:
            raise InvalidGeometryError("a clockwise boundary lies in no region (are the loops oriented?)")
        members[min(containing, key=lambda k: areas[k])].append(h)
    out = []
    for k in outer:
        region = [cycles[k]] + [cycles[h] for h in members[k]]
        edges = [e for cycle in region for e in cycle]
        loops = [TrimLoop(tuple(_unpaired_seam(e, edges) for e in cycle)) for cycle in region]
        out.append(TrimmedFace(face.surface, tuple(loops), 0, face.reversed, face.name))
    return out


def _unpaired_seam(edge: TrimEdge, edges: list[TrimEdge]) -> TrimEdge:
    """A seam piece whose other occurrence is not in the region is a plain edge there (a
    cut across a closed surface's seam leaves one side of it in each piece)."""
    if edge.seam_pcurve is None:
        return edge
    paired = any(f is not edge and f.curve3d is edge.curve3d and f.reversed != edge.reversed
                 and np.isclose(f.t0, edge.t0) and np.isclose(f.t1, edge.t1) for f in edges)
    if paired:
        return edge
    return TrimEdge(edge.curve3d, edge.pcurve, edge.t0, edge.t1, edge.reversed, edge.tolerance, None,
                    edge.degenerated, edge.vertex_tolerances)


def _loop_samples(cycle: list[TrimEdge]) -> NDArray:
    parts = []
    for e in cycle:
        t = np.linspace(e.t0, e.t1, LOOP_SAMPLES_PER_EDGE)
        uv = e.pcurve.evaluate(t[::-1] if e.reversed else t)
        parts.append(uv[:-1])
    return np.concatenate(parts)
