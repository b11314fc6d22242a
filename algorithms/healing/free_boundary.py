"""What a model's free edges are: sides of gaps between faces, or its free boundary.

A mesh generator fails on the first free edge, but not every free edge is a defect:
a ship's half hull ends at its centre plane and deck, a pipe at its mouth. Healing
reports its free edges by what they are, judged by the geometry around each:

*gap*
    One face's side of an edge sewing shares but the faces leave open in the geometry
    (``sewn``), or another face's free edge (or its side of such an edge) runs beside
    it: at a quarter, half and three quarters of its length that
    polyline lies within :data:`BESIDE` x its length of it. The two sides of a
    sliver between faces, a long edge against the short ones of a T-junction. Its
    *width* is the largest distance from its inner samples to the others' polylines
    where they run beside it (within ``BESIDE`` x its length, or ``join`` for a sewn
    side: not where a gap opens out towards an end), off by their chords' sagitta at
    most (up to ``_SAMPLES`` points an edge).
*boundary*
    Nothing of another face lies beside it: the model's open boundary, or the rim
    of a hole no face covers.

A fold of the rim back onto itself closer than ``BESIDE`` (a slot narrower than a
twentieth of its sides, cut into one face) is a boundary: only other faces' edges
count. Free edges whose ends meet (within ``join``) make one *loop*: a
``"gap"`` (all its edges along gaps), an ``"open boundary"`` (none), a ``"hole"``
(none, and it runs along one of the ``holes`` rims the caller classified as
holes by their surroundings, :mod:`.hole_cap`) or ``"gap and boundary"`` (a gap
opening onto the boundary: its edges counted each by its own kind).

Only the gaps and holes are interior free edges: defects. The loops' kinds are
judged on polylines alone (``(n, 3)`` points along each edge, its owner face), so
this holds for any surface type.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ...errors import InvalidGeometryError
from ..face_region import SegmentTree
from ..intersection.refine import segment_distance

__all__ = ["BESIDE", "FreeBoundary", "classify_free_edges"]

#: a free edge is along a gap when another face's free edge lies within this times its
#: length of its points at a quarter, half and three quarters of it (two edges leaving
#: a vertex at an angle a lie ``3 sin(a) / 4`` of the length apart at three quarters:
#: a wedge below about 3.8 degrees)
BESIDE = 0.05
#: point-segment distances computed per block
_BLOCK = 1_000_000
#: points per polyline used (its ends and quarters among them)
_SAMPLES = 33
_QUARTERS = (0.25, 0.5, 0.75)


@dataclass(frozen=True)
class FreeBoundary:
    """The free edges of a model by kind (:func:`classify_free_edges`).

    Attributes
    ----------
    kinds : tuple of str
        Per edge, "gap" or "boundary".
    widths : (n,) float
        Per edge along a gap, the gap's width there (model units); NaN on a boundary.
    loop : (n,) int
        Per edge, the number of its loop.
    loop_kinds : tuple of str
        Per loop, "gap", "open boundary", "hole" or "gap and boundary".
    owners : (n,) int
        Per edge, its face.
    lengths : (n,) float
        Per edge, its polyline's length.
    """

    kinds: tuple[str, ...]
    widths: NDArray
    loop: NDArray
    loop_kinds: tuple[str, ...]
    owners: NDArray
    lengths: NDArray

    @property
    def edges(self) -> dict[str, int]:
        """How many free edges lie along gaps, on the open boundary and around holes."""
        hole = {k for k, kind in enumerate(self.loop_kinds) if kind == "hole"}
        out = {"gap": 0, "open boundary": 0, "hole": 0}
        for kind, loop in zip(self.kinds, self.loop):
            out["gap" if kind == "gap" else "hole" if int(loop) in hole
                else "open boundary"] += 1
        return out

    @property
    def interior(self) -> int:
        """Free edges that are defects: along gaps or around holes."""
        counts = self.edges
        return counts["gap"] + counts["hole"]

    def interior_loops(self) -> list[dict]:
        """Per loop with interior free edges, widest gap first: its kind, how many
        edges along gaps (or around a hole), their faces, their length and the widest
        gap along them (None around a hole)."""
        out = []
        for k, kind in enumerate(self.loop_kinds):
            if kind == "open boundary":
                continue
            members = np.flatnonzero((self.loop == k) & ((np.array(self.kinds) == "gap")
                                                          | (kind == "hole")))
            widths = self.widths[members]
            widths = widths[np.isfinite(widths)]
            out.append({"kind": kind, "edges": int(members.size),
                        "faces": sorted({int(f) for f in self.owners[members]}),
                        "length": float(self.lengths[members].sum()),
                        "widest_gap": float(widths.max()) if widths.size else None})
        return sorted(out, key=lambda d: -(d["widest_gap"] or 0.0))

    def as_dict(self) -> dict:
        loops: dict[str, int] = {}
        for kind in self.loop_kinds:
            loops[kind] = loops.get(kind, 0) + 1
        gaps = self.widths[~np.isnan(self.widths)]
        return {"edges": self.edges, "interior": self.interior, "loops": loops,
                "widest_gap": float(gaps.max()) if gaps.size else None,
                "interior_loops": self.interior_loops()}


def classify_free_edges(polylines: Sequence[ArrayLike], owners: Sequence[int], *,
                        join: float, holes: Sequence[ArrayLike] = (),
                        sewn: Sequence[bool] = ()) -> FreeBoundary:
    """Each free edge a gap's side or on the boundary, and their loops (module doc).

    Parameters
    ----------
    polylines : sequence of (m, 3) float
        Points along each free edge, ``m >= 3`` (a free edge, or one face's side of a
        shared edge open in the geometry).
    owners : sequence of int
        The face of each polyline: only other faces' edges make a gap.
    join : float
        Ends closer than this are one vertex (model units; ``gap_tol``).
    holes : sequence of sequence of (k, 3) float
        Rims of loops classified as holes, each as polylines along its edges: a loop of
        boundary edges whose points lie within ``join`` of one of them is a hole.
    sewn : sequence of bool, optional
        Per polyline, whether it is one face's side of an edge sewing shares (open in
        the geometry): a gap's side however short the edge (its width measured within
        ``join`` too). Default none.

    Returns
    -------
    FreeBoundary

    Examples
    --------
    Two unit squares 0.01 apart side by side: the edges facing each other are a
    gap's sides, the other six the outer boundary, one loop of both kinds.

    >>> import numpy as np
    >>> t = np.linspace(0, 1, 9)[:, None]
    >>> def seg(a, b):
    ...     return np.asarray(a, float) + t * (np.asarray(b, float) - np.asarray(a, float))
    >>> left = [seg((0, 0, 0), (1, 0, 0)), seg((1, 0, 0), (1, 1, 0)),
    ...         seg((1, 1, 0), (0, 1, 0)), seg((0, 1, 0), (0, 0, 0))]
    >>> right = [p + (1.01, 0, 0) for p in left]
    >>> fb = classify_free_edges(left + right, [0] * 4 + [1] * 4, join=0.02)
    >>> fb.kinds[1], fb.kinds[7], fb.kinds[0]
    ('gap', 'gap', 'boundary')
    >>> fb.edges, fb.loop_kinds
    ({'gap': 2, 'open boundary': 6, 'hole': 0}, ('gap and boundary',))
    """
    lines = [np.asarray(p, dtype=float) for p in polylines]
    owner = np.asarray(owners, dtype=np.int64)
    if owner.shape != (len(lines),):
        raise InvalidGeometryError(f"owners must have one face per polyline "
                                   f"({len(lines)}), got shape {owner.shape}")
    if not np.isfinite(join) or join < 0:
        raise InvalidGeometryError(f"join must be a finite distance >= 0, got {join!r}")
    for k, p in enumerate(lines):
        if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 3 or not np.isfinite(p).all():
            raise InvalidGeometryError(f"polyline {k} must be (m >= 3, 3) finite points, "
                                       f"got shape {p.shape}")
    n = len(lines)
    shared = np.zeros(n, dtype=bool) if len(sewn) == 0 else np.asarray(sewn, dtype=bool)
    if shared.shape != (n,):
        raise InvalidGeometryError(f"sewn must have one flag per polyline ({n}), got shape "
                                   f"{shared.shape}")
    if n == 0:
        return FreeBoundary((), np.zeros(0), np.zeros(0, dtype=np.int64), (),
                            np.zeros(0, dtype=np.int64), np.zeros(0))
    along, widths = _gap_widths(lines, owner, shared, join)
    kinds = tuple("gap" if g else "boundary" for g in along)
    loop = _loops(lines, join)
    hole_rims = [[np.asarray(p, dtype=float).reshape(-1, 3) for p in rim] for rim in holes]
    loop_kinds = []
    for k in range(int(loop.max()) + 1):
        members = np.flatnonzero(loop == k)
        gap = sum(kinds[m] == "gap" for m in members)
        if gap == len(members):
            loop_kinds.append("gap")
        elif gap:
            loop_kinds.append("gap and boundary")
        elif _along_a_hole(np.concatenate([lines[m] for m in members]), hole_rims, join):
            loop_kinds.append("hole")
        else:
            loop_kinds.append("open boundary")
    lengths = np.array([np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in lines])
    return FreeBoundary(kinds, widths, loop, tuple(loop_kinds), owner, lengths)


def _gap_widths(lines: list[NDArray], owner: NDArray, sewn: NDArray, join: float
                ) -> tuple[NDArray, NDArray]:
    """(n,) bool, (n,) float: per polyline whether it lies along a gap (other faces'
    polylines within ``BESIDE`` x its length at its quarters, or ``sewn``) and the
    largest distance from its inner points to them (NaN on a boundary; measured within
    that reach, or ``join`` for a sewn side)."""
    lines = [_thinned(p) for p in lines]
    a = np.concatenate([p[:-1] for p in lines])                      # (s, 3) segment starts
    b = np.concatenate([p[1:] for p in lines])
    seg_owner = np.concatenate([np.full(len(p) - 1, o) for p, o in zip(lines, owner)])
    length = np.array([np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in lines])
    inner = [p[1:-1] for p in lines]
    points = np.concatenate(inner)
    point_line = np.concatenate([np.full(len(q), k) for k, q in enumerate(inner)])
    reach = np.where(sewn, np.maximum(BESIDE * length, join), BESIDE * length)
    distance = _to_other_segments(points, owner[point_line], reach[point_line], a, b,
                                  seg_owner)
    along = sewn.copy()
    out = np.full(len(lines), np.nan)
    start = 0
    for k, p in enumerate(lines):
        d = distance[start:start + len(p) - 2]
        start += len(p) - 2
        quarters = np.clip([round(q * (len(p) - 1)) - 1 for q in _QUARTERS], 0, len(d) - 1)
        along[k] |= bool(np.all(d[quarters] <= BESIDE * length[k]))
        if along[k] and np.isfinite(d).any():
            out[k] = float(d[np.isfinite(d)].max())
    return along, out


def _thinned(p: NDArray) -> NDArray:
    """At most ``_SAMPLES`` of the points of ``p``, its ends and its quarters kept."""
    if len(p) <= _SAMPLES:
        return p
    return p[np.unique(np.round(np.linspace(0, len(p) - 1, _SAMPLES)).astype(np.int64))]


def _to_other_segments(points: NDArray, point_owner: NDArray, reach: NDArray, a: NDArray,
                       b: NDArray, seg_owner: NDArray) -> NDArray:
    """(m,) float: distance from each point to the nearest segment ``a -> b`` of
    another owner, where one lies within its ``reach`` (inf elsewhere); candidates by a
    tree of the segments' midpoints."""
    out = np.full(len(points), np.inf)
    a, b, seg_owner = _pieces(a, b, seg_owner)
    d = b - a
    half = 0.5 * float(np.sqrt(np.einsum("ij,ij->i", d, d)).max())
    near = cKDTree(0.5 * (a + b)).query_ball_point(points, reach + half)
    counts = np.fromiter((len(c) for c in near), dtype=np.int64, count=len(points))
    if not counts.sum():
        return out
    pi = np.repeat(np.arange(len(points)), counts)
    si = np.fromiter((s for c in near for s in c), dtype=np.int64, count=int(counts.sum()))
    keep = point_owner[pi] != seg_owner[si]
    pi, si = pi[keep], si[keep]
    for start in range(0, len(pi), _BLOCK):
        p, s = pi[start:start + _BLOCK], si[start:start + _BLOCK]
        np.minimum.at(out, p, segment_distance(points[p], a[s], b[s]))
    return out


def _pieces(a: NDArray, b: NDArray, owner: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """The segments ``a -> b`` cut into pieces no longer than the median segment (or a
    quarter of the mean), so that a tree of midpoints finds every segment near a point
    within half a piece more than the reach (one long segment widened every point's search: 11
    million candidates on ``overture_asmo_icem.igs``, 2.6 s)."""
    length = np.linalg.norm(b - a, axis=1)
    # (no shorter than a quarter of the mean: many tiny segments, of degenerate edges,
    # would cut one long one into billions)
    step = max(float(np.median(length)), 0.25 * float(length.mean()))
    if step <= 0.0:
        return a, b, owner
    count = np.maximum(np.ceil(length / step).astype(np.int64), 1)
    seg = np.repeat(np.arange(len(a)), count)
    first = np.cumsum(count) - count
    k = np.arange(seg.size) - first[seg]
    t0, t1 = k / count[seg], (k + 1) / count[seg]
    d = b - a
    return (a[seg] + t0[:, None] * d[seg], a[seg] + t1[:, None] * d[seg], owner[seg])


def _loops(lines: list[NDArray], join: float) -> NDArray:
    """(n,) int: the loop of each polyline, polylines whose ends lie within ``join``
    of each other in one."""
    ends = np.concatenate([p[[0, -1]] for p in lines])               # (2 n, 3)
    pairs = cKDTree(ends).query_pairs(join, output_type="ndarray") // 2
    n = len(lines)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    return connected_components(graph, directed=False)[1].astype(np.int64)


def _along_a_hole(points: NDArray, rims: list[list[NDArray]], join: float) -> bool:
    """Whether ``points`` all lie within ``join`` of one of the ``rims`` (each
    polylines, sampled evenly: :class:`~surfprep.algorithms.face_region.SegmentTree`)."""
    return any(float(SegmentTree.from_polylines(rim).distance(points).max()) <= join
               for rim in rims if any(len(p) >= 2 for p in rim))
