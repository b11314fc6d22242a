"""Point / PointUse / Segment topology of an intersection segment soup, and curve tracing.

Step 4 of the SSI pipeline (000 §29.4.5; 004 §5), in arrays instead of linked lists:

* **Point**: the segment end points merged within ``tol`` (``cKDTree.query_pairs``,
  connected components of the pair graph = union-find). A merged point keeps the
  coordinates and (u, v) of its lowest-index member, never a mean (a mean of (u, v)
  across a periodic seam would be a point far from both).
* **PointUse**: one per segment end; ``uses[i]`` counts them. The circular lists of
  the paper become a CSR adjacency (``indptr``, ``neighbor_segment``).
* **Segment**: pairs of point indices. Zero-length segments (both ends merged) and
  duplicates (two triangle pairs yielding the same segment across a shared edge)
  are dropped.

Segments keep their input direction, and each traced chain is reversed if most
of its segments run against it (a ``SegmentSoup`` orients its segments along
``n_a x n_b``). Tracing follows the paper's algorithm: curves start at points whose use count is
not 2 and stop at the next such point (a point with more than 2 uses is a
bifurcation and breaks the curves there); segments left over form closed loops.
Before tracing, *hanging* ends (one use, not on a domain boundary) closer than
``join_tol`` are joined in mutually-nearest pairs: the merging of segments from
neighbouring overlap boxes whose triangulations do not align (004 §5).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from ...errors import InvalidGeometryError
from ..tolerance import check_tolerance

__all__ = ["Chain", "EndKind", "SegmentTopology", "build_topology", "topology_from_soup"]

Domain = tuple[float, float, float, float]


class EndKind(enum.Enum):
    """What lies at the end of a traced intersection curve."""

    #: the (u, v) of the end lies on the domain boundary of surface A or B
    BOUNDARY = "boundary"
    #: more than two segments meet at the end point (000 §29.4.5: curves break there)
    BIFURCATION = "bifurcation"
    #: one use and not on a domain boundary: a mesh border or a hanging end
    OPEN = "open"
    #: the curve is a closed loop and has no end
    CLOSED = "closed"


@dataclass(frozen=True)
class Chain:
    """One traced curve as indices into :class:`SegmentTopology` arrays.

    Attributes
    ----------
    point_ids : (n,) int
        Ordered points. A closed chain does not repeat its first point; a chain
        broken at a bifurcation on both ends may start and end at the same point.
    segment_ids : (n - 1,) int, or (n,) int when closed
        ``segment_ids[i]`` joins ``point_ids[i]`` and ``point_ids[i + 1]`` (cyclically).
    closed : bool
    start_kind, end_kind : EndKind
        Both :attr:`EndKind.CLOSED` for a closed chain.
    """

    point_ids: NDArray
    segment_ids: NDArray
    closed: bool
    start_kind: EndKind
    end_kind: EndKind

    def __len__(self) -> int:
        return int(self.point_ids.size)


@dataclass(frozen=True)
class SegmentTopology:
    """Unique points, cleaned segments, use counts and traced chains.

    Attributes
    ----------
    points : (m, 3) float
    uv_a, uv_b : (m, 2) float or None
    segments : (s, 2) int
        Point indices of each kept segment.
    source : (s,) int
        Index of each kept segment in the input soup (for ``tri_a``, ``tri_b``).
    uses : (m,) int
        PointUses per point.
    end_kinds : (m,) object
        EndKind of each point if a curve ends there (``None`` for 2 uses).
    chains : tuple of Chain
    """

    points: NDArray
    uv_a: NDArray | None
    uv_b: NDArray | None
    segments: NDArray
    source: NDArray
    uses: NDArray
    end_kinds: NDArray
    chains: tuple[Chain, ...]

    def chain_points(self, chain: Chain) -> NDArray:
        """(n, 3) float coordinates of a chain."""
        return self.points[chain.point_ids]


# ------------------------------------------------------------------ validation
def _check_ends(array: ArrayLike | None, k: int, dim: int, name: str) -> NDArray | None:
    if array is None:
        return None
    out = np.asarray(array, dtype=float)
    if out.shape != (k, 2, dim):
        raise InvalidGeometryError(f"{name} must have shape ({k}, 2, {dim}), got {out.shape}")
    if not np.all(np.isfinite(out)):
        raise InvalidGeometryError(f"{name} contains NaN or infinite values")
    return out


# ------------------------------------------------------------------ merging
#: points are first gathered in cubes of this share of the merge distance (all the
#: points of one cube are within it of each other)
_CUBE_SHARE = 1e-3


def _close_pairs(points: NDArray, tol: float) -> NDArray:
    """``(k, 2) int`` pairs of points within ``tol`` that connect the same components as
    all such pairs: the points of one small cube (edge ``_CUBE_SHARE tol``) joined to
    its first point, and between cubes the representatives of two cubes whose
    points come within ``tol`` (candidates from the representatives within ``tol``
    plus the cubes' diagonals, checked point by point). All pairs at once cost the
    square of the points piled in one spot: 5986 segment ends at 18 places gave
    17.8 million pairs and 1.1 GB (nist_ctc_02_rc.stp faces 476 x 477)."""
    n = points.shape[0]
    cube = _CUBE_SHARE * tol
    keys = np.floor((points - points.min(axis=0)) / cube).astype(np.int64)
    _, cell, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    cell = cell.ravel()
    if counts.size == n:                          # no two points in one cube
        return cKDTree(points).query_pairs(tol, output_type="ndarray")
    members = np.argsort(cell, kind="stable")
    starts = np.concatenate([[0], np.cumsum(counts)])
    first = members[starts[:-1]]
    inside = np.stack([first[cell], np.arange(n)], axis=1)[first[cell] != np.arange(n)]
    reach = tol + 2 * np.sqrt(3) * cube
    candidates = cKDTree(points[first]).query_pairs(reach, output_type="ndarray")
    single = (counts[candidates[:, 0]] == 1) & (counts[candidates[:, 1]] == 1)
    near = np.zeros(candidates.shape[0], dtype=bool)
    a, b = first[candidates[single, 0]], first[candidates[single, 1]]
    near[single] = np.linalg.norm(points[a] - points[b], axis=1) <= tol
    bound = np.nextafter(tol, np.inf)
    for k in np.flatnonzero(~single):             # a cube of several points: any pair
        p, q = (points[members[starts[c]:starts[c + 1]]] for c in candidates[k])
        near[k] = cKDTree(q).query(p, distance_upper_bound=bound)[0].min() <= tol
    between = first[candidates[near]]
    return np.concatenate([inside, between]).astype(np.int64, copy=False)


def _cluster(points: NDArray, tol: float) -> NDArray:
    """Labels ``(n,) int`` of points connected by distances <= tol, numbered by first member."""
    n = points.shape[0]
    pairs = _close_pairs(points, tol) if n else np.zeros((0, 2), dtype=np.int64)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    # renumber so that labels increase with the lowest member index
    first = np.full(labels.max() + 1 if n else 0, n, dtype=np.int64)
    np.minimum.at(first, labels, np.arange(n))
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    return rank[labels]


def _representatives(labels: NDArray) -> NDArray:
    """Index of the lowest member of each label: (n_labels,) int."""
    first = np.full(labels.max() + 1 if labels.size else 0, labels.size, dtype=np.int64)
    np.minimum.at(first, labels, np.arange(labels.size))
    return first


def _clean_segments(seg: NDArray) -> tuple[NDArray, NDArray]:
    """Drop zero-length and duplicate segments; returns (segments (s, 2), source (s,))."""
    keep = np.flatnonzero(seg[:, 0] != seg[:, 1])
    key = np.sort(seg[keep], axis=1)
    _, first = np.unique(key, axis=0, return_index=True)
    source = keep[np.sort(first)]
    return seg[source], source


def _split_at_points(points: NDArray, seg: NDArray, tol: float) -> tuple[NDArray, NDArray]:
    """Segments split at every point that lies on them within ``tol`` (not at their ends).

    Two triangles beside an edge that lies in the other surface (a plane through a
    row of mesh vertices) each give a segment along it, and where the tessellation
    is finer on one side than the other the two overlap without sharing ends: split
    at each other's ends they become the same pieces, which :func:`_clean_segments`
    keeps once, instead of three-way junctions along a simple curve.

    Returns ``(segments (s', 2) int, origin (s',) int)``: the pieces, in order along
    each segment, and the segment each comes from.
    """
    if seg.shape[0] == 0:
        return seg, np.arange(0)
    a, b = points[seg[:, 0]], points[seg[:, 1]]
    half = 0.5 * np.linalg.norm(b - a, axis=1)
    tree = cKDTree(points)
    near = tree.query_ball_point(0.5 * (a + b), half + tol)
    pieces, origin = [], []
    for k, found in enumerate(near):
        inner = [q for q in found if q != seg[k, 0] and q != seg[k, 1]]
        if inner:
            q = np.array(inner)
            d = b[k] - a[k]
            s = (points[q] - a[k]) @ d / max(float(d @ d), 1e-300)
            off = np.linalg.norm(points[q] - (a[k] + s[:, None] * d), axis=1)
            on = (off <= tol) & (s > 0.0) & (s < 1.0)
            if on.any():
                chain = np.concatenate([[seg[k, 0]], q[on][np.argsort(s[on])], [seg[k, 1]]])
                pieces.append(np.stack([chain[:-1], chain[1:]], axis=1))
                origin.append(np.full(chain.size - 1, k))
                continue
        pieces.append(seg[k:k + 1])
        origin.append(np.array([k]))
    return np.concatenate(pieces), np.concatenate(origin)


def _on_boundary(uv: NDArray | None, domain: Domain | None, uv_tol: float) -> NDArray | bool:
    if uv is None or domain is None:
        return False
    u0, u1, v0, v1 = domain
    eu, ev = uv_tol * (u1 - u0), uv_tol * (v1 - v0)
    u, v = uv[:, 0], uv[:, 1]
    return (u <= u0 + eu) | (u >= u1 - eu) | (v <= v0 + ev) | (v >= v1 - ev)


def _join_hanging(points: NDArray, segments: NDArray, hanging: NDArray, join_tol: float
                  ) -> NDArray:
    """Point relabelling ``(m,) int`` joining mutually nearest hanging ends within join_tol.

    The two ends of one segment are never joined (that would collapse it).
    """
    m = points.shape[0]
    label = np.arange(m)
    ids = np.flatnonzero(hanging)
    if ids.size < 2:
        return label
    tree = cKDTree(points[ids])
    dist, nearest = tree.query(points[ids], k=2, distance_upper_bound=join_tol)
    partner = np.where(np.isfinite(dist[:, 1]), nearest[:, 1], -1)
    valid = partner >= 0
    mutual = np.zeros(ids.size, dtype=bool)
    mutual[valid] = partner[partner[valid]] == np.flatnonzero(valid)
    # the two ends of one segment must not be joined
    seg_of = np.full(m, -1)
    seg_of[segments.ravel()] = np.repeat(np.arange(segments.shape[0]), 2)
    a, b = ids[mutual], ids[partner[mutual]]
    ok = (a < b) & (seg_of[a] != seg_of[b])
    label[b[ok]] = a[ok]
    return label


# ------------------------------------------------------------------ adjacency
def _adjacency(segments: NDArray, m: int) -> tuple[NDArray, NDArray, NDArray]:
    """CSR PointUse lists: ``indptr (m+1,)``, ``seg (2s,)``, ``other (2s,)`` per point."""
    ends = segments.ravel()
    seg = np.repeat(np.arange(segments.shape[0]), 2)
    other = segments[:, ::-1].ravel()
    order = np.argsort(ends, kind="stable")
    indptr = np.concatenate([[0], np.cumsum(np.bincount(ends, minlength=m))])
    return indptr, seg[order], other[order]


def _walk(start: int, first_seg: int, indptr: NDArray, nseg: NDArray, nother: NDArray,
          uses: NDArray, used: NDArray, segments: NDArray) -> tuple[list[int], list[int]]:
    """Steps 3-7 of the tracing algorithm from ``start`` along ``first_seg``."""
    pts, segs = [start], []
    cur, s = start, first_seg
    while True:
        used[s] = True
        segs.append(s)
        nxt = int(segments[s, 0] if segments[s, 1] == cur else segments[s, 1])
        if nxt == start and uses[nxt] == 2:      # closed loop back at its start
            return pts, segs
        pts.append(nxt)
        if uses[nxt] != 2:
            return pts, segs
        lo = indptr[nxt]
        s_next = int(nseg[lo] if nseg[lo] != s else nseg[lo + 1])
        if used[s_next]:
            return pts, segs
        cur, s = nxt, s_next


def _trace(segments: NDArray, uses: NDArray, end_kinds: NDArray) -> tuple[Chain, ...]:
    m = uses.size
    indptr, nseg, nother = _adjacency(segments, m)
    used = np.zeros(segments.shape[0], dtype=bool)
    chains: list[Chain] = []
    for p in np.flatnonzero(uses != 2):           # open curves: ends have uses != 2
        for s in nseg[indptr[p]:indptr[p + 1]]:
            if used[s]:
                continue
            pts, segs = _walk(int(p), int(s), indptr, nseg, nother, uses, used, segments)
            chains.append(Chain(np.array(pts), np.array(segs), False,
                                end_kinds[pts[0]], end_kinds[pts[-1]]))
    for s in range(segments.shape[0]):            # what is left: closed loops
        if used[s]:
            continue
        start = int(segments[s, 0])
        pts, segs = _walk(start, s, indptr, nseg, nother, uses, used, segments)
        chains.append(Chain(np.array(pts), np.array(segs), True,
                            EndKind.CLOSED, EndKind.CLOSED))
    return tuple(chains)


def _orient(chain: Chain, segments: NDArray) -> Chain:
    """Reverse a chain when most of its segments run against it (the soup orients its
    segments along ``n_a x n_b``, so a chain follows the curve's direction)."""
    pts, segs = chain.point_ids, chain.segment_ids
    ahead = np.roll(pts, -1)[: segs.size] if chain.closed else pts[1:]
    forward = np.count_nonzero(segments[segs, 1] == ahead)
    if 2 * forward >= segs.size:
        return chain
    if chain.closed:
        return Chain(np.roll(pts[::-1], 1), segs[::-1], True, chain.end_kind, chain.start_kind)
    return Chain(pts[::-1], segs[::-1], False, chain.end_kind, chain.start_kind)


def _end_kinds(uses: NDArray, boundary: NDArray) -> NDArray:
    kinds = np.full(uses.size, None, dtype=object)
    kinds[uses == 1] = EndKind.OPEN
    kinds[(uses != 2) & boundary] = EndKind.BOUNDARY
    kinds[uses > 2] = EndKind.BIFURCATION
    return kinds


# ------------------------------------------------------------------ public
def build_topology(points: ArrayLike, uv_a: ArrayLike | None = None,
                   uv_b: ArrayLike | None = None, *, tol: float,
                   join_tol: float | None = None, domain_a: Domain | None = None,
                   domain_b: Domain | None = None, uv_tol: float = 1e-9) -> SegmentTopology:
    """Merge segment ends into unique points, clean the segments and trace the curves.

    Parameters
    ----------
    points : (k, 2, 3) float
        End points of the intersection segments, any order and direction.
    uv_a, uv_b : (k, 2, 2) float, optional
        Parameters of each end on surface A / B (``None`` for a mesh operand).
    tol : float > 0
        End points closer than ``tol`` are one Point (transitively).
    join_tol : float, optional
        Hanging ends (one use, not on a boundary) closer than this, mutually
        nearest, are joined (004 §5). Default: no joining beyond ``tol``.
    domain_a, domain_b : (u0, u1, v0, v1), optional
        Parameter domains; an end whose (u, v) lies within ``uv_tol`` (relative to
        the domain size) of a domain side is a :attr:`EndKind.BOUNDARY` end.
    uv_tol : float

    Returns
    -------
    SegmentTopology

    Raises
    ------
    InvalidGeometryError
        Wrong shapes or non-finite values.
    InvalidToleranceError
        A tolerance that is not finite and positive.
    """
    tol = check_tolerance(tol, "tol")
    join_tol = tol if join_tol is None else check_tolerance(join_tol, "join_tol")
    uv_tol = check_tolerance(uv_tol, "uv_tol", allow_zero=True)
    ends = np.asarray(points, dtype=float)
    if ends.ndim != 3 or ends.shape[1:] != (2, 3):
        raise InvalidGeometryError(f"points must have shape (k, 2, 3), got {ends.shape}")
    if not np.all(np.isfinite(ends)):
        raise InvalidGeometryError("points contain NaN or infinite values")
    k = ends.shape[0]
    uva = _check_ends(uv_a, k, 2, "uv_a")
    uvb = _check_ends(uv_b, k, 2, "uv_b")

    flat = ends.reshape(-1, 3)
    labels = _cluster(flat, tol) if k else np.zeros(0, dtype=np.int64)
    rep = _representatives(labels)
    pts = flat[rep]
    ua = None if uva is None else uva.reshape(-1, 2)[rep]
    ub = None if uvb is None else uvb.reshape(-1, 2)[rep]
    split, origin = _split_at_points(pts, labels.reshape(k, 2), tol)
    segments, source = _clean_segments(split)
    source = origin[source]
    boundary = np.zeros(pts.shape[0], dtype=bool)
    boundary |= _on_boundary(ua, domain_a, uv_tol)
    boundary |= _on_boundary(ub, domain_b, uv_tol)

    if join_tol > tol and segments.size:
        uses = np.bincount(segments.ravel(), minlength=pts.shape[0])
        relabel = _join_hanging(pts, segments, (uses == 1) & ~boundary, join_tol)
        segments, keep = _clean_segments(relabel[segments])
        source = source[keep]

    used_pts = np.unique(segments)                 # drop points no segment uses any more
    compact = np.full(pts.shape[0], -1)
    compact[used_pts] = np.arange(used_pts.size)
    pts, boundary = pts[used_pts], boundary[used_pts]
    ua = None if ua is None else ua[used_pts]
    ub = None if ub is None else ub[used_pts]
    segments = compact[segments].reshape(-1, 2)
    uses = np.bincount(segments.ravel(), minlength=pts.shape[0])
    kinds = _end_kinds(uses, boundary)
    chains = tuple(_orient(c, segments) for c in _trace(segments, uses, kinds))
    return SegmentTopology(pts, ua, ub, segments, source, uses, kinds, chains)


def topology_from_soup(soup, *, tol: float, join_tol: float | None = None,
                       domain_a: Domain | None = None, domain_b: Domain | None = None,
                       uv_tol: float = 1e-9) -> SegmentTopology:
    """:func:`build_topology` on a ``SegmentSoup`` (anything with ``points``, ``uv_a``, ``uv_b``)."""
    return build_topology(soup.points, getattr(soup, "uv_a", None), getattr(soup, "uv_b", None),
                          tol=tol, join_tol=join_tol, domain_a=domain_a, domain_b=domain_b,
                          uv_tol=uv_tol)
