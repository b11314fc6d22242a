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
    shorter edge's length; a free edge and a chain of shorter free edges of other
    faces lying along it end to end (a T-junction, occt_k1geo_autocad.stp: a circle
    of 2.8 mm against three edges of two faces, 6e-4 mm off it and exactly on its
    surface) are partners, the edge replaced by the chain; two edges paired within
    ``gap_tol`` but apart in the geometry (a *loose* pair, each in no other pair) are
    partners too. Of several options for one edge the narrowest is taken. A face may be
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
from ..trimmed import DEFAULT_TOLERANCE, TrimEdge, TrimLoop, TrimmedFace
from .adjacency import FaceEdge, dense_edge, edge_positions, polyline_distance
from .approximant import DEFAULT_RELATIVE_TOL
from .loop_sides import reverse_curve, signed_area

__all__ = ["CORNER", "OFF", "ON_SURFACE", "PROJECTION_SAMPLES", "RETRIM_WIDTH", "TURNED",
           "Retrim", "retrim_faces", "retrim_partners"]

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


def _face_tols(edges: Sequence[FaceEdge], tol: float | None) -> dict[int, float]:
    """Per face (that has edges) the tolerance a re-trim of it is held to: ``tol``, or
    :data:`DEFAULT_RELATIVE_TOL` x the diagonal of its edges' box."""
    lo: dict[int, NDArray] = {}
    hi: dict[int, NDArray] = {}
    for e in edges:
        lo[e.face] = np.minimum(lo.get(e.face, np.inf), e.samples.min(axis=0))
        hi[e.face] = np.maximum(hi.get(e.face, -np.inf), e.samples.max(axis=0))
    if tol is not None:
        return dict.fromkeys(lo, tol)
    return {f: DEFAULT_RELATIVE_TOL * float(np.linalg.norm(hi[f] - lo[f])) for f in lo}


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
    """``curve`` run the way ``like`` runs: its start nearer ``like``'s start than its
    end is, along ``like`` (a partner of the whole edge or one piece of a chain)."""
    line = like.evaluate(np.linspace(*like.domain, 65))
    p0, p1 = curve.evaluate(np.array(curve.domain))
    i0 = np.argmin(np.linalg.norm(line - p0, axis=1))
    i1 = np.argmin(np.linalg.norm(line - p1, axis=1))
    if i0 != i1:
        closed = np.linalg.norm(line[0] - line[-1]) <= 1e-6 * np.ptp(line, axis=0).max()
        forward = (i0 > i1) if closed and abs(int(i0) - int(i1)) > len(line) // 2 else i0 < i1
        return curve if forward else reverse_curve(curve)
    ahead = float(np.dot(p1 - p0, line[-1] - line[0]))
    return curve if ahead >= 0 else reverse_curve(curve)


def _trim_edge(face: TrimmedFace, edge: FaceEdge) -> TrimEdge:
    n, p = edge_positions(face)[edge.k]
    return face.loops[n].edges[p]


def retrim_partners(faces: Sequence[TrimmedFace | None], edges: Sequence[FaceEdge],
                    free: Sequence[int], *, loose: Sequence[tuple[int, int, float]] = (),
                    tol: float | None = None
                    ) -> list[tuple[int, tuple[int, ...], float, float]]:
    """Which edges could be replaced by which: ``(a, (b, ...), width, distance)`` with
    ``a`` an edge of the face to re-trim, its partner or its chain of partners in
    order along ``a`` (indices into ``edges``), how far apart they are and the
    partners' largest distance from ``a``'s surface (module docstring). Candidates
    are the free edges that are each other's nearest, a free edge and the free edges
    of other faces lying along it end to end (a T-junction: one long edge against a
    chain of short ones), and the ``loose`` pairs ``(a, b, gap)`` (paired at
    ``gap_tol`` but ``gap`` apart in the geometry; ``a``'s face the one to re-trim,
    each edge in one such pair). A pair whose surfaces both hold the other's edge
    (two faces meeting along a crease, one edge longer) is listed both ways.
    ``tol``: model units; default 1e-3 x each face's edge-box diagonal."""
    nearest = _nearest(edges, free)
    candidates, seen = [], set()
    for a, (b, width) in nearest.items():
        if nearest.get(b, (None,))[0] == a and (b, a) not in seen:
            seen.add((a, b))
            candidates.append((a, (b,), width))
    directions = [((a, bs), (bs[0], (a,))) for a, bs, _ in candidates]
    chains = _chains(edges, free)
    candidates += chains
    directions += [((a, bs),) for a, bs, _ in chains]
    once = _once(loose)
    loose = [(a, (b,), gap) for a, b, gap in loose if a in once and b in once]
    candidates += loose
    directions += [((a, bs),) for a, bs, _ in loose]
    out, tols = [], _face_tols(edges, tol)
    for (_, _, width), ways in zip(candidates, directions):
        for own, others in ways:
            face = faces[edges[own].face]
            if face is None or any(faces[edges[b].face] is None for b in others) or any(
                    e.is_seam for loop in face.loops for e in loop.edges):
                continue
            distance = max(_projection(face, edges[own], edges[b], 17)[3] for b in others)
            if distance <= min(tols[edges[own].face], ON_SURFACE * width):
                out.append((own, others, width, distance))
    best: dict[int, tuple] = {}            # per edge the narrowest of its options
    for option in out:
        if option[0] not in best or option[2] < best[option[0]][2]:
            best[option[0]] = option
    return list(best.values())


def _chains(edges: Sequence[FaceEdge], free: Sequence[int]
            ) -> list[tuple[int, tuple[int, ...], float]]:
    """Free edges covered end to end by two or more free edges of other faces, each
    lying along it within :data:`RETRIM_WIDTH` of its own length and meeting the next
    within that share of the shortest: ``(a, (b1, b2, ...), width)``, the chain in
    order along ``a``'s natural direction, ``width`` the Hausdorff distance between
    ``a`` and the chain. An edge is in at most one chain."""
    length = dict(zip(free, _lengths([edges[k] for k in free])))
    dense = {k: dense_edge(edges[k]) for k in free}
    lo = {k: edges[k].samples.min(axis=0) for k in free}
    hi = {k: edges[k].samples.max(axis=0) for k in free}
    out, used = [], set()
    for a in sorted(free, key=lambda k: -length[k]):
        if a in used:
            continue
        reach = RETRIM_WIDTH * length[a]
        closed = bool(np.linalg.norm(np.diff(edges[a].ends, axis=0)) <= 1e-6 * length[a])
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(dense[a], axis=0),
                                                              axis=1))])
        pieces = []
        for b in free:
            if (b in used or b == a or edges[b].face == edges[a].face
                    or length[b] >= length[a] or np.any(lo[b] > hi[a] + reach)
                    or np.any(hi[b] < lo[a] - reach)):
                continue
            off = float(polyline_distance(edges[b].samples, dense[a]).max())
            if off > RETRIM_WIDTH * length[b]:
                continue
            ends = sorted(arc[np.argmin(np.linalg.norm(dense[a] - p, axis=1))]
                          for p in edges[b].ends)
            if closed and ends[1] - ends[0] > 1.5 * length[b]:    # across a's start
                ends = [ends[1], arc[-1]]
            pieces.append((ends[0], ends[1], b, off))
        chain = _covering(sorted(pieces), arc[-1], length)
        if chain is None or len(chain) < 2:
            continue
        joined = np.concatenate([dense[b] for b in chain])
        width = max(float(polyline_distance(edges[a].samples, joined).max()),
                    max(p[3] for p in pieces if p[2] in chain))
        if width > RETRIM_WIDTH * min(length[b] for b in chain):
            continue
        out.append((a, tuple(chain), width))
        used.update((a, *chain))
    return out


def _covering(pieces: list, total: float, length: dict) -> list[int] | None:
    """The pieces ``(start, end, edge, offset)`` (arc positions along the long edge,
    sorted) that tile ``[0, total]``, each next one starting where the last ended
    within :data:`RETRIM_WIDTH` of the shorter's length; None when they do not."""
    chain, at = [], 0.0
    while at < total:
        slack = [p for p in pieces if abs(p[0] - at) <= RETRIM_WIDTH * length[p[2]]
                 and p[1] > at and p[2] not in chain]
        if not slack:
            return None
        _start, end, b, _ = min(slack, key=lambda p: (abs(p[0] - at), p[3]))
        chain.append(b)
        at = end
        if total - at <= RETRIM_WIDTH * length[b]:
            return chain
    return chain


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
    by_face: dict[int, list[tuple[int, tuple[int, ...], float]]] = {}
    for a, bs, width, _ in retrim_partners(faces, edges, free, loose=loose, tol=tol):
        by_face.setdefault(edges[a].face, []).append((a, bs, width))
    retrims, refused, tols = [], [], _face_tols(edges, tol)
    partner_of: dict[int, int] = {}
    for a, b in pairs:
        partner_of.setdefault(a, b)
        partner_of.setdefault(b, a)
    consumed: set[frozenset] = set()     # partner pairs a re-trimmed face has used
    # the face with most edges off first: of two faces meeting along a crease, the one
    # whose whole loop is off (a lid trimmed short) is re-trimmed, not its walls
    for f, swaps in sorted(by_face.items(), key=lambda item: (-len(item[1]), item[0])):
        swaps = [s for s in swaps if not {frozenset((s[0], b)) for b in s[1]} & consumed]
        if not swaps:
            continue
        face = faces[f]
        face_tol = tols[f]
        swaps = _with_corners_moved(face, edges, swaps, partner_of, face_tol)
        try:
            new, deviation = _retrimmed(face, edges, swaps, face_tol)
        except _Refused as exc:
            refused.append((f, exc.why, exc.figure))
            continue
        out[f] = new
        consumed.update(frozenset((a, b)) for a, bs, _ in swaps for b in bs)
        retrims.append(Retrim(f, tuple(edges[a].k for a, _, _ in swaps),
                              tuple((edges[b].face, edges[b].k) for _, bs, _ in swaps
                                    for b in bs),
                              max(w for _, _, w in swaps), deviation))
    return out, retrims, refused


class _Refused(Exception):
    def __init__(self, why: str, figure: float):
        super().__init__(why)
        self.why, self.figure = why, figure


def _with_corners_moved(face: TrimmedFace, edges: Sequence[FaceEdge], swaps: list,
                        partner_of: dict[int, int], tol: float) -> list:
    """``swaps`` grown by the paired edges of ``face`` next to a replaced edge whose end
    is more than ``tol`` from the replacing curves' ends: each replaced by its pair's
    curve when that lies on the surface within ``tol``."""
    f = edges[swaps[0][0]].face
    by_k = {e.k: n for n, e in enumerate(edges) if e.face == f}
    where = edge_positions(face)
    at = {v: k for k, v in where.items()}
    swaps = list(swaps)
    grown = True
    while grown:
        grown = False
        taken = {edges[a].k: (a, bs) for a, bs, _ in swaps}
        for k, (a, bs) in list(taken.items()):
            n, p = where[k]
            size = len(face.loops[n].edges)
            new_ends = np.array([_oriented(edges[b].curve, edges[a].curve).evaluate(
                np.array(edges[b].curve.domain)) for b in bs]).reshape(-1, 3)
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
                swaps.append((c, (other,), float(np.max(polyline_distance(
                    edges[c].samples, dense_edge(edges[other]))))))
                taken[kq] = (c, (other,))
                grown = True
    return swaps


def _retrimmed(face: TrimmedFace, edges: Sequence[FaceEdge], swaps, tol: float
               ) -> tuple[TrimmedFace, float]:
    """``face`` with the edges of ``swaps`` (``(a, (b, ...), width)``) replaced, each by
    its partner or by its chain of partners; the new edges' largest distance from the
    surface."""
    where = edge_positions(face)
    plan = {where[edges[a].k]: (edges[a], [edges[b] for b in bs]) for a, bs, _ in swaps}
    loops, deviation = [], 0.0
    for n, loop in enumerate(face.loops):
        slots = []                  # loop order: a kept TrimEdge, or [t, uv, curve, reversed]
        for p, e in enumerate(loop.edges):
            if (n, p) not in plan:
                slots.append(e)
                continue
            own, others = plan[(n, p)]
            pieces = []
            for other in others:    # along own's natural direction
                t, uv, _points, distance = _projection(face, own, other, PROJECTION_SAMPLES)
                if distance > tol:
                    raise _Refused(OFF, distance)
                pieces.append([t, uv.copy(), _oriented(other.curve, own.curve), e.reversed])
            slots.extend(pieces[::-1] if e.reversed else pieces)
        _pin_corners(slots)
        new_edges = []
        for slot in slots:
            if isinstance(slot, TrimEdge):
                new_edges.append(slot)
                continue
            edge, gap = _new_edge(face, slot, tol)
            deviation = max(deviation, gap)
            new_edges.append(edge)
        loops.append(TrimLoop(new_edges))
    new = replace(face, loops=tuple(loops))
    for old_loop, new_loop in zip(face.loops, new.loops):
        if np.sign(signed_area(_outline(old_loop))) != np.sign(signed_area(_outline(new_loop))):
            raise _Refused(TURNED, 0.0)
    return new, deviation


def _new_edge(face: TrimmedFace, slot, tol: float) -> tuple[TrimEdge, float]:
    """The edge of a replacing curve: pcurve through its (pinned) projections; refused
    when its ends (pinned to a neighbour) or its samples are farther than ``tol``
    from the curve."""
    t, uv, curve, reversed_ = slot
    ends = face.surface.evaluate(uv[[0, -1], 0], uv[[0, -1], 1])
    off = float(np.linalg.norm(ends - curve.evaluate(np.array([t[0], t[-1]])), axis=1).max())
    if off > tol:
        raise _Refused(CORNER, off)
    pcurve = interpolate_curve(uv, parameters=t)
    check = np.linspace(t[0], t[-1], _CHECK_SAMPLES)
    on = pcurve.evaluate(check)
    gap = float(np.linalg.norm(face.surface.evaluate(on[:, 0], on[:, 1])
                               - curve.evaluate(check), axis=1).max())
    if gap > tol:
        raise _Refused(OFF, gap)
    return TrimEdge(curve, pcurve, t[0], t[-1], reversed_, max(DEFAULT_TOLERANCE, 1.001 * gap),
                    vertex_tolerances=(1.001 * gap, 1.001 * gap)), gap


def _ends_uv(slot) -> tuple[NDArray, NDArray]:
    """A slot's uv at its start and its end in loop direction."""
    if isinstance(slot, TrimEdge):
        uv = slot.pcurve.evaluate(np.array([slot.t0, slot.t1]))
        reversed_ = slot.reversed
    else:
        uv, reversed_ = slot[1][[0, -1]], slot[3]
    return (uv[1], uv[0]) if reversed_ else (uv[0], uv[1])


def _pin_corners(slots: list) -> None:
    """Make the projected uv of replacing curves meet their neighbours in the loop: a
    kept edge's pcurve end wins, two replacing curves meet at their mean."""
    for k, slot in enumerate(slots):
        following = slots[(k + 1) % len(slots)]
        if isinstance(slot, TrimEdge) and isinstance(following, TrimEdge):
            continue
        end, start = _ends_uv(slot)[1], _ends_uv(following)[0]
        if isinstance(slot, TrimEdge):
            corner = end
        elif isinstance(following, TrimEdge):
            corner = start
        else:
            corner = 0.5 * (end + start)
        if not isinstance(slot, TrimEdge):
            slot[1][0 if slot[3] else -1] = corner
        if not isinstance(following, TrimEdge):
            following[1][-1 if following[3] else 0] = corner


def _outline(loop: TrimLoop) -> NDArray:
    pts = []
    for e in loop.edges:
        uv = e.pcurve.evaluate(np.linspace(e.t0, e.t1, 17))
        pts.append((uv[::-1] if e.reversed else uv)[:-1])
    return np.concatenate(pts)
