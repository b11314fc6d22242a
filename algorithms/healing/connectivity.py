"""Connectivity table of a set of four-sided B-spline patches (001 §8, 003 "connecting").

Two patches are neighbours when a pair of their boundary curves lies within
``gap_tol`` of each other: both ends of one side close to the two ends of the
other (either way round: ``reversed`` records which) and every interior sample
of each side within ``gap_tol`` of the other side. Corner points of all patches
closer than ``gap_tol`` form one :class:`CornerCluster` (a corner may be shared by
any number of patches).

The topology rules of 001 §8 are checked:

* each boundary curve is shared by at most two patches (no bifurcation);
* full-face interface: a side touching another side over part of its length,
  or a corner touching the interior of another patch's side, is refused.

A violation raises :class:`NetworkTopologyError` naming the patches and sides,
or (``strict=False``) is listed in :attr:`Connectivity.violations` and the
offending pair is left unconnected.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from ...errors import InvalidGeometryError
from ..projection import project_to_curve
from ..surface import NurbsSurface
from ..tensor import Direction

__all__ = [
    "SIDE_SAMPLES",
    "Connectivity",
    "CornerCluster",
    "NetworkTopologyError",
    "SharedEdge",
    "Side",
    "corner_index",
    "default_gap_tol",
    "find_connectivity",
    "side_indices",
    "side_points",
]

#: samples per side for the distance estimate (interior ones decide contact)
SIDE_SAMPLES = 33
#: samples of the side a point is measured against (a polyline; chord error ~ L/(8 n^2) kappa L)
_POLYLINE_SAMPLES = 257
#: default ``gap_tol``: this fraction of the shortest side of the patches, ...
_GAP_FACTOR_SIDE = 0.05
#: ... and never more than this fraction of the box diagonal of all patches
_GAP_FACTOR_MODEL = 1e-2


class NetworkTopologyError(InvalidGeometryError):
    """Patches that violate the topology rules of 001 §8 (bifurcation, not full-face)."""


class Side(enum.Enum):
    """A boundary curve of a patch. ``U0``: ``u = u_min`` (control row ``P[0, :]``,
    runs in v); ``U1``: ``u = u_max``; ``V0``: ``v = v_min`` (``P[:, 0]``, runs in u);
    ``V1``: ``v = v_max``."""

    U0 = "u0"
    U1 = "u1"
    V0 = "v0"
    V1 = "v1"

    @property
    def along(self) -> Direction:
        """Parameter direction the side runs in."""
        return Direction.V if self in (Side.U0, Side.U1) else Direction.U

    @property
    def fixed(self) -> Direction:
        """Parameter held constant on the side."""
        return Direction.U if self in (Side.U0, Side.U1) else Direction.V

    @property
    def at_max(self) -> bool:
        return self in (Side.U1, Side.V1)

    def parameter(self, surface: NurbsSurface) -> float:
        """Value of :attr:`fixed` on this side."""
        u0, u1, v0, v1 = surface.domain
        return {Side.U0: u0, Side.U1: u1, Side.V0: v0, Side.V1: v1}[self]

    def uv(self, surface: NurbsSurface, t: NDArray) -> NDArray:
        """Parameters ``(n, 2)`` of the side at running parameters ``t (n,)``."""
        fixed = np.full_like(np.asarray(t, dtype=float), self.parameter(surface))
        cols = (fixed, t) if self.fixed is Direction.U else (t, fixed)
        return np.stack(cols, axis=-1)

    def running_domain(self, surface: NurbsSurface) -> tuple[float, float]:
        u0, u1, v0, v1 = surface.domain
        return (v0, v1) if self.along is Direction.V else (u0, u1)


SIDES = tuple(Side)


def side_indices(shape: tuple[int, int], side: Side, depth: int = 0) -> tuple[NDArray, NDArray]:
    """Control-net indices ``(i, j)`` of row ``depth`` from ``side`` (0: the boundary
    row, 1: the row next to it), each ``(n_along,)`` int, in running order."""
    nu, nv = shape
    if side.along is Direction.V:
        j = np.arange(nv)
        return np.full(nv, nu - 1 - depth if side.at_max else depth), j
    i = np.arange(nu)
    return i, np.full(nu, nv - 1 - depth if side.at_max else depth)


def corner_index(shape: tuple[int, int], side: Side, end: int) -> tuple[int, int]:
    """Control index of the corner at the start (``end=0``) or end (``1``) of ``side``."""
    i, j = side_indices(shape, side)
    return int(i[-1 if end else 0]), int(j[-1 if end else 0])


def side_points(surface: NurbsSurface, side: Side, n: int) -> NDArray:
    """``n`` points ``(n, 3)`` of a side, uniform in its running parameter."""
    a, b = side.running_domain(surface)
    uv = side.uv(surface, np.linspace(a, b, n))
    return surface.evaluate(uv[:, 0], uv[:, 1])


@dataclass(frozen=True)
class SharedEdge:
    """Side ``side_a`` of patch ``a`` is the same boundary curve as ``side_b`` of ``b``.

    ``reversed``: the sides run in opposite directions (start of one at the end
    of the other). ``gap_estimate``: largest sampled distance between them
    (the measured join is :mod:`.measure_joins`).
    """

    a: int
    side_a: Side
    b: int
    side_b: Side
    reversed: bool
    gap_estimate: float


@dataclass(frozen=True)
class CornerCluster:
    """Patch corners within ``gap_tol`` of each other: ``members`` as ``(patch, side,
    end)`` triples naming each corner once (``end`` 0/1 of ``side``)."""

    members: tuple[tuple[int, Side, int], ...]
    center: NDArray

    @property
    def patches(self) -> tuple[int, ...]:
        return tuple(sorted({m[0] for m in self.members}))


@dataclass(frozen=True)
class Connectivity:
    """Neighbours of every patch (001 §8's connectivity table).

    Attributes
    ----------
    edges : tuple of SharedEdge
    corners : tuple of CornerCluster
        Clusters of two or more corners.
    gap_tol : float
    violations : tuple of str
        Topology violations left unconnected (``strict=False`` only).
    """

    edges: tuple[SharedEdge, ...]
    corners: tuple[CornerCluster, ...]
    gap_tol: float
    violations: tuple[str, ...] = ()

    def neighbours(self, patch: int) -> dict[Side, tuple[int, Side]]:
        """``{side: (other patch, its side)}`` for the shared sides of ``patch``."""
        out = {}
        for e in self.edges:
            if e.a == patch:
                out[e.side_a] = (e.b, e.side_b)
            if e.b == patch:
                out[e.side_b] = (e.a, e.side_a)
        return out

    def free_sides(self, n_patches: int) -> list[tuple[int, Side]]:
        """Sides shared with no other patch."""
        used = {(e.a, e.side_a) for e in self.edges} | {(e.b, e.side_b) for e in self.edges}
        return [(p, s) for p in range(n_patches) for s in SIDES if (p, s) not in used]


def default_gap_tol(patches: list[NurbsSurface]) -> float:
    """``min(0.05 x shortest side, 0.01 x diagonal of all patches)`` in model units."""
    lengths, boxes = [], []
    for s in patches:
        for side in SIDES:
            pts = side_points(s, side, 9)
            lengths.append(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
        boxes.append(s.bounding_box())
    box = np.concatenate(boxes)
    diag = float(np.linalg.norm(box.max(axis=0) - box.min(axis=0)))
    positive = [x for x in lengths if x > 1e-9 * diag]        # collapsed sides left out
    shortest = min(positive) if positive else diag
    return min(_GAP_FACTOR_SIDE * shortest, _GAP_FACTOR_MODEL * diag)


def _point_polyline_distance(points: NDArray, line: NDArray) -> NDArray:
    """Distance ``(m,)`` from ``points (m, 3)`` to the polyline ``line (k, 3)``."""
    a, b = line[:-1], line[1:]
    ab = b - a
    denom = np.maximum(np.einsum("kc,kc->k", ab, ab), np.finfo(float).tiny)
    t = np.clip(np.einsum("mkc,kc->mk", points[:, None, :] - a[None], ab) / denom, 0.0, 1.0)
    foot = a[None] + t[..., None] * ab[None]
    return np.min(np.linalg.norm(points[:, None, :] - foot, axis=2), axis=1)


@dataclass(frozen=True)
class _SideSamples:
    patches: list[NurbsSurface]
    coarse: NDArray        # (P, 4, SIDE_SAMPLES, 3)
    fine: NDArray          # (P, 4, _POLYLINE_SAMPLES, 3)
    boxes: NDArray         # (P, 4, 2, 3)
    sag: NDArray           # (P, 4) chord error of the fine polylines (estimate)


def _sample_sides(patches: list[NurbsSurface]) -> _SideSamples:
    coarse = np.stack([[side_points(s, side, SIDE_SAMPLES) for side in SIDES] for s in patches])
    fine = np.stack([[side_points(s, side, 2 * _POLYLINE_SAMPLES - 1) for side in SIDES]
                     for s in patches])
    mid, fine = fine[:, :, 1::2], fine[:, :, ::2]
    sag = np.linalg.norm(mid - 0.5 * (fine[:, :, :-1] + fine[:, :, 1:]), axis=3).max(axis=2)
    boxes = np.stack([fine.min(axis=2), fine.max(axis=2)], axis=2)
    return _SideSamples(list(patches), coarse, fine, boxes, sag)


def _exact_distance(samples: _SideSamples, points: NDArray, patch: int, side: int) -> NDArray:
    surface = samples.patches[patch]
    s = SIDES[side]
    curve = surface.isocurve(s.parameter(surface), s.fixed)
    return project_to_curve(curve, points).distance


def _contact(samples: _SideSamples, pa: int, sa: int, pb: int, sb: int, tol: float
             ) -> tuple[NDArray, NDArray]:
    """Distances of each side's samples to the other side: ``(n,)``, ``(n,)``.

    Polyline distances first; where they cannot decide (within the polylines'
    chord error of ``tol``) the exact closest points on the boundary curve.
    """
    da = _point_polyline_distance(samples.coarse[pa, sa], samples.fine[pb, sb])
    db = _point_polyline_distance(samples.coarse[pb, sb], samples.fine[pa, sa])
    slack = 2.0 * max(samples.sag[pa, sa], samples.sag[pb, sb])
    if np.any(np.abs(da - tol) <= slack) or np.any(np.abs(db - tol) <= slack):
        da = _exact_distance(samples, samples.coarse[pa, sa], pb, sb)
        db = _exact_distance(samples, samples.coarse[pb, sb], pa, sa)
    return da, db


def _ends_match(samples: _SideSamples, pa: int, sa: int, pb: int, sb: int, tol: float
                ) -> bool | None:
    """True: ends match reversed, False: same direction, None: they do not match."""
    a0, a1 = samples.coarse[pa, sa, 0], samples.coarse[pa, sa, -1]
    b0, b1 = samples.coarse[pb, sb, 0], samples.coarse[pb, sb, -1]
    if np.linalg.norm(a0 - b0) <= tol and np.linalg.norm(a1 - b1) <= tol:
        return False
    if np.linalg.norm(a0 - b1) <= tol and np.linalg.norm(a1 - b0) <= tol:
        return True
    return None


def _candidate_pairs(samples: _SideSamples, tol: float) -> list[tuple[int, int, int, int]]:
    """Side pairs whose boxes overlap and where at least two interior samples of one
    side lie within ``tol`` (plus the polylines' chord error) of the other side's box:
    sides meeting only at a corner are culled before any distance is computed. A side
    collapsed to a point (a three-sided patch) shares nothing."""
    boxes = samples.boxes.reshape(-1, 2, 3)
    lo, hi = boxes[:, 0] - tol, boxes[:, 1] + tol
    overlap = np.all((lo[:, None] <= hi[None]) & (lo[None] <= hi[:, None]), axis=2)
    i, j = np.nonzero(np.triu(overlap, 1))
    coarse = samples.coarse.reshape(-1, SIDE_SAMPLES, 3)[:, 1:-1]
    slack = tol + 2.0 * samples.sag.reshape(-1)

    def near(p: NDArray, q: NDArray) -> NDArray:
        """Interior samples of sides ``p`` within reach of the boxes of sides ``q``."""
        out = np.zeros(p.size, np.int64)
        for start in range(0, p.size, 4096):
            a, b = p[start:start + 4096], q[start:start + 4096]
            gap = np.maximum(boxes[b, 0][:, None] - coarse[a], coarse[a] - boxes[b, 1][:, None])
            dist = np.linalg.norm(np.maximum(gap, 0.0), axis=2)
            reach = np.maximum(slack[a], slack[b])[:, None]
            out[start:start + 4096] = np.count_nonzero(dist <= reach, axis=1)
        return out

    length = np.linalg.norm(np.diff(samples.fine, axis=2), axis=3).sum(axis=2).reshape(-1)
    i, j = i[(length[i] > tol) & (length[j] > tol)], j[(length[i] > tol) & (length[j] > tol)]
    keep = (near(i, j) >= 2) | (near(j, i) >= 2)
    return [(a // 4, a % 4, b // 4, b % 4) for a, b in zip(i[keep].tolist(), j[keep].tolist())]


def _touch_away_from_shared_ends(samples: _SideSamples, pa: int, sa: int, pb: int, sb: int,
                                 da: NDArray, db: NDArray, tol: float) -> bool:
    """Whether two interior samples of one side farther than ``2 tol`` from every end
    the two sides share (within ``tol``) lie within ``tol`` of the other side.

    Two sides leaving a common vertex at an angle ``a`` lie within ``tol`` of each
    other up to ``tol / sin(a)`` from it: with ``gap_tol`` a tenth of the sides, every
    two sides meeting at a corner of a grid "touched" (48 notes on a clean 2 x 2
    grid; 76 on ``overture_ship_napa_part5.igs``). Past ``2 tol`` only sides meeting
    at less than 30 degrees still do: a sliver corner, said so."""
    a, b = samples.coarse[pa, sa], samples.coarse[pb, sb]
    ends = np.concatenate([a[[0, -1]], b[[0, -1]]])
    cross = np.linalg.norm(a[[0, -1]][:, None] - b[[0, -1]][None], axis=2) <= tol
    shared = ends[np.concatenate([cross.any(axis=1), cross.any(axis=0)])]
    interior = slice(1, SIDE_SAMPLES - 1)

    def count(points: NDArray, d: NDArray) -> int:
        far = np.ones(len(points), dtype=bool)
        for end in shared:
            far &= np.linalg.norm(points - end, axis=1) > 2.0 * tol
        return int(np.count_nonzero((d <= tol)[interior] & far[interior]))

    return count(a, da) >= 2 or count(b, db) >= 2


def _describe(pa: int, sa: int, pb: int, sb: int) -> str:
    return f"patch {pa} side {SIDES[sa].value} and patch {pb} side {SIDES[sb].value}"


def _shared_edges(patches: list[NurbsSurface], samples: _SideSamples, tol: float,
                  strict: bool) -> tuple[list[SharedEdge], list[str]]:
    edges, violations = [], []
    interior = slice(1, SIDE_SAMPLES - 1)
    for pa, sa, pb, sb in _candidate_pairs(samples, tol):
        if pa == pb and sa == sb:
            continue
        da, db = _contact(samples, pa, sa, pb, sb, tol)
        touching = (np.count_nonzero(da[interior] <= tol) >= 2
                    or np.count_nonzero(db[interior] <= tol) >= 2)
        if not touching:
            continue
        orientation = _ends_match(samples, pa, sa, pb, sb, tol)
        if orientation is not None and np.all(da <= tol) and np.all(db <= tol):
            edges.append(SharedEdge(pa, SIDES[sa], pb, SIDES[sb], orientation,
                                    float(max(da.max(), db.max()))))
            continue
        if not _touch_away_from_shared_ends(samples, pa, sa, pb, sb, da, db, tol):
            continue                    # they meet at a corner only
        message = (f"{_describe(pa, sa, pb, sb)} touch over part of their length only "
                   f"(not a full-face interface, 001 §8): split the longer side or "
                   f"choose patch boundaries that meet corner to corner")
        if strict:
            raise NetworkTopologyError(message)
        violations.append(message)
    return _drop_bifurcations(edges, violations, strict)


def _drop_bifurcations(edges: list[SharedEdge], violations: list[str], strict: bool
                       ) -> tuple[list[SharedEdge], list[str]]:
    uses: dict[tuple[int, Side], list[SharedEdge]] = {}
    for e in edges:
        uses.setdefault((e.a, e.side_a), []).append(e)
        uses.setdefault((e.b, e.side_b), []).append(e)
    bad = set()
    for (patch, side), group in uses.items():
        if len(group) < 2:
            continue
        if bad & {id(e) for e in group}:       # the same bifurcation seen from another side
            bad.update(id(e) for e in group)
            continue
        others = ", ".join(f"patch {e.b if e.a == patch else e.a}" for e in group)
        message = (f"side {side.value} of patch {patch} is shared by {len(group) + 1} "
                   f"patches ({others}): a boundary curve may be shared by at most two "
                   "(no bifurcations, 001 §8)")
        if strict:
            raise NetworkTopologyError(message)
        violations.append(message)
        bad.update(id(e) for e in group)
    return [e for e in edges if id(e) not in bad], violations


def _corner_clusters(patches: list[NurbsSurface], samples: _SideSamples,
                     edges: list[SharedEdge], tol: float) -> list[CornerCluster]:
    """Union of corners within ``tol`` and of the ends of every shared edge."""
    # corner k of patch p: (side V0 start, V0 end, V1 start, V1 end) = (u0v0, u1v0, u0v1, u1v1)
    points = samples.coarse[:, [2, 2, 3, 3], [0, -1, 0, -1]].reshape(-1, 3)
    parent = np.arange(points.shape[0])

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    def union(x: int, y: int) -> None:
        parent[find(x)] = find(y)

    for x, y in cKDTree(points).query_pairs(tol):
        union(x, y)
    for e in edges:
        ends_a = [corner_number(e.side_a, k) + 4 * e.a for k in (0, 1)]
        ends_b = [corner_number(e.side_b, k) + 4 * e.b for k in (0, 1)]
        if e.reversed:
            ends_b = ends_b[::-1]
        union(ends_a[0], ends_b[0])
        union(ends_a[1], ends_b[1])
    groups: dict[int, list[int]] = {}
    for x in range(points.shape[0]):
        groups.setdefault(find(x), []).append(x)
    out = []
    for members in groups.values():
        if len({m // 4 for m in members}) < 2:
            continue
        named = tuple((m // 4, *_CORNER_NAMES[m % 4]) for m in members)
        out.append(CornerCluster(named, points[members].mean(axis=0)))
    return out


#: corner k of a patch as (side, end): u0v0, u1v0, u0v1, u1v1
_CORNER_NAMES = ((Side.V0, 0), (Side.V0, 1), (Side.V1, 0), (Side.V1, 1))


def corner_number(side: Side, end: int) -> int:
    """Number 0..3 (u0v0, u1v0, u0v1, u1v1) of the corner at ``end`` of ``side``."""
    at_u = {Side.U0: 0, Side.U1: 1}
    at_v = {Side.V0: 0, Side.V1: 1}
    if side in at_u:
        return at_u[side] + 2 * end
    return end + 2 * at_v[side]


def find_connectivity(patches: list[NurbsSurface], *, gap_tol: float | None = None,
                      strict: bool = True) -> Connectivity:
    """The connectivity table of ``patches`` (001 §8).

    Parameters
    ----------
    patches : list of NurbsSurface, dimension 3
    gap_tol : float, optional
        Model units: sides closer than this (ends and every sample) are one
        boundary curve. Default :func:`default_gap_tol`.
    strict : bool
        Raise :class:`NetworkTopologyError` on a topology violation; with False
        the offending pairs are listed in ``violations`` and not connected.

    Returns
    -------
    Connectivity
    """
    from ..tolerance import check_tolerance

    patches = list(patches)
    if not patches:
        raise InvalidGeometryError("find_connectivity needs at least one patch")
    for k, s in enumerate(patches):
        if not isinstance(s, NurbsSurface) or s.dimension != 3:
            raise InvalidGeometryError(f"patch {k} is not a 3D NurbsSurface")
    tol = default_gap_tol(patches) if gap_tol is None else check_tolerance(gap_tol, "gap_tol")
    samples = _sample_sides(patches)
    edges, violations = _shared_edges(patches, samples, tol, strict)
    corners = _corner_clusters(patches, samples, edges, tol)
    return Connectivity(tuple(edges), tuple(corners), tol, tuple(violations))
