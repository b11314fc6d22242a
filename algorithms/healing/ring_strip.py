"""Rings: two closed loops of free edges that run beside each other all round, a gap
wider than ``gap_tol``, bridged by four-sided strips.

A tube whose wall has two skins (an outer and an inner face) and whose end face is
missing ends in two closed loops of free edges, one on each skin, the wall's
thickness apart (the nozzles of occt_spaceship_alias.stp: rims 0.9 mm apart, 60 to
120 mm long). Neither loop is a hole: capping one would close the tube, and their
surroundings turn away from them as a pipe's end does. Together they bound the
missing ring: a sliver all round, a gap between faces wider than ``gap_tol``, which
sewing cannot close and moving the faces should not (each would travel the wall's
thickness).

A ring is bridged by four-sided strips (the gap strips of issue 21, 001 §3 over each):
each strip is bounded by a piece of one loop, a straight connector across the gap, the
matching piece of the other loop and the next connector. The split points are every
vertex of either loop (a vertex of one loop is matched to the closest point of the
other; a vertex of each loop within :data:`MERGE` of each other, along the loop, are
matched to each other), so every piece lies within one edge, and more points evenly in
between where a piece would span more than a :data:`PIECES`-th of the loop. The strips'
insides follow the ruled surface between the two pieces (:class:`RuledStrip`, their
approximants' ``fill_source``).

Functions
---------
ring_pairs
    Which loops make rings, each loop in at most one.
ring_strips
    The strips of one ring: four boundary curves and the ruled surface of each.

References
----------
.. [001] B. Hamann, B. A. Jean, "Interactive surface correction based on a local
   approximation scheme", *Computer Aided Geometric Design* 13(4), 1996, §3.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from ...errors import InvalidGeometryError
from ..curve import NurbsCurve
from ..fitting import interpolate_surface
from ..surface import NurbsSurface
from .clipping import SurfaceSource
from .decompose import reverse_curve
from .hole_cap import orient_loop

__all__ = ["MAX_WIDTH", "PIECES", "NotARingError", "RingPair", "RuledStrip", "ring_pairs",
           "ring_strips"]

#: two loops are a ring when they lie at most this times the shorter one's length apart
#: (the sliver test of the loops, :data:`surfprep.plugin.heal.loops.GAP_WIDTH`)
MAX_WIDTH = 0.02
#: no strip spans more than this fraction of its ring: a loop of one edge closed on
#: itself is split in two; loops of two or more edges at their vertices only (sewing
#: joins a strip's side to part of an edge, a T-junction, on valid faces, but not to
#: the mouths of the spaceship's nozzles, faces whose wires are open across gaps)
PIECES = 2
#: a vertex of each loop this many times the ring's width apart along it are matched
MERGE = 4.0
#: samples per edge of a loop (the closest points and arc lengths are read off them)
SAMPLES = 256
#: points per side of a strip's ruled surface
RULED_SAMPLES = 65


class NotARingError(InvalidGeometryError):
    """Two loops cannot be bridged by strips: ``str()`` says why."""


@dataclass(frozen=True)
class RingPair:
    """Two loops (indices into the sequence given to :func:`ring_pairs`) that make a
    ring, the widest and the narrowest distance between them (model units)."""

    first: int
    second: int
    width: float
    narrowest: float


@dataclass(frozen=True, eq=False)
class RuledStrip:
    """The ruled surface between a strip's two loop pieces: where an approximant over
    the strip finds no face, its points lie on this (the role of a hole's cap)."""

    surface: NurbsSurface

    def source(self, name: str = "") -> SurfaceSource:
        """The surface as the approximant's ``fill_source``."""
        return SurfaceSource(surface=self.surface, name=name)


@dataclass(frozen=True)
class _Place:
    """A point of a loop: its edge, its parameter there and its arc length from the
    loop's start."""

    edge: int
    param: float
    arc: float


@dataclass(frozen=True)
class _Dense:
    """A closed loop sampled: points, the edge and the parameter of each, and the arc
    length from the loop's start (``length`` the loop's)."""

    points: NDArray
    edge: NDArray
    param: NDArray
    arc: NDArray
    length: float
    curves: tuple

    @classmethod
    def of(cls, curves: Sequence[NurbsCurve]) -> _Dense:
        params = [np.linspace(*c.domain, SAMPLES + 1)[:-1] for c in curves]
        points = np.concatenate([c.evaluate(t) for c, t in zip(curves, params)])
        edge = np.repeat(np.arange(len(curves)), SAMPLES)
        step = np.linalg.norm(np.diff(np.vstack([points, points[:1]]), axis=0), axis=1)
        arc = np.concatenate([[0.0], np.cumsum(step[:-1])])
        return cls(points, edge, np.concatenate(params), arc, float(step.sum()), tuple(curves))

    def vertices(self) -> list[_Place]:
        """The loop's vertices (each edge's start)."""
        return [self.place(k * SAMPLES) for k in range(len(self.curves))]

    def place(self, n: int, f: float = 0.0) -> _Place:
        """The point a fraction ``f`` of the way from sample ``n`` to the next (within
        sample ``n``'s edge: the parameter runs on to the edge's end)."""
        k = int(self.edge[n])
        nxt = n + 1
        end = self.param[nxt] if nxt < len(self.param) and self.edge[nxt] == k \
            else self.curves[k].domain[1]
        length = self.arc[nxt] if nxt < len(self.arc) else self.length
        return _Place(k, float(self.param[n] + f * (end - self.param[n])),
                      float(self.arc[n] + f * (length - self.arc[n])))

    def at_arc(self, s: float) -> _Place:
        """The point at arc length ``s`` from the loop's start."""
        n = int(np.searchsorted(self.arc, s, side="right")) - 1
        length = self.arc[n + 1] if n + 1 < len(self.arc) else self.length
        return self.place(n, float(np.clip((s - self.arc[n]) / (length - self.arc[n]), 0, 1)))

    def foot(self, tree: cKDTree, point: NDArray) -> _Place:
        """The closest point to ``point`` on the loop's polyline (the nearest sample's
        two segments), as a place on the loop."""
        n = int(tree.query(point)[1])
        m = len(self.points)
        best = None
        for a in ((n - 1) % m, n):
            p, q = self.points[a], self.points[(a + 1) % m]
            d = q - p
            f = float(np.clip(np.dot(point - p, d) / max(np.dot(d, d), 1e-300), 0.0, 1.0))
            dist = float(np.linalg.norm(p + f * d - point))
            if best is None or dist < best[0]:
                best = (dist, a, f)
        return self.place(best[1], best[2])

    def distances(self, tree: cKDTree, points: NDArray) -> NDArray:
        """``(n,)`` float: each point's distance from the loop's polyline."""
        n = tree.query(points)[1]
        m = len(self.points)
        out = np.full(len(points), np.inf)
        for a in ((n - 1) % m, n):
            p, q = self.points[a], self.points[(a + 1) % m]
            d = q - p
            f = np.clip(np.einsum("ij,ij->i", points - p, d)
                        / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
            out = np.minimum(out, np.linalg.norm(p + f[:, None] * d - points, axis=1))
        return out


def ring_pairs(loops: Sequence[Sequence[NurbsCurve]], *, gap_tol: float,
               owners: Sequence[set] | None = None) -> list[RingPair]:
    """The loops that make rings.

    Two closed loops make a ring when every point of each lies within :data:`MAX_WIDTH`
    times the shorter loop's length of the other, and none within ``gap_tol`` (there
    sewing joins them), and no face has edges on both (such a face spans the space
    between them: the two rims of a band of faces 2.54 mm wide on
    occt_k1geo_microstation.stp); of several candidates the nearest pairs are taken
    first, each loop in at most one ring.

    Parameters
    ----------
    loops : sequence of sequence of NurbsCurve (3D)
        Closed loops of free edges, their curves in loop order (either way round).
    gap_tol : float
    owners : sequence of set, optional
        Per loop, the faces whose edges make it (default: no face in two loops).

    Returns
    -------
    list of RingPair
        Smallest ``width`` first.
    """
    dense = [_Dense.of(orient_loop(loop)) for loop in loops]
    trees = [cKDTree(d.points) for d in dense]
    boxes = np.array([[d.points.min(axis=0), d.points.max(axis=0)] for d in dense])
    found = []
    for i in range(len(dense)):
        for j in range(i + 1, len(dense)):
            if owners is not None and set(owners[i]) & set(owners[j]):
                continue
            limit = MAX_WIDTH * min(dense[i].length, dense[j].length)
            if np.any(boxes[i, 0] > boxes[j, 1] + limit) or np.any(boxes[j, 0] > boxes[i, 1] + limit):
                continue
            there = dense[j].distances(trees[j], dense[i].points)
            back = dense[i].distances(trees[i], dense[j].points)
            width = max(float(there.max()), float(back.max()))
            narrowest = min(float(there.min()), float(back.min()))
            if width <= limit and narrowest > gap_tol:
                found.append(RingPair(i, j, width, narrowest))
    out, used = [], set()
    for pair in sorted(found, key=lambda p: p.width):
        if pair.first not in used and pair.second not in used:
            out.append(pair)
            used |= {pair.first, pair.second}
    return out


def ring_strips(first: Sequence[NurbsCurve], second: Sequence[NurbsCurve], *,
                min_side: float = 0.0) -> list[tuple[list[NurbsCurve], RuledStrip]]:
    """The four-sided strips bridging a ring (module docstring).

    Parameters
    ----------
    first, second : sequence of NurbsCurve (3D)
        The two loops' curves in loop order (either way round).
    min_side : float
        Every side of every strip must be longer (sewing at ``gap_tol`` collapses
        shorter ones).

    Returns
    -------
    list of (boundary, RuledStrip)
        Per strip its four curves in loop order (the piece of ``first``, a connector,
        the piece of ``second``, the other connector: sides 0 and 2 lie on the loops)
        and the ruled surface between its pieces.

    Raises
    ------
    NotARingError
        The loops' closest points do not run round them in step (they are no ring), or
        a side would be no longer than ``min_side``.
    """
    a = _Dense.of(orient_loop(first))
    b = _Dense.of(orient_loop(second))
    if _runs_against(a, b):
        b = _Dense.of([reverse_curve(c) for c in reversed(b.curves)])
    width = float(a.distances(cKDTree(a.points), b.points).max())
    pairs = _split_pairs(a, b, merge=MERGE * width)
    strips = []
    for (a0, b0), (a1, b1) in zip(pairs, pairs[1:] + pairs[:1]):
        low, high = _piece(a, a0, a1), _piece(b, b0, b1)
        p, q = low.evaluate(np.array(low.domain)), high.evaluate(np.array(high.domain))
        sides = [low, _line(p[1], q[1]), high, _line(q[0], p[0])]
        short = min(float(np.linalg.norm(np.diff(_samples(s), axis=0), axis=1).sum())
                    for s in sides)
        if short <= min_side:
            raise NotARingError(f"a strip side would be {short:.3g} long, no longer than "
                                f"{min_side:.3g} (a vertex of one loop next to the other's)")
        strips.append((sides, RuledStrip(_ruled(low, high))))
    return strips


def _runs_against(a: _Dense, b: _Dense) -> bool:
    """Whether ``b``'s closest points to ``a``'s samples run backwards along ``b``."""
    nearest = cKDTree(b.points).query(a.points)[1]
    step = np.diff(b.arc[nearest])
    step = (step + 0.5 * b.length) % b.length - 0.5 * b.length      # wrapped
    return float(step.sum()) < 0


def _split_pairs(a: _Dense, b: _Dense, *, merge: float) -> list[tuple[_Place, _Place]]:
    """The split points, matched ``(on a, on b)``, in order along both."""
    to_a, to_b = cKDTree(a.points), cKDTree(b.points)
    events = [(v.arc, "a", v) for v in a.vertices()]
    events += [(a.foot(to_a, _point(b, v)).arc, "b", v) for v in b.vertices()]
    events.sort(key=lambda e: e[0])
    clusters: list[dict] = []
    for s, kind, v in events:
        last = clusters[-1] if clusters else None
        if last is not None and kind not in last and s - last["s"] <= merge:
            last[kind] = v
        else:
            clusters.append({"s": s, kind: v})
    if len(clusters) > 1:                       # across the loop's start
        first, last = clusters[0], clusters[-1]
        if (first["s"] + a.length - last["s"] <= merge
                and not ({"a", "b"} & set(first) & set(last))):
            first.update({k: last[k] for k in ("a", "b") if k in last})
            clusters.pop()
    pairs = []
    for c in clusters:
        pa = c["a"] if "a" in c else a.foot(to_a, _point(b, c["b"]))
        pb = c["b"] if "b" in c else b.foot(to_b, _point(a, pa))
        pairs.append((pa, pb))
    pairs.sort(key=lambda p: p[0].arc)
    # more points where a piece would span more than a PIECES-th of the loop
    out = []
    longest = a.length / PIECES
    for (pa, pb), (qa, _) in zip(pairs, pairs[1:] + pairs[:1]):
        out.append((pa, pb))
        span = (qa.arc - pa.arc) % a.length or a.length
        extra = int(np.ceil(span / longest - 1e-3)) - 1     # (a half loop: one split)
        for k in range(1, extra + 1):
            na = a.at_arc((pa.arc + k * span / (extra + 1)) % a.length)
            out.append((na, b.foot(to_b, _point(a, na))))
    _check_in_step(b, [pb.arc for _, pb in out])
    return out


def _point(d: _Dense, place: _Place) -> NDArray:
    return d.curves[place.edge].evaluate(np.array([place.param]))[0]


def _check_in_step(b: _Dense, along_b: list[float]) -> None:
    """The split points' matches run once round ``b``, forwards."""
    s = np.array(along_b)
    step = np.diff(np.append(s, s[0])) % b.length
    if np.any(step <= 0) or not np.isclose(step.sum(), b.length, rtol=1e-9):
        raise NotARingError("the loops' closest points do not run round them in step")


def _piece(d: _Dense, start: _Place, end: _Place) -> NurbsCurve:
    """The loop's curve from ``start`` to ``end`` (within one edge, or to the next
    edge's start)."""
    curve = d.curves[start.edge]
    nxt = d.curves[end.edge]
    if end.edge == (start.edge + 1) % len(d.curves) and end.param == nxt.domain[0]:
        t1 = curve.domain[1]                                  # to the edge's end
    elif end.edge == start.edge and end.param > start.param:
        t1 = end.param
    else:
        raise NotARingError("a strip's piece would span a vertex of its loop")
    return curve.restrict(start.param, t1)


def _line(p: NDArray, q: NDArray) -> NurbsCurve:
    return NurbsCurve(np.stack([p, q]), np.array([0.0, 0.0, 1.0, 1.0]), 1)


def _samples(curve: NurbsCurve, n: int = 65) -> NDArray:
    return curve.evaluate(np.linspace(*curve.domain, n))


def _ruled(low: NurbsCurve, high: NurbsCurve) -> NurbsSurface:
    """Bicubic interpolant of the ruled surface between two pieces run the same way,
    matched by arc-length fraction (the lines across lie in the surface exactly: cubics
    through collinear points are lines)."""
    def even(curve):
        t = np.linspace(*curve.domain, 8 * RULED_SAMPLES)
        dense = curve.evaluate(t)
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))])
        return curve.evaluate(np.interp(np.linspace(0.0, arc[-1], RULED_SAMPLES), arc, t))
    p, q = even(low), even(high)
    rows = np.linspace(0.0, 1.0, 4)
    grid = p[:, None, :] * (1 - rows)[None, :, None] + q[:, None, :] * rows[None, :, None]
    return interpolate_surface(grid)
