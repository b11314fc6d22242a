"""The hybrid hierarchical representation of two composed solids (004 §4-5).

Levels, each kept for later queries (a :class:`Hierarchy`):

1. **Bézier patches** (004 §4.1) of each solid's exterior boundary surfaces, with their
   control-net boxes (:class:`BoundaryPatches`; a solid's level 1 does not depend on
   the other solid, so composing it again with a changed partner reuses it).
2. **Overlap boxes** (004 §4.2): the intersection of the boxes of every pair of
   patches of A and B whose boxes meet. Each patch is then subdivided (dyadic
   sub-rectangles, ``SUBDIVISION`` levels, the secondary decomposition of §4.1 by
   blossoming, :func:`~surfprep.algorithms.intersection.culling.subpatch_boxes`) and
   only the sub-patches whose boxes meet the overlap box are kept: "the portions of
   the Bézier patches that intersect the overlap box". A box where one side keeps
   nothing is empty and dropped.
3. **Selective tessellation** (004 §4.3) of only those sub-patches, cut back to the
   overlap box during refinement
   (:func:`~surfprep.algorithms.intersection.tessellation.tessellate` with the box as
   its keep box). The subdivision criterion is the parametric chord error, not the
   flatness metric of eq. (4.1) (:func:`quad_flatness`), which vanishes on every
   ruled strip -- four corners of a cylinder strip are coplanar -- and so cannot bound
   how far a triangle lies from the surface.
4. **A kd-tree** over the vertices of A's triangulation in each box, and the sweep
   of B's triangles through it (004 §4.4, §5, :func:`.sweep.sweep_pairs`); the
   box-tree descent the library's surface--surface intersection uses
   (:func:`~surfprep.algorithms.intersection.culling.candidate_pairs`) gives the same
   pairs and can be chosen instead (``candidates="descent"``).
5. **Intersection curves** (004 §4.5, §5, §6): the segments of the triangle pairs
   (:func:`~surfprep.algorithms.intersection.triangles.intersect_triangles`), merged
   into bidirectional lists per box (:func:`.sweep.link_segments`), every point
   moved onto both exact surfaces by triple-plane intersection
   (:func:`.correction.correct_points`; a point that does not converge lies beyond a
   face's boundary, where the curve passes to the next face, and is dropped), then
   the hanging ends of neighbouring boxes
   joined -- mutually nearest ends within a reach of a few triangle edges -- until
   none hangs (:class:`Loop`).

Where 004 refines "merge triangles" where two boxes' triangulations meet, the ends
here are already on the exact curve (corrected), so joining them needs no further
triangles.

References
----------
004 §4-6 (see ``surfprep.algorithms`` References).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from ..intersection.culling import candidate_pairs, overlap_boxes, subpatch_boxes, surface_patch_boxes
from ..intersection.mesh import TriangleMesh
from ..intersection.tessellation import tessellate
from ..intersection.triangles import intersect_triangles
from ..volume import NurbsVolume
from .correction import correct_points
from .sweep import Chains, link_segments, sweep_pairs, triangle_boxes

__all__ = ["BoundaryPatches", "Hierarchy", "Loop", "OverlapBox", "build_hierarchy",
           "quad_flatness"]

#: dyadic levels of the secondary decomposition of a patch against its overlap box
SUBDIVISION = 2
#: ends of two chains are joined when nearer than this many longest triangle edges
JOIN_REACH = 3.0


def quad_flatness(p0: NDArray, p1: NDArray, p2: NDArray, p3: NDArray) -> NDArray:
    """The flatness metric of 004 eq. (4.1) of quadrilaterals ``(p0, p1, p2, p3)``:
    ``((p1 - p0) x (p2 - p0)) . (p3 - p0) / |p1 - p0|^2``, each ``(..., 3)``.

    Six times the volume of the tetrahedron of the corners over the squared first
    edge: a length, zero for a planar quadrilateral (see the module doc for why the
    tessellation does not split by it)."""
    e1, e2, e3 = p1 - p0, p2 - p0, p3 - p0
    return np.abs(np.einsum("...i,...i->...", np.cross(e1, e2), e3)) / np.einsum(
        "...i,...i->...", e1, e1)


# ------------------------------------------------------------------ level 1
@dataclass(frozen=True, eq=False)
class BoundaryPatches:
    """Level 1 of one solid: the Bézier patches of its exterior boundary surfaces.

    Attributes
    ----------
    volume : NurbsVolume
    names : tuple of str
        The exterior faces (``"u1"``, ...), :meth:`NurbsVolume.exterior_faces`.
    surfaces : tuple of NurbsSurface
    face : (k,) int
        The face of each patch.
    rects : (k, 4) float
        Its parameter rectangle ``[u0, u1, v0, v1]`` on that face.
    boxes : (k, 2, 3) float
        Its control-net box.
    """

    volume: NurbsVolume
    names: tuple
    surfaces: tuple
    face: NDArray
    rects: NDArray
    boxes: NDArray

    @classmethod
    def of(cls, volume: NurbsVolume) -> BoundaryPatches:
        faces = volume.exterior_faces()
        face, rects, boxes = [], [], []
        for k, surface in enumerate(faces.values()):
            b, r = surface_patch_boxes(surface)
            face.append(np.full(r.shape[0], k, dtype=np.int64))
            rects.append(r)
            boxes.append(b)
        if not faces:
            return cls(volume, (), (), np.zeros(0, np.int64), np.zeros((0, 4)), np.zeros((0, 2, 3)))
        return cls(volume, tuple(faces), tuple(faces.values()), np.concatenate(face),
                   np.concatenate(rects), np.concatenate(boxes))

    @property
    def size(self) -> int:
        return int(self.face.size)


# ------------------------------------------------------------------ levels 2-4
@dataclass(frozen=True, eq=False)
class OverlapBox:
    """One overlap box and what lies under it (levels 2-5 of one pair of patches).

    Attributes
    ----------
    patch_a, patch_b : int
        The patches (indices into each solid's :class:`BoundaryPatches`).
    box : (2, 3) float
    rects_a, rects_b : (r, 4) float
        The sub-patches kept on each side (level 3).
    mesh_a, mesh_b : TriangleMesh
        Their triangulations, with the ``(u, v)`` of every vertex.
    pairs : (p, 2) int
        Triangle pairs whose boxes meet (level 4).
    segments : (s, 2, 3) float
        Intersection segments of those pairs, oriented along ``n_a x n_b``.
    uv_a, uv_b : (s, 2, 2) float
        The segment ends' parameters on each face (barycentric).
    chains : Chains
        The segments merged into bidirectional lists.
    """

    patch_a: int
    patch_b: int
    box: NDArray
    rects_a: NDArray
    rects_b: NDArray
    mesh_a: TriangleMesh
    mesh_b: TriangleMesh
    pairs: NDArray
    segments: NDArray
    uv_a: NDArray
    uv_b: NDArray
    chains: Chains


@dataclass(frozen=True, eq=False)
class Loop:
    """A merged intersection curve (level 5): points on both exact boundaries.

    Attributes
    ----------
    points : (n, 3) float
    face_a, face_b : (n,) int
        The face of A and of B each point lies on (indices into the names of each
        solid's :class:`BoundaryPatches`).
    uv_a, uv_b : (n, 2) float
        Its parameters there.
    box : (n,) int
        The overlap box whose triangles gave it.
    gap : (n,) float
        Distance between its feet on the two surfaces (<= tol where corrected).
    closed : bool
        A closed loop does not repeat its first point.
    """

    points: NDArray
    face_a: NDArray
    face_b: NDArray
    uv_a: NDArray
    uv_b: NDArray
    box: NDArray
    gap: NDArray
    closed: bool


@dataclass(frozen=True, eq=False)
class Hierarchy:
    """The hybrid hierarchical representation of two composed solids (module doc).

    Attributes
    ----------
    a, b : BoundaryPatches
        Level 1 of each solid.
    candidate_boxes : int
        Pairs of patch boxes that meet (before the sub-patch test of level 2).
    boxes : tuple of OverlapBox
        The non-empty overlap boxes, with levels 3-5 under each.
    loops : tuple of Loop
    tol, mesh_tol : float
    candidates : str
        ``"sweep"`` or ``"descent"``: how level 4 found the triangle pairs.
    times : dict
        Seconds per stage.
    """

    a: BoundaryPatches
    b: BoundaryPatches
    candidate_boxes: int
    boxes: tuple
    loops: tuple
    tol: float
    mesh_tol: float
    candidates: str
    times: dict = field(default_factory=dict)

    def counts(self) -> dict:
        """How many items each level holds (004 §7 reports these for its tori)."""
        return {
            "bezier_patches_a": self.a.size, "bezier_patches_b": self.b.size,
            "patch_box_pairs": self.candidate_boxes, "overlap_boxes": len(self.boxes),
            "subpatches": int(sum(o.rects_a.shape[0] + o.rects_b.shape[0] for o in self.boxes)),
            "triangles": int(sum(o.mesh_a.triangles.shape[0] + o.mesh_b.triangles.shape[0]
                                 for o in self.boxes)),
            "triangle_pairs": int(sum(o.pairs.shape[0] for o in self.boxes)),
            "segments": int(sum(o.segments.shape[0] for o in self.boxes)),
            "loops": len(self.loops),
            "closed_loops": int(sum(loop.closed for loop in self.loops)),
        }


def _split(rects: NDArray, levels: int) -> NDArray:
    """``(k, 4**levels, 4)`` dyadic sub-rectangles of rectangles ``(k, 4)``."""
    n = 2 ** levels
    s = np.arange(n + 1) / n
    u0, u1, v0, v1 = (rects[:, i:i + 1] for i in range(4))
    us, vs = u0 + (u1 - u0) * s, v0 + (v1 - v0) * s                      # (k, n + 1)
    iu, iv = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    iu, iv = iu.ravel(), iv.ravel()
    return np.stack([us[:, iu], us[:, iu + 1], vs[:, iv], vs[:, iv + 1]], axis=2)


def _kept_subpatches(patches: BoundaryPatches, which: NDArray, subs: NDArray, boxes: NDArray,
                     pad: float) -> NDArray:
    """``(k, m)`` mask of the sub-patches ``subs (k, m, 4)`` of patches ``which`` whose boxes
    meet the overlap boxes ``(k, 2, 3)`` (padded)."""
    keep = np.zeros(subs.shape[:2], dtype=bool)
    for f, surface in enumerate(patches.surfaces):
        rows = np.flatnonzero(patches.face[which] == f)
        if rows.size == 0:
            continue
        sub_boxes = subpatch_boxes(surface, subs[rows].reshape(-1, 4)).reshape(
            rows.size, subs.shape[1], 2, 3)
        box = boxes[rows][:, None]
        keep[rows] = np.all((sub_boxes[:, :, 0] - pad <= box[:, :, 1])
                            & (box[:, :, 0] - pad <= sub_boxes[:, :, 1]), axis=2)
    return keep


def _barycentric_uv(mesh: TriangleMesh, tri: NDArray, bary: NDArray) -> NDArray:
    return np.einsum("kec,kcd->ked", bary, mesh.uv[mesh.triangles[tri]])


def _box_under(patches_a: BoundaryPatches, patches_b: BoundaryPatches, pa: int, pb: int,
               box: NDArray, rects_a: NDArray, rects_b: NDArray, mesh_tol: float,
               candidates: str, times: dict) -> OverlapBox:
    """Levels 3-5 (before correction) under one overlap box; seconds added to ``times``."""
    clock = time.perf_counter()
    surface_a = patches_a.surfaces[patches_a.face[pa]]
    surface_b = patches_b.surfaces[patches_b.face[pb]]
    mesh_a = tessellate(surface_a, mesh_tol, rects_a, keep_boxes=box[None], keep_pad=mesh_tol).mesh
    mesh_b = tessellate(surface_b, mesh_tol, rects_b, keep_boxes=box[None], keep_pad=mesh_tol).mesh
    boxes_b = triangle_boxes(mesh_b.vertices, mesh_b.triangles)
    clock = _lap(times, "tessellation", clock)
    if candidates == "sweep":
        pairs = sweep_pairs(mesh_a.vertices, mesh_a.triangles, boxes_b)
    else:
        pairs = candidate_pairs(triangle_boxes(mesh_a.vertices, mesh_a.triangles), boxes_b)
    clock = _lap(times, "candidates", clock)
    hits = intersect_triangles(mesh_a.vertices[mesh_a.triangles[pairs[:, 0]]],
                               mesh_b.vertices[mesh_b.triangles[pairs[:, 1]]])
    tri_a, tri_b = pairs[hits.index, 0], pairs[hits.index, 1]
    result = OverlapBox(pa, pb, box, rects_a, rects_b, mesh_a, mesh_b, pairs, hits.segments,
                        _barycentric_uv(mesh_a, tri_a, hits.bary_a),
                        _barycentric_uv(mesh_b, tri_b, hits.bary_b), link_segments(hits.segments))
    _lap(times, "segments", clock)
    return result


def _lap(times: dict, stage: str, since: float) -> float:
    now = time.perf_counter()
    times[stage] = times.get(stage, 0.0) + now - since
    return now


# ------------------------------------------------------------------ level 5
@dataclass(frozen=True)
class _Piece:
    """A chain (or a run of one) of one box, its points corrected."""

    points: NDArray
    uv_a: NDArray
    uv_b: NDArray
    gap: NDArray
    box: int
    face_a: int
    face_b: int
    reach: float


def _chain_points(o: OverlapBox, chain: NDArray, closed: bool) -> tuple[NDArray, NDArray, NDArray]:
    ends = o.segments[chain]
    take = (slice(None), 0)
    points = ends[take]
    uv_a, uv_b = o.uv_a[chain][take], o.uv_b[chain][take]
    if not closed:                                   # the last segment's end too
        points = np.vstack([points, ends[-1, 1]])
        uv_a = np.vstack([uv_a, o.uv_a[chain[-1], 1]])
        uv_b = np.vstack([uv_b, o.uv_b[chain[-1], 1]])
    return points, uv_a, uv_b


def _longest_edge(mesh: TriangleMesh) -> float:
    if mesh.triangles.shape[0] == 0:
        return 0.0
    c = mesh.vertices[mesh.triangles]
    return float(np.max(np.linalg.norm(c - np.roll(c, 1, axis=1), axis=2)))


def _pieces(patches_a: BoundaryPatches, patches_b: BoundaryPatches, boxes: list[OverlapBox],
            tol: float) -> list[tuple[_Piece, bool]]:
    """Every chain of every box, its points corrected onto both faces, grouped per face
    pair so each face pair is corrected in one vectorized call."""
    raw = []
    for k, o in enumerate(boxes):
        reach = JOIN_REACH * max(_longest_edge(o.mesh_a), _longest_edge(o.mesh_b))
        fa, fb = int(patches_a.face[o.patch_a]), int(patches_b.face[o.patch_b])
        for chain, closed in zip(o.chains.chains, o.chains.closed):
            points, uv_a, uv_b = _chain_points(o, chain, bool(closed))
            raw.append((_Piece(points, uv_a, uv_b, np.zeros(len(points)), k, fa, fb, reach),
                        bool(closed)))
    groups: dict = {}
    for i, (piece, _) in enumerate(raw):
        groups.setdefault((piece.face_a, piece.face_b), []).append(i)
    out = []
    for (fa, fb), members in groups.items():
        sizes = [len(raw[i][0].points) for i in members]
        fixed = correct_points(patches_a.surfaces[fa], patches_b.surfaces[fb],
                               np.vstack([raw[i][0].points for i in members]),
                               np.vstack([raw[i][0].uv_a for i in members]),
                               np.vstack([raw[i][0].uv_b for i in members]), tol=tol)
        for i, part in zip(members, np.split(np.arange(sum(sizes)), np.cumsum(sizes)[:-1])):
            piece, closed = raw[i]
            kept = fixed.converged[part]
            if kept.all():
                out.append((replace(piece, points=fixed.points[part], uv_a=fixed.uv_a[part],
                                    uv_b=fixed.uv_b[part], gap=fixed.gap[part]), closed))
                continue
            # points that do not converge lie off a face (the curve leaves it there): the
            # chain is cut into its runs of converged points
            if closed:                                   # start the runs after a dropped point
                part = np.roll(part, -int(np.flatnonzero(~kept)[0]))
                kept = fixed.converged[part]
            edges = np.diff(np.concatenate([[0], kept.astype(np.int8), [0]]))
            for lo, hi in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
                if hi - lo >= 2:
                    run = part[lo:hi]
                    out.append((replace(piece, points=fixed.points[run], uv_a=fixed.uv_a[run],
                                        uv_b=fixed.uv_b[run], gap=fixed.gap[run]), False))
    return out


def _as_loop(parts: list[tuple[_Piece, bool]], closed: bool, tol: float) -> Loop:
    """Concatenate pieces (each maybe reversed); points nearer than ``tol`` to the
    previous one are dropped (the shared end of two joined pieces)."""
    cols = {k: [] for k in ("points", "uv_a", "uv_b", "gap", "face_a", "face_b", "box")}
    for piece, reverse in parts:
        order = slice(None, None, -1) if reverse else slice(None)
        n = len(piece.points)
        cols["points"].append(piece.points[order])
        cols["uv_a"].append(piece.uv_a[order])
        cols["uv_b"].append(piece.uv_b[order])
        cols["gap"].append(piece.gap[order])
        cols["face_a"].append(np.full(n, piece.face_a))
        cols["face_b"].append(np.full(n, piece.face_b))
        cols["box"].append(np.full(n, piece.box))
    data = {k: np.concatenate(v) for k, v in cols.items()}
    step = np.linalg.norm(np.diff(data["points"], axis=0), axis=1)
    keep = np.concatenate([[True], step > tol])
    if closed and keep.sum() > 1 and np.linalg.norm(data["points"][0] - data["points"][keep][-1]) <= tol:
        keep[np.flatnonzero(keep)[-1]] = False
    data = {k: v[keep] for k, v in data.items()}
    return Loop(data["points"], data["face_a"], data["face_b"], data["uv_a"], data["uv_b"],
                data["box"], data["gap"], bool(closed))


def _nearest_other_end(ends: NDArray, short: NDArray) -> tuple[NDArray, NDArray]:
    """For every end ``(2n, 3)`` (ends ``2i``, ``2i + 1`` of piece ``i``) the nearest other
    end and its distance, by a kd-tree; a ``short`` piece's ends may not pair with each
    other (a piece too short to close on itself). ``-1`` where there is none."""
    from scipy.spatial import cKDTree
    m = ends.shape[0]
    k = min(m, 3)                           # itself, maybe its own other end, the next
    distance, index = cKDTree(ends).query(ends, k=k)
    distance, index = distance.reshape(m, k), index.reshape(m, k)
    me = np.arange(m)[:, None]
    banned = (index == me) | ((index // 2 == me // 2) & short[me // 2])
    distance = np.where(banned, np.inf, distance)
    pick = np.argmin(distance, axis=1)
    best = distance[np.arange(m), pick]
    return np.where(np.isfinite(best), index[np.arange(m), pick], -1), best


def _join(pieces: list[tuple[_Piece, bool]], tol: float) -> list[Loop]:
    """Join the hanging ends of open pieces (mutually nearest within reach) into loops."""
    loops = [_as_loop([(p, False)], True, tol) for p, closed in pieces if closed]
    open_ = [p for p, closed in pieces if not closed]
    if not open_:
        return loops
    ends = np.array([[p.points[0], p.points[-1]] for p in open_]).reshape(-1, 3)   # end 2i, 2i+1
    reach = np.repeat([p.reach for p in open_], 2)
    nearest, distance = _nearest_other_end(ends, np.array([len(p.points) < 4 for p in open_]))
    mate = np.full(ends.shape[0], -1)
    for e in range(ends.shape[0]):
        f = nearest[e]
        if f >= 0 and nearest[f] == e and distance[e] <= max(reach[e], reach[f]):
            mate[e] = f
    used = np.zeros(len(open_), dtype=bool)
    order = list(np.flatnonzero(mate[0::2] < 0)) + list(np.flatnonzero(mate[1::2] < 0)) \
        + list(range(len(open_)))
    for start in order:                       # open curves from a hanging end first
        if used[start]:
            continue
        reverse = mate[2 * start] >= 0 and mate[2 * start + 1] < 0
        parts, k, closed = [], start, False
        while True:
            used[k] = True
            parts.append((open_[k], reverse))
            out_end = 2 * k + (0 if reverse else 1)
            nxt = mate[out_end]
            if nxt < 0:
                break
            k2 = nxt // 2
            if k2 == start and used[k2]:
                closed = True
                break
            if used[k2]:
                break
            reverse = bool(nxt % 2 == 1)     # entering at its end: walk it backwards
            k = k2
        loops.append(_as_loop(parts, closed, tol))
    return loops


def build_hierarchy(a: BoundaryPatches, b: BoundaryPatches, *, tol: float, mesh_tol: float,
                    candidates: str = "sweep") -> Hierarchy:
    """Levels 2-5 of two solids' level 1 (the module doc).

    Parameters
    ----------
    a, b : BoundaryPatches
    tol : float > 0
        Model units: the curves' points lie within ``tol / 2`` of both boundaries.
    mesh_tol : float >= tol
        Chord tolerance of the local triangulations.
    candidates : {"sweep", "descent"}

    Returns
    -------
    Hierarchy
    """
    if candidates not in ("sweep", "descent"):
        raise ValueError(f"candidates must be 'sweep' or 'descent', got {candidates!r}")
    times = {}
    started = time.perf_counter()
    overlap = overlap_boxes(a.boxes, b.boxes, pad=2 * mesh_tol)      # widened by mesh_tol each
    pairs, boxes = overlap.pairs, overlap.boxes
    subs_a, subs_b = _split(a.rects[pairs[:, 0]], SUBDIVISION), _split(b.rects[pairs[:, 1]], SUBDIVISION)
    keep_a = _kept_subpatches(a, pairs[:, 0], subs_a, boxes, mesh_tol)
    keep_b = _kept_subpatches(b, pairs[:, 1], subs_b, boxes, mesh_tol)
    live = np.flatnonzero(keep_a.any(axis=1) & keep_b.any(axis=1))
    times["overlap_boxes"] = time.perf_counter() - started
    under = [_box_under(a, b, int(pairs[k, 0]), int(pairs[k, 1]), boxes[k], subs_a[k][keep_a[k]],
                        subs_b[k][keep_b[k]], mesh_tol, candidates, times) for k in live]
    started = time.perf_counter()
    pieces = _pieces(a, b, under, tol)
    times["correction"] = time.perf_counter() - started
    started = time.perf_counter()
    loops = _join(pieces, tol)
    times["merge"] = time.perf_counter() - started
    return Hierarchy(a, b, int(pairs.shape[0]), tuple(under), tuple(loops), float(tol),
                     float(mesh_tol), candidates, times)
