"""Sides of heal's approximants fitted to the edges of faces kept as they were (the joins
of 001 §8 where the neighbour is not an approximant).

A side of an approximant that meets a face :func:`surfprep.heal` keeps (not
another approximant) is fitted to that face's edge or edges
(:func:`fit_side_to_curve`), with the corners it shares with other approximants
moved first onto the edge's ends, so the gap to the kept face closes up to the
fit error instead of being left to the sewing tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ..projection import project_to_curve
from .adjacency import EDGE_SAMPLES, FaceEdge, dense_edge, polyline_distance
from .connectivity import Side, corner_number, side_points
from .continuity import covered_samples, fit_side_to_curve
from .measure_joins import measure_join
from .network import Network

__all__ = ["MAX_SNAP_SPANS", "SNAP_CHECK_SAMPLES", "PartialTarget", "snap_to_originals"]

#: knot spans along a snapped side at most
MAX_SNAP_SPANS = 64
#: samples along a snapped side where its gap to the edge is checked
SNAP_CHECK_SAMPLES = 257

@dataclass(frozen=True, eq=False)
class PartialTarget:
    """Edges lying along PART of a side, the rest of the side meeting nothing: only the
    samples along them are fitted (:func:`fit_side_to_curve` with ``cover_tol``)."""

    curves: list
    cover_tol: float


def _matching_edge(side: NDArray, dense_side: NDArray, edges: list[FaceEdge], gap_tol: float):
    """What ``side`` is fitted to: the edge lying closest along the whole side, within
    ``gap_tol`` both ways; else the pieces of edges lying along the side
    (:func:`_edge_pieces`: whole edges, or the part of an edge between the
    projections of the side's ends, for a side meeting only part of an edge) that
    together cover it, of one face if they can, as a list; else None."""
    lo, hi = side.min(axis=0) - gap_tol, side.max(axis=0) + gap_tol
    best, best_distance = None, gap_tol
    near = []
    for e in edges:
        if np.any(e.samples.min(axis=0) > hi) or np.any(e.samples.max(axis=0) < lo):
            continue
        near.append(e)
        along = polyline_distance(e.samples, dense_side).max()
        if along > gap_tol:
            continue
        distance = max(along, polyline_distance(side, dense_edge(e)).max())
        if distance <= best_distance:
            best, best_distance = e.curve, distance
    if best is not None:
        return best
    pieces = [(e.face, c) for e in near for c in _edge_pieces(e, side, dense_side, gap_tol)]
    if not pieces:
        return None
    groups = [[c for f, c in pieces if f == face] for face in dict.fromkeys(f for f, _ in pieces)]
    groups.append([c for _, c in pieces])
    for curves in groups:
        cover = np.min([polyline_distance(side, _dense(c)) for c in curves], axis=0)
        if cover.max() <= gap_tol:
            return curves[0] if len(curves) == 1 else curves
    ended = [e for e in near if polyline_distance(e.ends, dense_side).max() <= gap_tol
             and polyline_distance(e.samples, dense_side).max() <= gap_tol]
    by_face = [[e.curve for e in ended if e.face == face] for face in {e.face for e in ended}]
    return _partial(side, by_face, gap_tol)


def _partial(side: NDArray, groups: list[list], gap_tol: float) -> PartialTarget | None:
    """The edges of the one face lying along part of the side with both ends on it, when
    the part they cover is one stretch from one of the side's ends (a kept face meets
    the side there, the rest is free); else None. Edges with an end off the side are
    left out: an edge leaving a side at a shallow angle near its end lies within
    ``gap_tol`` of it over a short stretch without meeting it."""
    if len(groups) != 1 or not groups[0]:
        return None
    curves = groups[0]
    near = np.min([polyline_distance(side, _dense(c)) for c in curves], axis=0) <= gap_tol
    changes = np.count_nonzero(np.diff(near.astype(int)))
    if changes != 1:
        return None
    return PartialTarget(curves, gap_tol)


def _dense(curve, n: int = 129) -> NDArray:
    return curve.evaluate(np.linspace(*curve.domain, n))


def _edge_pieces(edge: FaceEdge, side: NDArray, dense_side: NDArray, gap_tol: float) -> list:
    """The part of ``edge`` lying along ``side`` (within ``gap_tol``), as curves: the
    edge restricted between the projections of the side's two ends (both pieces of a
    closed edge's wrap-around, when the side runs over its seam); [] when that part
    is shorter than ``gap_tol`` (a corner contact) or leaves the side."""
    curve = edge.curve
    t0, t1 = curve.domain
    ends = project_to_curve(curve, side[[0, -1]]).t
    a, b = float(min(ends)), float(max(ends))
    span = t1 - t0
    closed = np.linalg.norm(edge.ends[0] - edge.ends[1]) <= gap_tol
    candidates = [[(a, b)]]
    if closed:
        candidates.append([(b, t1), (t0, a)])
    for intervals in candidates:
        intervals = [(x, y) for x, y in intervals if y - x > 1e-9 * span]
        if not intervals:
            continue
        curves = [curve if (y - x) >= (1 - 1e-9) * span else curve.restrict(x, y)
                  for x, y in intervals]
        samples = np.concatenate([_dense(c, 17) for c in curves])
        length = sum(float(np.linalg.norm(np.diff(_dense(c, 17), axis=0), axis=1).sum())
                     for c in curves)
        if length > gap_tol and polyline_distance(samples, dense_side).max() <= gap_tol:
            return curves
    return []


def _in_cluster(patch: int, side: Side, end: int, members: set) -> bool:
    """Whether the corner at ``end`` of ``side`` is shared with another approximant."""
    number = corner_number(side, end)
    return any(corner_number(s, e) == number for p, s, e in members if p == patch)


def _snapped(surface, side: Side, target, free: tuple[bool, bool], tight: float):
    """``surface`` with ``side`` fitted to ``target`` (an edge or a list of edges): knot
    spans along the side doubled (up to :data:`MAX_SNAP_SPANS`) until the side lies
    within ``tight`` of the edges."""
    curves = _curves(target)
    spans = min(MAX_SNAP_SPANS, sum(2 * (np.unique(c.knots).size - 1) for c in curves) + 8)
    while True:
        partial = isinstance(target, PartialTarget)
        fitted = fit_side_to_curve(surface, side, curves, min_spans=spans, free_corners=free,
                                   cover_tol=target.cover_tol if partial else None)
        pts = side_points(fitted, side, SNAP_CHECK_SAMPLES)
        found = [project_to_curve(c, pts) for c in curves]
        nearest = np.argmin(np.stack([f.distance for f in found]), axis=0)
        gap = np.stack([f.distance for f in found])[nearest, np.arange(pts.shape[0])]
        if partial:
            gap = gap[covered_samples(curves, found, nearest, target.cover_tol)]
        gap = gap.max(initial=0.0)
        if spans >= MAX_SNAP_SPANS or gap <= tight:
            return fitted
        spans = min(MAX_SNAP_SPANS, 2 * spans)


def _curves(target) -> list:
    if isinstance(target, PartialTarget):
        return target.curves
    return target if isinstance(target, list) else [target]


def snap_to_originals(network: Network, edges: list[FaceEdge], gap_tol: float,
                       tight: float) -> tuple[Network, int]:
    """Sides of approximants that meet a face kept as it was (not another approximant)
    fitted to that face's edge (:func:`fit_side_to_curve`), joins measured again.

    A corner shared with other approximants is first moved, in every patch that
    shares it, onto the nearer end of the edge (:func:`_pin_corners`), so the side
    can follow the edge to its end instead of stopping at the averaged corner.

    Then the T-junctions between approximants, which :func:`connect` does not join
    (it joins whole sides only): a free side lying along PART of another
    approximant's free side (e.g. two sides of a split face's sub-patch, meeting at
    a straight corner, along one side of a neighbour) is fitted to that part; the
    longer side stays.
    """
    shared = {(e.a, e.side_a) for e in network.edges} | {(e.b, e.side_b) for e in network.edges}
    patches = list(network.patches)
    clusters = network.connectivity.corners
    targets = _targets(patches, shared, edges, gap_tol)
    _apply(patches, targets, clusters, tight)
    done = shared | {(p, side) for p, side, _ in targets}
    longer = _targets(patches, done, _free_sides(patches, done), gap_tol, part_only=True)
    _apply(patches, longer, clusters, tight)
    if not targets and not longer:
        return network, 0
    joins = tuple(measure_join(patches, e) for e in network.edges)
    return replace(network, patches=tuple(patches), joins=joins), len(targets) + len(longer)


def _targets(patches: list, skip: set, edges: list[FaceEdge], gap_tol: float,
             part_only: bool = False) -> list:
    """``(patch, side, target)`` for the sides not in ``skip`` that :func:`_matching_edge`
    finds among ``edges`` (those of the patch itself left out; boxes tested at once);
    with ``part_only`` only a strict part of one edge (a side along a whole edge, or
    covered by several, is left alone)."""
    if not edges:
        return []
    lo = np.array([e.samples.min(axis=0) for e in edges]) - gap_tol
    hi = np.array([e.samples.max(axis=0) for e in edges]) + gap_tol
    owner = np.array([e.face for e in edges])
    out = []
    for p in range(len(patches)):
        for side in Side:
            if (p, side) in skip:
                continue
            pts = side_points(patches[p], side, 17)
            near = np.all((lo <= pts.max(axis=0)) & (hi >= pts.min(axis=0)), axis=1)
            near &= owner != -1 - p
            if not near.any():
                continue
            candidates = [edges[k] for k in np.flatnonzero(near)]
            target = _matching_edge(pts, side_points(patches[p], side, 129), candidates,
                                    gap_tol)
            if target is None or (part_only and (
                    isinstance(target, (list, PartialTarget))
                    or any(target is e.curve for e in candidates))):
                continue
            out.append((p, side, target))
    return out


def _free_sides(patches: list, skip: set) -> list[FaceEdge]:
    """The sides of approximants not in ``skip`` as :class:`FaceEdge` (face ``-1 - q``
    for patch ``q``)."""
    out = []
    for q, surface in enumerate(patches):
        for k, side in enumerate(Side):
            if (q, side) in skip:
                continue
            curve = surface.isocurve(side.parameter(surface), side.fixed)
            out.append(FaceEdge(-1 - q, k, curve,
                                curve.evaluate(np.linspace(*curve.domain, EDGE_SAMPLES))))
    return out


def _apply(patches: list, targets: list, clusters, tight: float) -> None:
    """Corners pinned, then every target side fitted (``patches`` changed in place)."""
    if not targets:
        return
    _pin_corners(patches, targets, clusters, tight)
    in_clusters = {(m[0], m[1], m[2]) for c in clusters for m in c.members}
    for p, side, target in targets:
        free = tuple(not _in_cluster(p, side, end, in_clusters)
                     and _near_an_end(patches[p], side, end, target) for end in (0, 1))
        patches[p] = _snapped(patches[p], side, target, free, tight)


def _corner_index(surface, number: int) -> tuple[int, int]:
    nu, nv = surface.n_control
    return (0 if number % 2 == 0 else nu - 1), (0 if number // 2 == 0 else nv - 1)


def _near_an_end(surface, side: Side, end: int, target) -> bool:
    """Whether the corner may move onto an end of ``target``: always for a target along
    the whole side; for a :class:`PartialTarget` only a corner within its ``cover_tol``."""
    if not isinstance(target, PartialTarget):
        return True
    corner = side_points(surface, side, 2)[end]
    ends = np.concatenate([c.evaluate(np.array(c.domain)) for c in target.curves])
    return bool(np.linalg.norm(ends - corner, axis=1).min() <= target.cover_tol)


def _pin_corners(patches: list, targets: list, clusters, tight: float) -> None:
    """Corners of approximant clusters moved (in place, in every member patch: their
    shared boundary rows stay identical) onto the end of a kept face's edge a member
    side is snapped to, where they are farther from it than ``tight``."""
    for p, side, target in targets:
        ends = np.concatenate([c.evaluate(np.array(c.domain)) for c in _curves(target)])
        for end in (0, 1):
            number = corner_number(side, end)
            cluster = next((c for c in clusters if any(
                m[0] == p and corner_number(m[1], m[2]) == number for m in c.members)), None)
            if cluster is None:
                continue
            i, j = _corner_index(patches[p], number)
            corner = patches[p].control_points[i, j]
            goal = ends[int(np.argmin(np.linalg.norm(ends - corner, axis=1)))]
            reach = target.cover_tol if isinstance(target, PartialTarget) else np.inf
            if not tight < np.linalg.norm(goal - corner) <= reach:
                continue
            for q in {m[0] for m in cluster.members}:
                numbers = {corner_number(m[1], m[2]) for m in cluster.members if m[0] == q}
                net = patches[q].control_points.copy()
                for n in numbers:
                    net[_corner_index(patches[q], n)] = goal
                patches[q] = replace(patches[q], control_points=net)
