"""The arrangement of curves in a face's parameter domain, traced into regions (the
planar graph :func:`.face_split.split_face` builds).

Vertices are points of ``(u, v)`` (merged within ``eps``; two can be joined, as cuts
meeting at one boundary point are); half-edges are cut segments (both ways) and runs
of the face's loops between cut ends (one way: the face's side). At each vertex the
half-edges leave in the order of their angles; a face is traced by taking, at each
vertex, the first half-edge clockwise from the way back, so the region stays on the
left. Half-edges whose tangents coincide at a vertex (within :data:`TIE_ANGLE`: a
curve leaving a pole along the pole's edge in the parameters) are ordered by their
chords a sixteenth of the way along.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..errors import InvalidGeometryError
from .curve import NurbsCurve
from .cuts import Cut, cut_point_at
from .trimmed import DEFAULT_TOLERANCE, TrimEdge, TrimmedFace, edge_deviation

__all__ = ["TIE_ANGLE", "Arrangement"]

#: directions at a vertex closer than this (radians) are told apart by their chords
TIE_ANGLE = 1e-3


def _near_tie(angles: list[float]) -> bool:
    """Two of ``angles`` (radians) within :data:`TIE_ANGLE` of each other, round the circle."""
    a = np.sort(np.mod(angles, 2 * np.pi))
    if a.size < 2:
        return False
    gaps = np.diff(np.append(a, a[0] + 2 * np.pi))
    return bool(np.min(gaps) < TIE_ANGLE)


def _direction(pcurve: NurbsCurve, t: float, sign: float) -> NDArray:
    """Unit direction of a pcurve at ``t`` run forwards (``sign`` 1) or backwards (-1); a
    short chord where the derivative vanishes."""
    d = sign * pcurve.derivatives(np.array([t]), 1)[0, 1]
    n = float(np.linalg.norm(d))
    if n > 0:
        return d / n
    lo, hi = pcurve.domain
    step = 1e-6 * (hi - lo)
    other = float(np.clip(t + sign * step, lo, hi))
    d = pcurve.evaluate(np.array([other]))[0] - pcurve.evaluate(np.array([t]))[0]
    return d / max(float(np.linalg.norm(d)), 1e-300)


class Arrangement:
    """The arrangement of a face's cuts and loop runs as half-edges round vertices,
    traced face by face (the module doc)."""

    def __init__(self, face: TrimmedFace, eps: float) -> None:
        self.face = face
        self.eps = eps
        self.points: list[NDArray] = []          # vertex positions in (u, v)
        self.space: list[list[NDArray]] = []     # the 3D points that meet there
        self.boundary: list[bool] = []
        self.half: list[dict] = []               # origin, target, edges, angle out, direction in
        self.same: dict[int, int] = {}           # vertex -> the vertex it was joined to

    def join(self, k: int, into: int) -> None:
        """Vertex ``k`` is vertex ``into`` from now on (half-edges added later use it)."""
        if k != into:
            self.same[k] = into
            self.space[into].extend(self.space[k])
            self.boundary[into] = self.boundary[into] or self.boundary[k]

    def vertex(self, point: NDArray, *space: NDArray, boundary: bool = False) -> int:
        for k, q in enumerate(self.points):
            if np.linalg.norm(q - point) <= self.eps:
                k = self.same.get(k, k)
                self.space[k].extend(space)
                self.boundary[k] = self.boundary[k] or boundary
                return k
        self.points.append(np.asarray(point, dtype=float))
        self.space.append(list(space))
        self.boundary.append(boundary)
        return len(self.points) - 1

    def _add(self, origin: int, target: int, edges: list[TrimEdge], out: NDArray, into: NDArray,
             far_out: NDArray, far_into: NDArray) -> None:
        """A half-edge leaving ``origin`` along ``out`` and arriving at ``target`` along
        ``into``; ``far_out`` / ``far_into``: the chords to / from a point a sixteenth of
        the way along it, which order half-edges whose tangents coincide (a curve leaving
        a pole along the pole's edge in the parameters)."""
        self.half.append({"origin": origin, "target": target, "edges": edges,
                          "angle": float(np.arctan2(out[1], out[0])), "into": into,
                          "far_angle": float(np.arctan2(far_out[1], far_out[0])), "far_into": far_into})

    def cut_segment(self, c: int, cut: Cut, a: float, b: float) -> None:
        pa, pb = cut.pcurve.evaluate(np.array([a, b]))
        va = self.vertex(pa, cut_point_at(cut, self.face, a))
        vb = self.vertex(pb, cut_point_at(cut, self.face, b))
        near_a, near_b = cut.pcurve.evaluate(np.array([a + (b - a) / 16, b - (b - a) / 16]))
        for origin, target, forward in ((va, vb, True), (vb, va, False)):
            start, stop = (a, b) if forward else (b, a)
            sign = 1.0 if forward else -1.0
            edge = TrimEdge(cut.curve3d, cut.pcurve, a, b, not forward, 0.0)
            far_out, far_into = (near_a - pa, pb - near_b) if forward else (near_b - pb, pa - near_a)
            self._add(origin, target, [("cut", c, edge)],
                      _direction(cut.pcurve, start, sign), _direction(cut.pcurve, stop, sign), far_out, far_into)
        self.half[-2]["twin"], self.half[-1]["twin"] = len(self.half) - 1, len(self.half) - 2

    def run(self, pieces: list[TrimEdge], start: int, stop: int, gap: float) -> None:
        """A run of loop pieces from vertex ``start`` to ``stop`` (one way: the face's
        side), its corners tolerating ``gap`` to the cuts that end there."""
        first, last = pieces[0], pieces[-1]
        t_first = first.t1 if first.reversed else first.t0
        t_last = last.t0 if last.reversed else last.t1
        ends = [p.pcurve.evaluate(np.array([t, t + (u - t) / 16]))
                for p, t, u in ((first, t_first, first.t0 if first.reversed else first.t1),
                                (last, t_last, last.t1 if last.reversed else last.t0))]
        self._add(start, stop, [("run", gap, p) for p in pieces],
                  _direction(first.pcurve, t_first, -1.0 if first.reversed else 1.0),
                  _direction(last.pcurve, t_last, -1.0 if last.reversed else 1.0),
                  ends[0][1] - ends[0][0], ends[1][0] - ends[1][1])

    def check_ends(self) -> None:
        """Every vertex inside the face must join at least two cut segments."""
        degree = np.zeros(len(self.points), int)
        for h in self.half:
            degree[h["origin"]] += 1
        for k, d in enumerate(degree):
            if not self.boundary[k] and d < 2:
                raise InvalidGeometryError(f"a cut ends at {self.points[k].tolist()}, neither on the "
                                           "face's boundary nor on another cut")

    def cycles(self) -> list[list[TrimEdge]]:
        outgoing: dict[int, list[int]] = {}
        for k, h in enumerate(self.half):
            outgoing.setdefault(h["origin"], []).append(k)
        used: set[int] = set()
        cycles = []
        for k0 in range(len(self.half)):
            if k0 in used:
                continue
            cycle: list[TrimEdge] = []
            k = k0
            while k not in used:
                used.add(k)
                h = self.half[k]
                cycle.extend(self._edges(h))
                candidates = outgoing.get(h["target"], [])
                back = float(np.arctan2(-h["into"][1], -h["into"][0]))
                angles = [self.half[j]["angle"] for j in candidates]
                # (the way back along a cut is its twin's way out: no tie)
                if _near_tie([back, *(a for j, a in zip(candidates, angles) if j != h.get("twin"))]):
                    back = float(np.arctan2(-h["far_into"][1], -h["far_into"][0]))
                    angles = [self.half[j]["far_angle"] for j in candidates]
                # the first outgoing half-edge clockwise from the way back: the face stays on the left
                k = candidates[min(range(len(candidates)),
                                   key=lambda i: ((back - angles[i]) % (2 * np.pi)) or 2 * np.pi)]
            cycles.append(cycle)
        return cycles

    def _edges(self, h: dict) -> list[TrimEdge]:
        out = []
        gap_origin = self._gap(h["origin"])
        gap_target = self._gap(h["target"])
        for kind, info, edge in h["edges"]:
            if kind == "run":
                out.append(_loosened(edge, info))
                continue
            t0_end, t1_end = (gap_target, gap_origin) if edge.reversed else (gap_origin, gap_target)
            probe = TrimEdge(edge.curve3d, edge.pcurve, edge.t0, edge.t1)
            tolerance = max(DEFAULT_TOLERANCE, 1.01 * edge_deviation(probe, self.face.surface))
            out.append(TrimEdge(edge.curve3d, edge.pcurve, edge.t0, edge.t1, edge.reversed, tolerance,
                                vertex_tolerances=(max(DEFAULT_TOLERANCE, 1.01 * t0_end),
                                                   max(DEFAULT_TOLERANCE, 1.01 * t1_end))))
        return out

    def _gap(self, k: int) -> float:
        pts = np.array(self.space[k])
        if len(pts) < 2:
            return 0.0
        return float(np.max(np.linalg.norm(pts - pts.mean(axis=0), axis=1)) * 2.0)


def _loosened(edge: TrimEdge, gap: float) -> TrimEdge:
    """A boundary piece whose corners tolerate the gap to the cut that ends there."""
    if gap <= 0.0:
        return edge
    lo, hi = edge.vertex_tolerances
    return TrimEdge(edge.curve3d, edge.pcurve, edge.t0, edge.t1, edge.reversed, edge.tolerance,
                    edge.seam_pcurve, edge.degenerated,
                    (max(lo, 1.01 * gap), max(hi, 1.01 * gap)))
