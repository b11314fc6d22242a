"""Splitting a trimmed face along curves in its parameter domain (002 §1, the first step of
cutting faces by their intersection curves).

A *cut* is a curve in the face's ``(u, v)`` (a pcurve, with its 3D curve when known):
either open, running from the face's boundary to its boundary, or closed, lying
inside the face. :func:`split_face` returns the regions the cuts divide the face
into, each a :class:`~surfprep.algorithms.trimmed.TrimmedFace` on the same surface
whose loops are made of pieces of the old loops (the same edges over shorter
ranges) and of the cuts (each cut bounds two regions, run once each way).

The arrangement is traced as a planar graph (:class:`.arrangement.Arrangement`): the cuts are split where they cross
one another (crossings found on their polylines, then by Newton on the pcurves),
their ends on the loops split the loops into runs, and cut ends that meet inside
the face are one vertex. At each vertex the half-edges leave in the order of
their angles; a face is traced by taking, at each vertex, the first half-edge
clockwise from the way back, so the region stays on the left. Every cycle traced
counter-clockwise bounds a region; clockwise cycles (a hole of the face, the
outside of a closed cut) are holes of the smallest region that contains them.

A cut that runs along the face's boundary divides nothing and is left out (faces
meeting along a shared edge, touching solids) -- but where it ends inside an edge of
the loop, the edge is split there (a face of another solid touching along part of
it can then share the piece); a cut that runs along it for part of its length only
keeps the part across the face -- and so is a cut that repeats another
(the same curve reported twice). A cut that stops inside the face and
meets no other cut divides nothing either (where a fin stands on a sheet): it
becomes an internal edge (:attr:`~surfprep.algorithms.trimmed.TrimmedFace.internal`)
of the region it lies in; when its other end is on the boundary (a spur) the loop's
edge is split there, so the two share the vertex. Two cuts ending at one boundary
point are refused.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidGeometryError
from .arrangement import Arrangement
from .cuts import (
    CUT_SAMPLES,
    Cut,
    cut_point_at,
    distinct_cuts,
    locate_on_loops,
    near_in_space,
    parts_along_boundary,
    snap_to_corner,
    split_where_cuts_end,
)
from .face_region import inside_loops
from .trimmed import (
    DEFAULT_TOLERANCE,
    LOOP_SAMPLES_PER_EDGE,
    TrimEdge,
    TrimLoop,
    TrimmedFace,
    curve3d_points,
    edge_deviation,
    natural_loop,
)

__all__ = ["Cut", "split_face"]

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
    vertex: int = -1               # its vertex in the arrangement


def _signed_area(uv: NDArray) -> float:
    x, y = uv[:, 0], uv[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _param(edge: TrimEdge, fraction: float) -> float:
    """The edge parameter ``fraction`` of the way along it in loop direction."""
    return edge.t1 - fraction * (edge.t1 - edge.t0) if edge.reversed else edge.t0 + fraction * (edge.t1 - edge.t0)


def _runs(loop: TrimLoop, marks: list[_Mark], eps: float = 0.0
          ) -> list[tuple[list[TrimEdge], _Mark, _Mark]]:
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
            ta, tb = _param(edge, lo), _param(edge, hi)
            # a piece of no length: a mark at an edge's end, a rounding apart from it
            sliver = hi - lo <= 1e-6 and np.linalg.norm(np.subtract(*edge.pcurve.evaluate(
                np.array([ta, tb])))) <= eps
            if hi - lo > 1e-12 and not sliver:
                pieces.append(TrimEdge(edge.curve3d, edge.pcurve, min(ta, tb), max(ta, tb), edge.reversed,
                                       edge.tolerance, edge.seam_pcurve, edge.degenerated,
                                       edge.vertex_tolerances))
            position = k_edge + hi if hi < 1.0 else k_edge + 1.0
        runs.append((pieces, start, stop))
    return runs


def split_face(face: TrimmedFace, cuts: list[Cut], *, tol: float | None = None,
               tol3d: float | None = None) -> list[TrimmedFace]:
    """The regions of a face cut along curves in its domain (see the module doc).

    Parameters
    ----------
    face : TrimmedFace
    cuts : list of Cut
        Open cuts from the boundary to the boundary (or to other cuts' ends inside the
        face), closed cuts; cuts may cross each other (they are split where they do).
    tol : float, optional
        How close (in the parameters) a cut's end must be to the boundary, and two ends
        or crossings to be one vertex; default 1e-7 of the domain's span.
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
        A cut with one end neither on the boundary nor on another cut (a spur; a cut
        with both ends inside becomes an internal edge), two cuts ending at one
        boundary point, cuts that overlap.
    """
    u0, u1, v0, v1 = face.surface.domain
    span = max(u1 - u0, v1 - v0)
    eps = 1e-7 * span if tol is None else float(tol)
    loops = list(face.loops) if face.loops else [natural_loop(face.surface)]
    along, across = [], []
    for cut in cuts:
        parts = parts_along_boundary(face, loops, cut, eps, tol3d)
        along.extend(parts[0])
        across.extend(parts[1])
    loops = split_where_cuts_end(face, loops, along, eps, tol3d, across)
    cuts = distinct_cuts(across, face, eps, tol3d)
    graph = Arrangement(face, eps)
    # where each cut is split: its ends and its crossings with the other cuts
    params: list[list[float]] = [[cut.range[0], cut.range[1]] for cut in cuts]
    for i in range(len(cuts)):
        for j in range(i + 1, len(cuts)):
            for s, t in _crossings(cuts[i], cuts[j], eps):
                point = cuts[i].pcurve.evaluate(np.array([s]))[0]
                graph.vertex(point, cut_point_at(cuts[i], face, s), cut_point_at(cuts[j], face, t))
                params[i].append(s)
                params[j].append(t)
    joined = _t_junctions(face, cuts, params, graph, eps, tol3d)
    dangling, spurs = _dangling(face, loops, cuts, params, eps, tol3d, joined)
    marks: list[_Mark] = []
    for c, cut in enumerate(cuts):
        line = cut.samples()
        if c in dangling or np.linalg.norm(line[0] - line[-1]) <= eps:
            continue                                             # closed: its ends are one vertex
        for end, point in ((0, line[0]), (1, line[-1])):
            where = locate_on_loops(loops, point, eps, near_in_space(face, loops, cut, end, tol3d))
            if where is None:
                continue                                         # an inner end: joined below
            li, ei, t = where
            e = loops[li].edges[ei]
            t = snap_to_corner(e, face.surface, t, eps, tol3d)
            frac = (t - e.t0) / (e.t1 - e.t0)
            gap = float(np.linalg.norm(curve3d_points(e, face.surface, np.array([t]))[0]
                                       - _cut_point(cut, face, end)))
            mark = _Mark(li, ei, t, c, end, ei + (1.0 - frac if e.reversed else frac), gap)
            marks.append(mark)
            mark.vertex = graph.vertex(point, curve3d_points(e, face.surface, np.array([t]))[0],
                                       _cut_point(cut, face, end), boundary=True)
    marks = _one_mark_per_point(marks, graph, loops)
    # the cut segments between consecutive split parameters, both ways
    for c, cut in enumerate(cuts):
        if c in dangling or c in spurs:
            continue
        ts = np.sort(np.clip(np.asarray(params[c], dtype=float), *cut.range))
        width = 1e-12 * max(abs(cut.range[1] - cut.range[0]), 1.0)
        kept = [ts[0]] + [t for t in ts[1:-1] if t - ts[0] > width and ts[-1] - t > width]
        kept = [t for k, t in enumerate(kept) if k == 0 or t - kept[k - 1] > width] + [ts[-1]]
        for a, b in itertools.pairwise(kept):
            graph.cut_segment(c, cut, a, b)
    # the boundary runs between marks, one way (the face's side)
    by_loop: dict[int, list[_Mark]] = {}
    for m in marks:
        by_loop.setdefault(m.loop, []).append(m)
    for li, ms in by_loop.items():
        for pieces, start, stop in _runs(loops[li], ms, eps):
            if not pieces:   # two cut ends a rounding apart, not one vertex (seen on real files)
                raise InvalidGeometryError(
                    f"two cut ends on loop {li} (near {np.round(start.along, 6)} along it) "
                    "leave nothing of the loop between them but are not one vertex")
            graph.run(pieces, start.vertex, stop.vertex, max(start.gap, stop.gap))
    graph.check_ends()
    cycles = graph.cycles()
    for li, loop in enumerate(loops):
        if li not in by_loop:
            cycles.append(list(loop.edges))
    return _with_internal(face, _regions(face, cycles), [cuts[c] for c in sorted(dangling | spurs)])


def _one_mark_per_point(marks: list[_Mark], graph: Arrangement, loops: list[TrimLoop]) -> list[_Mark]:
    """The marks with those at one point of a loop (cuts meeting at the boundary: the
    pieces of a curve touching it, curves of three faces meeting at a corner) merged
    into the first: the others' cut ends are made its vertex, and the loop is split
    there once."""
    out: list[_Mark] = []
    for m in sorted(marks, key=lambda m: (m.loop, m.along)):
        same = next((k for k in out if k.loop == m.loop and
                     (k.vertex == m.vertex or abs(k.along - m.along) <= 1e-9
                      or abs(abs(k.along - m.along) - len(loops[m.loop].edges)) <= 1e-9)), None)
        if same is None:
            out.append(m)
        else:
            graph.join(m.vertex, same.vertex)
    return out


def _near_point(edge: TrimEdge, face: TrimmedFace, point: NDArray, tol3d: float | None):
    """A test that a point found on ``edge`` lies within ``tol3d`` of ``point`` in space."""
    if tol3d is None:
        return lambda best: False
    return lambda best: float(np.linalg.norm(
        curve3d_points(edge, face.surface, np.array([best[2]]))[0] - point)) <= tol3d


def _t_junctions(face: TrimmedFace, cuts: list[Cut], params: list[list[float]], graph: Arrangement,
                 eps: float, tol3d: float | None) -> set[tuple[int, int]]:
    """Cuts that end on another cut's inside (a T: where a cylinder touches a box's face
    along a line, the line ends on the circle where the box's next face cuts the
    cylinder): the other cut is split there (``params``) and both meet at one vertex.
    Returns the ``(cut, end)`` that end so."""
    joined: set[tuple[int, int]] = set()
    for j, cut in enumerate(cuts):
        line = cut.samples()
        if np.linalg.norm(line[0] - line[-1]) <= eps:
            continue
        for end, point in ((0, line[0]), (1, line[-1])):
            for i, other in enumerate(cuts):
                if i == j:
                    continue
                edge = TrimEdge(other.curve3d, other.pcurve, *other.range)
                where = locate_on_loops([TrimLoop((edge,))], point, eps,
                                        _near_point(edge, face, cut_point_at(cut, face, cut.range[end]), tol3d))
                if where is None:
                    continue
                s = where[2]
                at = other.pcurve.evaluate(np.array([s]))[0]
                if min(np.linalg.norm(at - q) for q in other.pcurve.evaluate(np.array(other.range))) <= eps:
                    continue                                  # at the other's end: an ordinary joint
                params[i].append(s)
                graph.join(graph.vertex(at, cut_point_at(other, face, s)), graph.vertex(point))
                joined.add((j, end))
                break
    return joined


def _dangling(face: TrimmedFace, loops: list[TrimLoop], cuts: list[Cut], params: list[list[float]],
              eps: float, tol3d: float | None, joined: set[tuple[int, int]] = frozenset()
              ) -> tuple[set[int], set[int]]:
    """The cuts that divide nothing: open, crossing no other cut, with an end inside the
    face (on no loop, at no other cut's end) -- a curve that stops inside the face -- and,
    taken away, those they leave so in turn (a path of cuts joined end to end inside the
    face that stops inside it: a fin's foot made of two curves). Both ends off the
    boundary: *dangling*; one on it: a *spur* (its boundary end splits the loop's edge
    there, so the edge and the spur share that vertex). All become internal edges of the
    region they lie in."""
    ends = []
    for cut in cuts:
        line = cut.samples()
        ends.append((line[0], line[-1]))
    candidates, on_loop = [], {}
    for c, cut in enumerate(cuts):
        first, last = ends[c]
        if np.linalg.norm(first - last) <= eps or len(params[c]) > 2:
            continue                                   # closed, or crossing another cut
        on_loop[c] = [locate_on_loops(loops, point, eps, near_in_space(face, loops, cut, end, tol3d)) is not None
                      for end, point in ((0, first), (1, last))]
        if not all(on_loop[c]):                        # boundary to boundary: it divides
            candidates.append(c)
    dangling, spurs = set(), set()
    removed: set[int] = set()
    changed = True
    while changed:
        changed = False
        for c in candidates:
            if c in removed:
                continue
            free = False
            for end, (p, on) in enumerate(zip(ends[c], on_loop[c])):
                # an end on no loop, on no other cut's inside and at no end of a cut still
                # there (crossing cuts count: they are split at their crossings, not pruned)
                if not on and (c, end) not in joined and not any(np.linalg.norm(p - q) <= eps for d, pair in enumerate(ends)
                                      if d != c and d not in removed for q in pair):
                    free = True
            if free:
                removed.add(c)
                (spurs if any(on_loop[c]) else dangling).add(c)
                changed = True
    return dangling, spurs


def _with_internal(face: TrimmedFace, regions: list[TrimmedFace], dangling: list[Cut]
                   ) -> list[TrimmedFace]:
    """Each dangling cut as an internal edge of the region its middle lies in."""
    if not dangling:
        return regions
    extra: list[list[TrimEdge]] = [[] for _ in regions]
    samples = [[_loop_samples(list(loop.edges)) for loop in region.loops] for region in regions]
    for cut in dangling:
        t0, t1 = cut.range
        middle = cut.pcurve.evaluate(np.array([0.5 * (t0 + t1)]))
        k = next((k for k, loops in enumerate(samples) if inside_loops(middle, loops)[0]), None)
        if k is None:
            raise InvalidGeometryError("a curve that stops inside the face lies in no region of it")
        edge = TrimEdge(cut.curve3d, cut.pcurve, t0, t1, False, 0.0)
        extra[k].append(TrimEdge(cut.curve3d, cut.pcurve, t0, t1, False,
                                 max(DEFAULT_TOLERANCE, edge_deviation(edge, face.surface))))
    return [region if not more else
            TrimmedFace(region.surface, region.loops, region.outer_loop_index, region.reversed,
                        region.name, region.internal + tuple(more))
            for region, more in zip(regions, extra)]


def _crossings(a: Cut, b: Cut, eps: float) -> list[tuple[float, float]]:
    """Parameters ``(s, t)`` where two cuts cross (ends that merely meet left out),
    from their polylines then Newton on ``a(s) = b(t)``."""
    sa, sb = np.linspace(*a.range, CUT_SAMPLES), np.linspace(*b.range, CUT_SAMPLES)
    pa, pb = a.pcurve.evaluate(sa), b.pcurve.evaluate(sb)
    p, r = pa[:-1], np.diff(pa, axis=0)
    q, s = pb[:-1], np.diff(pb, axis=0)
    rxs = r[:, None, 0] * s[None, :, 1] - r[:, None, 1] * s[None, :, 0]
    qp = q[None, :, :] - p[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[..., 0] * s[None, :, 1] - qp[..., 1] * s[None, :, 0]) / rxs
        u = (qp[..., 0] * r[:, None, 1] - qp[..., 1] * r[:, None, 0]) / rxs
    hit = (rxs != 0) & (t >= 0) & (t <= 1) & (u >= 0) & (u <= 1)
    out: list[tuple[float, float]] = []
    for i, j in zip(*np.nonzero(hit), strict=True):
        x = sa[i] + t[i, j] * (sa[i + 1] - sa[i])
        y = sb[j] + u[i, j] * (sb[j + 1] - sb[j])
        for _ in range(20):                                  # Newton on a(x) - b(y) = 0
            da, db = a.pcurve.derivatives(np.array([x]), 1)[0], b.pcurve.derivatives(np.array([y]), 1)[0]
            f = da[0] - db[0]
            jac = np.column_stack([da[1], -db[1]])
            if abs(np.linalg.det(jac)) < 1e-300:
                break
            dx, dy = np.linalg.solve(jac, -f)
            x = float(np.clip(x + dx, *a.range))
            y = float(np.clip(y + dy, *b.range))
            if abs(dx) + abs(dy) < 1e-15 * (1 + abs(x) + abs(y)):
                break
        at_end = min(abs(x - a.range[0]), abs(x - a.range[1])) * _speed(a, x) <= eps and \
            min(abs(y - b.range[0]), abs(y - b.range[1])) * _speed(b, y) <= eps
        if at_end:
            continue                                         # two ends that meet: a joint, not a crossing
        if all(abs(x - x0) > 1e-12 * (1 + abs(x)) for x0, _ in out):
            out.append((x, y))
    return out


def _speed(cut: Cut, t: float) -> float:
    return float(np.linalg.norm(cut.pcurve.derivatives(np.array([t]), 1)[0, 1]))


def _cut_point(cut: Cut, face: TrimmedFace, end: int) -> NDArray:
    """The cut's start (``end`` 0) or end point in space."""
    t = np.array([cut.range[end]])
    if cut.curve3d is not None:
        return cut.curve3d.evaluate(t)[0]
    uv = cut.pcurve.evaluate(t)
    return face.surface.evaluate(uv[:, 0], uv[:, 1])[0]


def _regions(face: TrimmedFace, cycles: list[list[TrimEdge]]) -> list[TrimmedFace]:
    """Counter-clockwise cycles as regions, clockwise ones as holes of the smallest region
    containing them."""
    samples = [_loop_samples(cycle) for cycle in cycles]
    areas = [_signed_area(uv) for uv in samples]
    outer = [k for k, a in enumerate(areas) if a > 0]
    holes = [k for k, a in enumerate(areas) if a <= 0]
    members: dict[int, list[int]] = {k: [] for k in outer}
    keys = [_cycle_key(cycle) for cycle in cycles]
    for h in holes:
        point = samples[h][len(samples[h]) // 2:len(samples[h]) // 2 + 1]
        # a region bounded by the hole's own edges run the other way (the island inside a
        # closed cut) does not contain it: its area equals the hole's to rounding, and
        # the hole's points lie on its boundary
        containing = [k for k in outer if keys[k] != keys[h]
                      and inside_loops(point, [samples[k]])[0] and areas[k] > -areas[h]]
        if not containing:
            raise InvalidGeometryError("a clockwise boundary lies in no region (are the loops oriented?)")
        members[min(containing, key=lambda k: areas[k])].append(h)
    out = []
    for k in outer:
        region = [cycles[k]] + [cycles[h] for h in members[k]]
        edges = [e for cycle in region for e in cycle]
        loops = [TrimLoop(tuple(_unpaired_seam(e, edges) for e in cycle)) for cycle in region]
        out.append(TrimmedFace(face.surface, tuple(loops), 0, face.reversed, face.name, face.internal))
    return out


def _cycle_key(cycle: list[TrimEdge]) -> frozenset:
    """The edges of a cycle whatever their direction: its curves and parameter ranges."""
    return frozenset((id(e.curve3d) if e.curve3d is not None else id(e.pcurve),
                      round(e.t0, 12), round(e.t1, 12)) for e in cycle)


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
