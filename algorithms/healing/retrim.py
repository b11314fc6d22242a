"""Faces re-trimmed to their neighbours' edges: gaps wider than ``gap_tol`` closed
where only a face's trimming loop is off (001 §1 "gaps", for :func:`surfprep.heal`).

Exporters write a face's trimming loop at their own tolerance, and a loop can run
beside its neighbours' edges while the face's *surface* passes through them:
occt_k1_catia_theorem.stp's faces 54 and 55 have nine edges each lying 0.09-0.1 mm
(seven times the model's gap tolerance) from their neighbours' edges, and every
one of those neighbours' edges lies within 1e-4 mm of their surfaces. Moving the
surfaces would move the model; re-trimming moves nothing: the face's free edges are
replaced by its neighbours' edges, the 3D curve the neighbour's and the pcurve its
closest-point projection onto the face's surface, so the two faces share the edge's
3D curve, and the gap left in the geometry is the neighbour's distance from the
surface, the new edge's tolerance (the 3D curve on a surface 1e-4 mm away held at
1e-4, where the loop was 0.1 mm off: a gap a neighbour's approximant closes only
by moving a face that was never off).

Partners
    A free edge ``a`` of face F and a free edge ``b`` of another face are partners
    when each is the other's nearest free edge by the Hausdorff distance of their
    samples (both ways), and that distance is at most :data:`RETRIM_WIDTH` times the
    shorter edge's length; two edges paired within ``gap_tol`` but apart in the
    geometry (a *loose* pair, each in no other pair) are partners too. A face may be
    re-trimmed with its partners when its surface holds their edges: within ``tol``
    and within :data:`ON_SURFACE` of how far the edges are apart (a dense sample
    projected, started from the face's own pcurve); otherwise the gap is in the
    geometry, and re-trimming would only hide it in an edge tolerance. Where both
    surfaces hold the other's edge (two faces meeting along a crease, one edge
    longer), the face with more edges off is tried first and the pairs it uses are
    not used the other way round.

The new loop
    An edge paired with a neighbour (within ``gap_tol``) but ending more than
    ``tol`` from the replaced edge next to it is replaced by its pair too, when that
    lies on the surface: the corner moves with the loop. Every replaced edge's
    pcurve interpolates the projections; at a corner with an edge kept, the replaced
    edge's pcurve ends on the kept edge's pcurve end, at a corner between two
    replaced edges both end on the mean of their projections, so the loop closes
    exactly in ``(u, v)``. A face is re-trimmed only when every new edge lies within
    ``tol`` of its surface on a dense sample (the pinned corners included), the loop
    keeps its orientation, and no seam edge is involved; otherwise it is left and
    the note says why.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from ..fitting import interpolate_curve
from ..projection import project_to_surface
from ..trimmed import TrimEdge, TrimLoop, TrimmedFace
from .adjacency import FaceEdge, dense_edge, polyline_distance
from .approximant import DEFAULT_RELATIVE_TOL
from .loop_sides import reverse_curve, signed_area

__all__ = ["CORNER", "OFF", "ON_SURFACE", "PROJECTION_SAMPLES", "RETRIM_WIDTH", "TURNED", "Retrim", "retrim_faces", "retrim_partners"]

#: partners lie at most this share of the shorter edge's length apart
RETRIM_WIDTH = 0.2
#: a partner lies on the face's surface when it is within tol and within this share of
#: how far it is from the face's own edge (else it is a gap in the geometry, not in
#: the trim: re-trimming would only hide it in the edge's tolerance)
ON_SURFACE = 0.1
#: samples of a partner edge projected onto the face (the pcurve interpolates them)
PROJECTION_SAMPLES = 33
#: why a face was not re-trimmed: its loop would not close at a corner next to an edge
#: kept (a partner covering part of an edge, a T-junction) ...
CORNER = "the new loop would not close at a corner next to an edge kept"
#: ... a new edge would leave the surface between the projected samples ...
OFF = "a neighbour's edge leaves the surface"
#: ... the loop would turn the other way round
TURNED = "the new loop would turn the other way round"
#: samples on which the new edge's distance from the surface is measured
_CHECK_SAMPLES = 129


@dataclass(frozen=True)
class Retrim:
    """One face re-trimmed: ``face`` index, the loop positions ``k`` of its edges
    replaced (as :class:`FaceEdge.k`), the partner edges taken ``(face, k)``, how far
    the loop moved (``width``, the largest Hausdorff distance of a replaced edge
    to its partner) and the largest distance of the new edges from the surface
    (``deviation``: the gap left in the geometry)."""

    face: int
    replaced: tuple[int, ...]
    partners: tuple[tuple[int, int], ...]
    width: float
    deviation: float

    def as_dict(self) -> dict:
        return {"face": self.face, "edges": list(self.replaced),
                "partners": [list(p) for p in self.partners], "moved": self.width,
                "deviation": self.deviation}


def _lengths(edges: Sequence[FaceEdge]) -> NDArray:
    return np.array([np.linalg.norm(np.diff(e.samples, axis=0), axis=1).sum() for e in edges])


def _hausdorff(a: FaceEdge, b: FaceEdge, dense_a: NDArray, dense_b: NDArray) -> float:
    return float(max(polyline_distance(a.samples, dense_b).max(),
                     polyline_distance(b.samples, dense_a).max()))


def _nearest(edges: Sequence[FaceEdge], free: Sequence[int]) -> dict[int, tuple[int, float]]:
    """Per free edge its nearest free edge of another face within :data:`RETRIM_WIDTH`
    times the shorter length: ``{a: (b, hausdorff)}``."""
    length = _lengths([edges[k] for k in free])
    dense = {k: dense_edge(edges[k]) for k in free}
    lo = np.array([edges[k].samples.min(axis=0) for k in free])
    hi = np.array([edges[k].samples.max(axis=0) for k in free])
    out: dict[int, tuple[int, float]] = {}
    for i, a in enumerate(free):
        reach = RETRIM_WIDTH * length[i]
        near = np.nonzero(np.all(lo <= hi[i] + reach, axis=1)
                          & np.all(hi >= lo[i] - reach, axis=1))[0]
        for j in near:
            b = free[j]
            if edges[b].face == edges[a].face:
                continue
            h = _hausdorff(edges[a], edges[b], dense[a], dense[b])
            if h <= RETRIM_WIDTH * min(length[i], length[j]) and h < out.get(a, (0, np.inf))[1]:
                out[a] = (b, h)
    return out


def _face_tol(face: TrimmedFace, edges: Sequence[FaceEdge], tol: float | None) -> float:
    if tol is not None:
        return tol
    pts = np.concatenate([e.samples for e in edges])
    return DEFAULT_RELATIVE_TOL * float(np.linalg.norm(np.ptp(pts, axis=0)))


def _projection(face: TrimmedFace, own: FaceEdge, other: FaceEdge, n: int
                ) -> tuple[NDArray, NDArray, NDArray, float]:
    """``other``'s curve, oriented as ``own``'s, projected onto ``face``'s surface from
    ``own``'s pcurve: parameters ``(n,)``, uv ``(n, 2)``, the oriented curve's points
    ``(n, 3)`` and the largest distance."""
    curve = _oriented(other.curve, own.curve)
    t = np.linspace(*curve.domain, n)
    points = curve.evaluate(t)
    trim = _trim_edge(face, own)
    t_own = np.linspace(trim.t0, trim.t1, _CHECK_SAMPLES)
    own_xyz, own_uv = trim.curve3d.evaluate(t_own), trim.pcurve.evaluate(t_own)
    nearest = np.argmin(np.linalg.norm(points[:, None] - own_xyz[None], axis=2), axis=1)
    proj = project_to_surface(face.surface, points, guess=own_uv[nearest])
    return t, proj.uv, points, float(proj.distance.max())


def _oriented(curve, like):
    """``curve`` run the way ``like`` runs (ends matched)."""
    p0, p1 = curve.evaluate(np.array(curve.domain))
    q0, q1 = like.evaluate(np.array(like.domain))
    same = np.linalg.norm(p0 - q0) + np.linalg.norm(p1 - q1)
    crossed = np.linalg.norm(p0 - q1) + np.linalg.norm(p1 - q0)
    return curve if same <= crossed else reverse_curve(curve)


def _positions(face: TrimmedFace) -> dict[int, tuple[int, int]]:
    """``FaceEdge.k`` -> (loop index, position) for every edge of ``face`` (the
    numbering of :func:`.adjacency.face_edges`)."""
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


def _trim_edge(face: TrimmedFace, edge: FaceEdge) -> TrimEdge:
    n, p = _positions(face)[edge.k]
    return face.loops[n].edges[p]


def retrim_partners(faces: Sequence[TrimmedFace | None], edges: Sequence[FaceEdge],
                    free: Sequence[int], *, loose: Sequence[tuple[int, int, float]] = (),
                    tol: float | None = None) -> list[tuple[int, int, float, float]]:
    """Which edges could be replaced by which: ``(a, b, width, distance)`` with ``a`` an
    edge of the face to re-trim, ``b`` its partner (indices into ``edges``), how far
    apart they are and ``b``'s largest distance from ``a``'s surface (module
    docstring). Candidates are the free edges that are each other's nearest, and the
    ``loose`` pairs ``(a, b, gap)`` (paired at ``gap_tol`` but ``gap`` apart in the
    geometry; ``a``'s face the one to re-trim, each edge in one such pair). A pair whose surfaces both hold the other's edge (two faces meeting
    along a crease, one edge longer) is listed both ways. ``tol``: model units;
    default 1e-3 x each face's edge-box diagonal."""
    nearest = _nearest(edges, free)
    candidates, seen = [], set()
    for a, (b, width) in nearest.items():
        if nearest.get(b, (None,))[0] == a and (b, a) not in seen:
            seen.add((a, b))
            candidates.append((a, b, width))
    directions = [((a, b), (b, a)) for a, b, _ in candidates]
    once = _once(loose)
    loose = [(a, b, gap) for a, b, gap in loose if a in once and b in once]
    candidates += loose
    directions += [((a, b),) for a, b, _ in loose]
    out = []
    for (a, b, width), ways in zip(candidates, directions):
        for own, other in ways:
            face = faces[edges[own].face]
            if face is None or faces[edges[other].face] is None or any(
                    e.is_seam for loop in face.loops for e in loop.edges):
                continue
            mine = [e for e in edges if e.face == edges[own].face]
            distance = _projection(face, edges[own], edges[other], 17)[3]
            if distance <= min(_face_tol(face, mine, tol), ON_SURFACE * width):
                out.append((own, other, width, distance))
    return out


def _once(pairs: Sequence[tuple[int, int, float]]) -> set[int]:
    """The edges that occur in exactly one of ``pairs``."""
    count: dict[int, int] = {}
    for a, b, _ in pairs:
        count[a] = count.get(a, 0) + 1
        count[b] = count.get(b, 0) + 1
    return {k for k, n in count.items() if n == 1}


def retrim_faces(faces: Sequence[TrimmedFace | None], edges: Sequence[FaceEdge],
                 free: Sequence[int], *, pairs: Sequence[tuple[int, int]] = (),
                 loose: Sequence[tuple[int, int, float]] = (), tol: float | None = None
                 ) -> tuple[list[TrimmedFace | None], list[Retrim],
                            list[tuple[int, str, float]]]:
    """The faces with their free edges replaced by their partners' (module docstring).

    Parameters
    ----------
    faces : sequence of TrimmedFace or None
    edges : sequence of FaceEdge
        :func:`.adjacency.face_edges` of ``faces``.
    free : sequence of int
        Indices into ``edges`` paired with no other edge (at the caller's ``gap_tol``).
    pairs : sequence of (int, int)
        The edges paired at ``gap_tol``: an edge of a re-trimmed face whose end is off
        its re-trimmed neighbour's by more than ``tol`` is replaced by its pair's
        curve too (the corner moves with the loop).
    loose : sequence of (int, int, float)
        Pairs of ``pairs`` not closed in the geometry, with their gap, the first
        edge's face the one that may be re-trimmed: candidates too (an edge written
        beside its neighbour's within ``gap_tol`` on a face nothing else will close).
    tol : float, optional
        Model units: how far from the face's surface a new edge may lie (on
        :data:`_CHECK_SAMPLES` samples, closest-point projection). Default 1e-3 x
        each face's edge-box diagonal, as the approximants' default.

    Returns
    -------
    faces : list of TrimmedFace or None
        ``faces`` with the re-trimmed ones replaced (same indices).
    retrims : list of Retrim
    refused : list of (int, str, float)
        Faces with partners that were not re-trimmed: the face, why (:data:`CORNER`,
        :data:`OFF` or :data:`TURNED`) and the distance that stopped it.
    """
    out = list(faces)
    by_face: dict[int, list[tuple[int, int, float]]] = {}
    for a, b, width, _ in retrim_partners(faces, edges, free, loose=loose, tol=tol):
        by_face.setdefault(edges[a].face, []).append((a, b, width))
    retrims, refused = [], []
    partner_of: dict[int, int] = {}
    for a, b in pairs:
        partner_of.setdefault(a, b)
        partner_of.setdefault(b, a)
    consumed: set[frozenset] = set()     # partner pairs a re-trimmed face has used
    # the face with most edges off first: of two faces meeting along a crease, the one
    # whose whole loop is off (a lid trimmed short) is re-trimmed, not its walls
    for f, swaps in sorted(by_face.items(), key=lambda item: (-len(item[1]), item[0])):
        swaps = [s for s in swaps if frozenset(s[:2]) not in consumed]
        if not swaps:
            continue
        face = faces[f]
        mine = [e for e in edges if e.face == f]
        face_tol = _face_tol(face, mine, tol)
        swaps = _with_corners_moved(face, edges, swaps, partner_of, face_tol)
        try:
            new, deviation = _retrimmed(face, edges, swaps, face_tol)
        except _Refused as exc:
            refused.append((f, exc.why, exc.figure))
            continue
        out[f] = new
        consumed.update(frozenset(s[:2]) for s in swaps)
        retrims.append(Retrim(f, tuple(edges[a].k for a, _, _ in swaps),
                              tuple((edges[b].face, edges[b].k) for _, b, _ in swaps),
                              max(w for _, _, w in swaps), deviation))
    return out, retrims, refused


class _Refused(Exception):
    def __init__(self, why: str, figure: float):
        super().__init__(why)
        self.why, self.figure = why, figure


def _with_corners_moved(face: TrimmedFace, edges: Sequence[FaceEdge], swaps: list,
                        partner_of: dict[int, int], tol: float) -> list:
    """``swaps`` grown by the paired edges of ``face`` next to a replaced edge whose end
    is more than ``tol`` from the replacing curve's: each replaced by its pair's curve
    when that lies on the surface within ``tol``."""
    by_k = {e.k: n for n, e in enumerate(edges) if e is not None and e.face == edges[
        swaps[0][0]].face}
    where = _positions(face)
    at = {v: k for k, v in where.items()}
    swaps = list(swaps)
    grown = True
    while grown:
        grown = False
        taken = {edges[a].k: (a, b) for a, b, _ in swaps}
        for k, (a, b) in list(taken.items()):
            n, p = where[k]
            size = len(face.loops[n].edges)
            new_ends = _oriented(edges[b].curve, edges[a].curve).evaluate(
                np.array(edges[b].curve.domain))
            for q in ((p + 1) % size, (p - 1) % size):
                kq = at.get((n, q))
                c = by_k.get(kq)
                if c is None or kq in taken or c not in partner_of:
                    continue
                ends = edges[c].ends
                if np.min(np.linalg.norm(ends[:, None] - new_ends[None], axis=2)) <= tol:
                    continue
                other = partner_of[c]
                if _projection(face, edges[c], edges[other], 17)[3] > tol:
                    continue
                swaps.append((c, other, float(np.max(polyline_distance(
                    edges[c].samples, dense_edge(edges[other]))))))
                taken[kq] = (c, other)
                grown = True
    return swaps


def _retrimmed(face: TrimmedFace, edges: Sequence[FaceEdge], swaps, tol: float
               ) -> tuple[TrimmedFace, float]:
    """``face`` with the edges of ``swaps`` (``(a, b, width)``) replaced; the new edges'
    largest distance from the surface."""
    where = _positions(face)
    plan: dict[tuple[int, int], tuple[FaceEdge, FaceEdge]] = {}
    for a, b, _ in swaps:
        plan[where[edges[a].k]] = (edges[a], edges[b])
    # projections in each edge's natural direction
    proj = {}
    for key, (own, other) in plan.items():
        t, uv, _points, distance = _projection(face, own, other, PROJECTION_SAMPLES)
        if distance > tol:
            raise _Refused(OFF, distance)
        proj[key] = [t, uv.copy(), _oriented(other.curve, own.curve)]
    _pin_corners(face, proj)
    for t, uv, curve in proj.values():
        ends = face.surface.evaluate(uv[[0, -1], 0], uv[[0, -1], 1])
        off = float(np.linalg.norm(ends - curve.evaluate(np.array([t[0], t[-1]])), axis=1).max())
        if off > tol:
            raise _Refused(CORNER, off)
    loops, deviation = [], 0.0
    for n, loop in enumerate(face.loops):
        new_edges = []
        for p, e in enumerate(loop.edges):
            if (n, p) not in proj:
                new_edges.append(e)
                continue
            t, uv, curve = proj[(n, p)]
            pcurve = interpolate_curve(uv, parameters=t)
            check = np.linspace(t[0], t[-1], _CHECK_SAMPLES)
            on = pcurve.evaluate(check)
            gap = float(np.linalg.norm(face.surface.evaluate(on[:, 0], on[:, 1])
                                       - curve.evaluate(check), axis=1).max())
            if gap > tol:
                raise _Refused(OFF, gap)
            deviation = max(deviation, gap)
            new_edges.append(TrimEdge(curve, pcurve, t[0], t[-1], e.reversed,
                                      max(e.tolerance, 1.001 * gap),
                                      vertex_tolerances=(1.001 * gap, 1.001 * gap)))
        loops.append(TrimLoop(new_edges))
    new = replace(face, loops=tuple(loops))
    for old_loop, new_loop in zip(face.loops, new.loops):
        if np.sign(signed_area(_outline(old_loop))) != np.sign(signed_area(_outline(new_loop))):
            raise _Refused(TURNED, 0.0)
    return new, deviation


def _ends_uv(edge: TrimEdge) -> tuple[NDArray, NDArray]:
    """A kept edge's pcurve at its start and end in loop direction."""
    uv = edge.pcurve.evaluate(np.array([edge.t0, edge.t1]))
    return (uv[1], uv[0]) if edge.reversed else (uv[0], uv[1])


def _pin_corners(face: TrimmedFace, proj: dict) -> None:
    """Make the projected uv of replaced edges meet their neighbours in the loop:
    a kept neighbour's pcurve end wins, two replaced edges meet at their mean."""
    for (n, p), entry in list(proj.items()):
        loop = face.loops[n].edges
        q = (p + 1) % len(loop)                  # the next edge in loop direction
        end_row = 0 if loop[p].reversed else -1   # this edge's end, in its natural order
        if (n, q) in proj:
            start_row = -1 if loop[q].reversed else 0
            mean = 0.5 * (entry[1][end_row] + proj[(n, q)][1][start_row])
            entry[1][end_row] = mean
            proj[(n, q)][1][start_row] = mean
        else:
            entry[1][end_row] = _ends_uv(loop[q])[0]
        r = (p - 1) % len(loop)                  # the previous edge
        if (n, r) not in proj:
            start_row = -1 if loop[p].reversed else 0
            entry[1][start_row] = _ends_uv(loop[r])[1]


def _outline(loop: TrimLoop) -> NDArray:
    pts = []
    for e in loop.edges:
        uv = e.pcurve.evaluate(np.linspace(e.t0, e.t1, 17))
        pts.append((uv[::-1] if e.reversed else uv)[:-1])
    return np.concatenate(pts)
