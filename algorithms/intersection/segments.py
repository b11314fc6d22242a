"""From two operands to the soup of intersection segments (000 §29.4.1 steps 1-4).

:func:`mesh_segments` runs the first half of the SSI pipeline:

1. overlap boxes of the Bézier patch boxes (004 §4.2): the span hull boxes of
   both surfaces descended as grid trees (:func:`.culling.surface_tree`), then
   the exact Bézier boxes of the candidate patches only, so the work follows the
   intersection and not the pole count;
2. adaptive tessellation of only the patches that take part (004 §4.3,
   :func:`.tessellation.tessellate`), pruned during refinement so the work
   follows the intersection: a's sub-rectangles must come near a coarse
   tessellation of b (itself pruned by the overlap boxes), b's near a triangle
   of a;
3. box trees over both triangulations and their batched traversal, giving the
   candidate triangle pairs (000 §29.4.4, :func:`.culling.candidate_pairs`);
4. triangle-triangle intersection of the candidates (000 §29.4.3,
   :func:`.triangles.intersect_triangles`), with the (u, v) of every segment end
   on both surfaces by the barycentric map.

The result, a :class:`SegmentSoup`, is unordered: sorting the segments into
curves (§29.4.5) and refining them onto the exact surfaces (§29.4.6, 004 §6)
are later stages.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError, InvalidToleranceError
from ..surface import NurbsSurface
from .culling import (
    BoxTree,
    PatchOverlap,
    build_tree,
    candidate_pairs,
    exact_patch_boxes,
    patch_rectangles,
    surface_tree,
    tree_pairs,
)
from .mesh import TriangleMesh
from .tessellation import tessellate
from .triangles import TriangleHits, intersect_triangles

__all__ = ["SegmentSoup", "SoupStats", "mesh_segments"]

Operand = NurbsSurface | TriangleMesh

#: tolerance factor of the coarse tessellation of b that guides a's refinement
_COARSE = 32.0


@dataclass(frozen=True)
class SoupStats:
    """Work counts of one :func:`mesh_segments` run.

    Attributes
    ----------
    patches_a, patches_b : int
        Bézier patches of each surface (0 for a mesh operand).
    overlap_pairs : int
        Overlapping patch-box pairs (004 §4.2; for a mesh side each triangle is a "patch").
    tessellated_a, tessellated_b : int
        Patches tessellated (those in some overlap pair).
    candidate_pairs : int
        Triangle pairs whose boxes overlap (the tree traversal's output).
    """

    patches_a: int
    patches_b: int
    overlap_pairs: int
    tessellated_a: int
    tessellated_b: int
    candidate_pairs: int


@dataclass(frozen=True, eq=False)
class SegmentSoup:
    """Unordered intersection segments of two triangulated operands.

    Segment ``i`` is the intersection of triangle ``tri_a[i]`` of ``mesh_a`` with
    triangle ``tri_b[i]`` of ``mesh_b``. Contract for the later stages:

    Attributes
    ----------
    points : (k, 2, 3) float
        End points of each segment, oriented along ``n_a x n_b`` (the right-hand
        normals of the two triangles; for tessellated surfaces these follow
        ``S_u x S_v``), so the segments of one curve run the same way. An end
        produced by the same mesh edge and the same other triangle is bitwise the
        same point in every segment that has it (see :meth:`end_keys`).
    uv_a, uv_b : (k, 2, 2) float or None
        ``(u, v)`` of each end on surface a (b), interpolated with the
        barycentric coordinates in the triangle from its vertices' exact
        parameters (000 §29.4.2's uv connectivity); ``None`` for a side given as a
        plain mesh without ``uv``.
    tri_a, tri_b : (k,) int
        Triangle of each mesh the segment lies in.
    bary_a, bary_b : (k, 2, 3) float
        Barycentric coordinates of each end in ``tri_a`` (``tri_b``).
    end_source : (k, 2) int
        0: the end is where an edge of ``tri_a`` crosses ``tri_b``; 1: an edge of
        ``tri_b`` crossing ``tri_a``.
    end_edge : (k, 2) int
        Local edge id (0: corners 0-1, 1: 1-2, 2: 2-0) of that triangle.
    touching_points : (t, 3) float
        Pairs of triangles that meet in a single point only (tangential contact
        or a curve through a mesh vertex), minus points that are also segment
        ends. Hints only: 000 drops them.
    touching_pairs : (t, 2) int
        ``(triangle of a, triangle of b)`` of each touching point.
    touching_uv_a, touching_uv_b : (t, 2) float or None
    coplanar_pairs : (c, 2) int
        ``(triangle of a, triangle of b)`` lying in one plane (to rounding) and
        overlapping there; no segment is made for them.
    mesh_a, mesh_b : TriangleMesh
        The triangulations intersected (for a surface: of the patches in overlap
        boxes only, with ``uv``; for a mesh operand: that mesh).
    tol : float
        The tessellation tolerance (model units).
    stats : SoupStats
    """

    points: NDArray
    uv_a: NDArray | None
    uv_b: NDArray | None
    tri_a: NDArray
    tri_b: NDArray
    bary_a: NDArray
    bary_b: NDArray
    end_source: NDArray
    end_edge: NDArray
    touching_points: NDArray
    touching_pairs: NDArray
    touching_uv_a: NDArray | None
    touching_uv_b: NDArray | None
    coplanar_pairs: NDArray
    mesh_a: TriangleMesh
    mesh_b: TriangleMesh
    tol: float
    stats: SoupStats = field(repr=False)

    @property
    def n_segments(self) -> int:
        return self.points.shape[0]

    def end_keys(self) -> NDArray:
        """Combinatorial identity of every segment end: (k, 2, 4) int.

        ``(side, v0, v1, other)``: the end is where edge ``(v0, v1)`` (``v0 <
        v1``, vertex ids of mesh a for side 0, of mesh b for side 1) crosses
        triangle ``other`` of the other mesh. Ends with equal keys are bitwise
        equal points, so segments can be chained without a distance test
        (except through mesh vertices, where different edges give one point).
        """
        other = np.where(self.end_source == 0, self.tri_b[:, None], self.tri_a[:, None])
        corners = np.where((self.end_source == 0)[..., None],
                           self.mesh_a.triangles[self.tri_a][:, None],
                           self.mesh_b.triangles[self.tri_b][:, None])         # (k, 2, 3)
        e = self.end_edge
        v0 = np.take_along_axis(corners, e[..., None], axis=2)[..., 0]
        v1 = np.take_along_axis(corners, ((e + 1) % 3)[..., None], axis=2)[..., 0]
        return np.stack([self.end_source, np.minimum(v0, v1), np.maximum(v0, v1), other],
                        axis=-1)


# ----------------------------------------------------------------- driver
def _check_operand(operand: Operand) -> None:
    if isinstance(operand, NurbsSurface):
        if operand.dimension != 3:
            raise InvalidGeometryError(
                f"intersection needs surfaces in 3D, got dimension {operand.dimension}")
        return
    if not isinstance(operand, TriangleMesh):
        raise InvalidGeometryError(
            f"an operand must be a NurbsSurface or a TriangleMesh, got {type(operand).__name__}")


def _cull_tree(operand: Operand, pad: float) -> BoxTree:
    """Tree over a surface's span hull boxes (a grid, no sort) or a mesh's triangle boxes."""
    if isinstance(operand, NurbsSurface):
        return surface_tree(operand, pad)
    return build_tree(operand.triangle_boxes())


def _exact_boxes(operand: Operand, items: NDArray, pad: float) -> NDArray:
    """Bézier boxes of surface patches (padded), or triangle boxes, of ``items``."""
    if isinstance(operand, NurbsSurface):
        return exact_patch_boxes(operand, items) + np.array([-pad, pad])[:, None]
    return operand.triangle_boxes()[items]


def _overlap(a: Operand, b: Operand, pad_a: float, pad_b: float) -> PatchOverlap:
    """Overlapping patch (triangle) pairs and their overlap boxes (004 §4.2).

    The span hull boxes of each surface (boxes of the poles of every knot span)
    are descended as grid trees against each other, so only the spans near the
    other operand are ever looked at; the candidate pairs are then tested with
    their exact Bézier patch boxes, extracted for those patches only. Each box is
    widened by its side's pad.
    """
    pairs = tree_pairs(_cull_tree(a, pad_a), _cull_tree(b, pad_b))
    patches_a, inv_a = np.unique(pairs[:, 0], return_inverse=True)
    patches_b, inv_b = np.unique(pairs[:, 1], return_inverse=True)
    box_a = _exact_boxes(a, patches_a, pad_a)[inv_a.ravel()]
    box_b = _exact_boxes(b, patches_b, pad_b)[inv_b.ravel()]
    lo, hi = np.maximum(box_a[:, 0], box_b[:, 0]), np.minimum(box_a[:, 1], box_b[:, 1])
    keep = np.all(lo <= hi, axis=1)
    pairs = pairs[keep]
    return PatchOverlap(pairs, np.stack([lo[keep], hi[keep]], axis=1), np.unique(pairs[:, 0]),
                        np.unique(pairs[:, 1]))


def _rects(operand: Operand) -> tuple[NDArray | None, int, float]:
    """Parameter rectangles of a surface's patches, the patch count, and the pad."""
    if isinstance(operand, NurbsSurface):
        rects = patch_rectangles(operand)
        return rects, rects.shape[0], 0.0
    return None, 0, 0.0


def _tessellation(operand: Operand, rects: NDArray | None, patches: NDArray, keep: NDArray,
                  tol: float, pad: float, max_depth: int, keep_patch: NDArray | None = None
                  ) -> tuple[TriangleMesh, NDArray | None]:
    """Tessellation of the patches ``patches`` pruned by ``keep`` boxes (for each
    patch only the keep boxes whose ``keep_patch`` it is, when given), and the patch
    of every triangle (None for a mesh operand)."""
    if isinstance(operand, TriangleMesh):
        return operand, None
    region = None if keep_patch is None else np.searchsorted(patches, keep_patch)
    tess = tessellate(operand, tol, rects[patches], max_depth=max_depth, keep_boxes=keep,
                      keep_pad=pad, keep_region=region)
    return tess.mesh, patches[tess.leaf_region[tess.mesh.patch]]


def _partner_boxes(mesh: TriangleMesh, tri_patch: NDArray | None, own: NDArray,
                   other: NDArray) -> tuple[NDArray, NDArray | None]:
    """Keep boxes for tessellating one side near the other side's triangles.

    With the other side's triangle patches known, each overlap pair ``(own[i],
    other[i])`` contributes the boxes of the triangles of ``other[i]``, owned by
    ``own[i]``: a patch is then tested only against triangles of the patches whose
    boxes overlap its own (any intersection point lies in such a pair), instead of a
    tree over all triangles, whose pairs explode with the wide padding of a coarse
    guide. Returns ``(boxes, owner patch)``; owner None without patches (a mesh).
    """
    boxes = mesh.triangle_boxes()
    if tri_patch is None:
        return boxes, None
    order = np.argsort(tri_patch, kind="stable")
    sorted_patch = tri_patch[order]
    lo = np.searchsorted(sorted_patch, other, side="left")
    counts = np.searchsorted(sorted_patch, other, side="right") - lo
    pair = np.repeat(np.arange(other.size), counts)
    tri = order[np.repeat(lo - np.cumsum(counts) + counts, counts) + np.arange(pair.size)]
    return boxes[tri], own[pair]


def _guide(b: Operand, rects_b: NDArray | None, overlap, tol: float, max_depth: int
           ) -> tuple[TriangleMesh, NDArray | None, float]:
    """A mesh near operand b to prune a's refinement with, its triangles' patches, and
    the padding of its boxes.

    A mesh operand is itself; a surface gives a coarse tessellation (tolerance
    ``_COARSE tol``, itself pruned by the overlap boxes) whose triangle boxes,
    widened by twice the coarse tolerance, hold the surface b near the overlap.
    """
    if isinstance(b, TriangleMesh):
        return b, None, 0.0
    coarse = _COARSE * tol
    # an overlap box lies in its b patch's box: each patch is pruned by its own boxes
    mesh, tri_patch = _tessellation(b, rects_b, overlap.patches_b, overlap.boxes, coarse,
                                    2.0 * coarse, max_depth, keep_patch=overlap.pairs[:, 1])
    return mesh, tri_patch, 2.0 * coarse


def _interpolate_uv(mesh: TriangleMesh, tri: NDArray, bary: NDArray) -> NDArray | None:
    """(u, v) at barycentric coordinates: (..., 2) float, or None without uv."""
    if mesh.uv is None:
        return None
    corners = mesh.uv[mesh.triangles[tri]]                 # (k, 3, 2)
    if bary.ndim == 3:
        return np.einsum("kec,kcd->ked", bary, corners)
    return np.einsum("kc,kcd->kd", bary, corners)


def _not_segment_ends(touch: NDArray, ends: NDArray) -> NDArray:
    """Mask of touching points (t, 3) that are not bitwise segment ends (e, 3)."""
    if touch.shape[0] == 0 or ends.shape[0] == 0:
        return np.ones(touch.shape[0], bool)
    return ~np.isin(_row_bytes(touch), _row_bytes(ends))


def _row_bytes(points: NDArray) -> NDArray:
    """``(n,)`` one opaque item per row of ``points (n, 3) float``, equal where the rows are
    bitwise equal (``-0.0`` made ``0.0`` first): a 1-D membership test instead of a
    row-wise unique (5x faster on a thousand segment ends)."""
    rows = np.ascontiguousarray(points, dtype=np.float64) + 0.0
    return rows.view(np.dtype((np.void, 8 * rows.shape[1]))).ravel()


def _soup(hits: TriangleHits, pairs: NDArray, mesh_a: TriangleMesh, mesh_b: TriangleMesh,
          tol: float, stats: SoupStats) -> SegmentSoup:
    tri_a, tri_b = pairs[hits.index, 0], pairs[hits.index, 1]
    keep = _not_segment_ends(hits.touch_points, hits.segments.reshape(-1, 3))
    touch_pairs = pairs[hits.touch_index[keep]]
    touch_ba, touch_bb = hits.touch_bary_a[keep], hits.touch_bary_b[keep]
    return SegmentSoup(
        points=hits.segments, tri_a=tri_a, tri_b=tri_b,
        uv_a=_interpolate_uv(mesh_a, tri_a, hits.bary_a),
        uv_b=_interpolate_uv(mesh_b, tri_b, hits.bary_b),
        bary_a=hits.bary_a, bary_b=hits.bary_b, end_source=hits.source, end_edge=hits.edge,
        touching_points=hits.touch_points[keep], touching_pairs=touch_pairs,
        touching_uv_a=_interpolate_uv(mesh_a, touch_pairs[:, 0], touch_ba),
        touching_uv_b=_interpolate_uv(mesh_b, touch_pairs[:, 1], touch_bb),
        coplanar_pairs=pairs[hits.coplanar_index], mesh_a=mesh_a, mesh_b=mesh_b,
        tol=tol, stats=stats)


def mesh_segments(a: Operand, b: Operand, *, tol: float, max_depth: int = 24) -> SegmentSoup:
    """Intersection segments of two surfaces and/or triangle meshes (000 §29.4.1, steps 1-4).

    Parameters
    ----------
    a, b : NurbsSurface (dimension 3) or TriangleMesh
    tol : float > 0
        Chord tolerance of the tessellations, model units
        (:func:`.tessellation.tessellate`); also widens the patch boxes in the
        overlap test by ``2 tol`` per surface, so no triangle pair is lost.
        Surface a is refined only where its sub-patch boxes come near a coarse
        (``32 tol``) tessellation of b, surface b only where they come within
        ``2 tol`` of a box of a's triangles, so the work follows the intersection.
    max_depth : int
        Refinement levels at most.

    Returns
    -------
    SegmentSoup
        Surfaces whose patch boxes do not overlap give an empty soup without
        any tessellation.

    Raises
    ------
    InvalidToleranceError
        ``tol`` not finite and positive.
    InvalidGeometryError
        An operand of another type, or a surface not in 3D.
    """
    if not (np.isfinite(tol) and tol > 0):
        raise InvalidToleranceError(f"tol must be finite and > 0, got {tol!r}")
    tol = float(tol)
    _check_operand(a)
    _check_operand(b)
    rects_a, n_a, _ = _rects(a)
    rects_b, n_b, _ = _rects(b)
    # each side's boxes widened by its own pad (2 tol for a surface: its triangles
    # stray that little from it), so the overlap boxes hold every close triangle pair
    pad_a = 2.0 * tol if isinstance(a, NurbsSurface) else 0.0
    pad_b = 2.0 * tol if isinstance(b, NurbsSurface) else 0.0
    overlap = _overlap(a, b, pad_a, pad_b)
    own_a, own_b = overlap.pairs[:, 0], overlap.pairs[:, 1]
    guide, guide_patch, guide_pad = _guide(b, rects_b, overlap, tol, max_depth)
    keep, owner = _partner_boxes(guide, guide_patch, own_a, own_b)
    if owner is not None and not isinstance(a, NurbsSurface):
        keep, owner = guide.triangle_boxes(), None
    mesh_a, patch_a = _tessellation(a, rects_a, overlap.patches_a, keep, tol,
                                    pad_a + guide_pad, max_depth, keep_patch=owner)
    # b is refined only near a's triangles
    keep, owner = _partner_boxes(mesh_a, patch_a, own_b, own_a)
    if owner is not None and not isinstance(b, NurbsSurface):
        keep, owner = mesh_a.triangle_boxes(), None
    mesh_b, _ = _tessellation(b, rects_b, overlap.patches_b, keep, tol, pad_b, max_depth,
                              keep_patch=owner)
    pairs = candidate_pairs(mesh_a.triangle_boxes(), mesh_b.triangle_boxes())
    hits = intersect_triangles(mesh_a.triangle_points()[pairs[:, 0]],
                               mesh_b.triangle_points()[pairs[:, 1]])
    stats = SoupStats(n_a, n_b, overlap.pairs.shape[0],
                      overlap.patches_a.size if rects_a is not None else 0,
                      overlap.patches_b.size if rects_b is not None else 0,
                      pairs.shape[0])
    return _soup(hits, pairs, mesh_a, mesh_b, tol, stats)
