"""Culling for surface-surface intersection: overlap boxes and box trees.

* Overlap boxes (004 §4.2): the Bézier patches of both surfaces are boxed
  (control-net boxes, which contain rational patches with positive weights);
  every pair of overlapping patch boxes gives an overlap box, their
  intersection. Only the patches in some pair are tessellated (004 §4.3).
* Box trees (000 §29.4.4, 004 §4.4): a binary tree over triangle boxes with
  one item per leaf and at most ``2N - 1`` nodes, built by median splits on the
  longest axis of the item centroids. It is stored as flat arrays (child
  indices, boxes), built level by level with one sort per level.
* Tree against tree (000 §29.4.4, steps 1-4): the frontier of overlapping node
  pairs is processed level by level as arrays: each step tests all frontier
  pairs at once and replaces each overlapping pair by the pairs of the children
  of its larger node. The result is every pair of overlapping leaf boxes,
  exactly what testing all pairs would give, in about ``M log N`` work.

Boxes are closed: touching boxes overlap. ``pad`` widens the test (boxes
overlap when their gap is at most ``pad`` on every axis).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError
from ..jit import compiled
from ..surface import NurbsSurface
from . import tessellation_kernels, vectors

__all__ = [
    "BoxTree",
    "PatchOverlap",
    "RegionPatches",
    "build_tree",
    "candidate_pairs",
    "exact_patch_boxes",
    "grid_tree",
    "overlap_boxes",
    "overlap_patches",
    "patch_rectangles",
    "region_patches",
    "span_hull_boxes",
    "span_patches",
    "subpatch_boxes",
    "surface_patch_boxes",
    "surface_tree",
    "tree_pairs",
]


@dataclass(frozen=True, eq=False)
class BoxTree:
    """A binary bounding-box tree in flat arrays; node 0 is the root.

    Attributes
    ----------
    lo, hi : (N, 3) float
        Box of every node (of its items' boxes).
    left, right : (N,) int
        Children of internal nodes, -1 at leaves.
    item : (N,) int
        The item (input box index) of a leaf, -1 at internal nodes.
    size : (N,) int
        Number of items under each node.
    depth : int
        Number of levels.
    """

    lo: NDArray
    hi: NDArray
    left: NDArray
    right: NDArray
    item: NDArray
    size: NDArray
    depth: int

    @property
    def n_nodes(self) -> int:
        return self.lo.shape[0]


def _check_boxes(boxes: ArrayLike, name: str) -> NDArray:
    b = np.asarray(boxes, dtype=float)
    if b.size == 0:
        return np.zeros((0, 2, 3))
    if b.ndim != 3 or b.shape[1:] != (2, 3):
        raise InvalidGeometryError(f"{name} must have shape (m, 2, 3), got {b.shape}")
    if not np.all(np.isfinite(b)) or np.any(b[:, 0] > b[:, 1]):
        raise InvalidGeometryError(f"{name} must be finite with min <= max")
    return b


def build_tree(boxes: ArrayLike) -> BoxTree:
    """Median-split tree over boxes (000 §29.4.4), built level by level.

    Parameters
    ----------
    boxes : (m, 2, 3) float

    Returns
    -------
    BoxTree
        ``2m - 1`` nodes (none for ``m = 0``); each leaf holds one box.
    """
    boxes = _check_boxes(boxes, "boxes")
    m = boxes.shape[0]
    n = max(2 * m - 1, 0)
    left = np.full(n, -1, np.int64)
    right = np.full(n, -1, np.int64)
    item = np.full(n, -1, np.int64)
    start = np.zeros(n, np.int64)
    size = np.zeros(n, np.int64)
    if m == 0:
        return BoxTree(np.zeros((0, 3)), np.zeros((0, 3)), left, right, item, size, 0)
    centroid = boxes.mean(axis=1)
    order = np.arange(m)
    size[0], levels, frontier, next_id = m, [np.array([0])], np.array([0]), 1
    while True:
        split = frontier[size[frontier] > 1]
        if split.size == 0:
            break
        order = _sort_segments(order, centroid, start[split], size[split])
        half = size[split] // 2
        kids = next_id + np.arange(2 * split.size)
        left[split], right[split] = kids[0::2], kids[1::2]
        start[kids[0::2]], size[kids[0::2]] = start[split], half
        start[kids[1::2]], size[kids[1::2]] = start[split] + half, size[split] - half
        next_id += kids.size
        frontier = kids
        levels.append(kids)
    leaves = left < 0
    item[leaves] = order[start[leaves]]
    lo, hi = np.zeros((n, 3)), np.zeros((n, 3))
    lo[leaves], hi[leaves] = boxes[item[leaves], 0], boxes[item[leaves], 1]
    for level in reversed(levels):                       # boxes bottom-up
        inner = level[left[level] >= 0]
        lo[inner] = np.minimum(lo[left[inner]], lo[right[inner]])
        hi[inner] = np.maximum(hi[left[inner]], hi[right[inner]])
    return BoxTree(lo, hi, left, right, item, size, len(levels))


def _sort_segments(order: NDArray, centroid: NDArray, starts: NDArray, counts: NDArray
                   ) -> NDArray:
    """Sort each segment ``order[s:s+c]`` by the centroid coordinate of its longest axis."""
    seg = np.repeat(np.arange(starts.size), counts)
    pos = starts[seg] + np.arange(seg.size) - np.repeat(np.cumsum(counts) - counts, counts)
    c = centroid[order[pos]]                                        # (k, 3)
    first = np.cumsum(counts) - counts
    extent = np.maximum.reduceat(c, first, axis=0) - np.minimum.reduceat(c, first, axis=0)
    axis = np.argmax(extent, axis=1)
    key = c[np.arange(seg.size), axis[seg]]
    perm = np.lexsort((key, seg))                                   # stable: deterministic
    out = order.copy()
    out[pos] = order[pos][perm]
    return out


def _overlap(lo_a: NDArray, hi_a: NDArray, lo_b: NDArray, hi_b: NDArray, pad: float
             ) -> NDArray:
    return np.all((lo_a <= hi_b + pad) & (lo_b <= hi_a + pad), axis=-1)


def tree_pairs(tree_a: BoxTree, tree_b: BoxTree, *, pad: float = 0.0) -> NDArray:
    """All pairs of overlapping leaf boxes of two trees, by a batched simultaneous descent.

    Parameters
    ----------
    tree_a, tree_b : BoxTree
    pad : float >= 0
        Boxes within ``pad`` of each other on every axis count as overlapping.

    Returns
    -------
    (k, 2) int
        ``(item of a, item of b)``, sorted lexicographically.
    """
    if tree_a.n_nodes == 0 or tree_b.n_nodes == 0:
        return np.zeros((0, 2), np.int64)
    fa, fb = np.zeros(1, np.int64), np.zeros(1, np.int64)
    found = []
    while fa.size:
        keep = _overlap(tree_a.lo[fa], tree_a.hi[fa], tree_b.lo[fb], tree_b.hi[fb], pad)
        fa, fb = fa[keep], fb[keep]
        leaf_a, leaf_b = tree_a.left[fa] < 0, tree_b.left[fb] < 0
        both = leaf_a & leaf_b
        found.append(np.stack([tree_a.item[fa[both]], tree_b.item[fb[both]]], axis=1))
        down_a = ~leaf_a & (leaf_b | (tree_a.size[fa] >= tree_b.size[fb]))
        down_b = ~both & ~down_a
        fa = np.concatenate([tree_a.left[fa[down_a]], tree_a.right[fa[down_a]],
                             fa[down_b], fa[down_b]])
        fb = np.concatenate([fb[down_a], fb[down_a],
                             tree_b.left[fb[down_b]], tree_b.right[fb[down_b]]])
    pairs = np.concatenate(found)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def candidate_pairs(boxes_a: ArrayLike, boxes_b: ArrayLike, *, pad: float = 0.0) -> NDArray:
    """Pairs of overlapping boxes ``(i, j)``, ``boxes_a[i]`` against ``boxes_b[j]``.

    Builds a :class:`BoxTree` on each side and runs :func:`tree_pairs`.

    Parameters
    ----------
    boxes_a : (m, 2, 3) float
    boxes_b : (n, 2, 3) float
    pad : float >= 0

    Returns
    -------
    (k, 2) int, sorted lexicographically.
    """
    if not (np.isfinite(pad) and pad >= 0):
        raise InvalidGeometryError(f"pad must be finite and >= 0, got {pad!r}")
    a = _check_boxes(boxes_a, "boxes_a")
    b = _check_boxes(boxes_b, "boxes_b")
    if compiled(8 * (a.shape[0] + b.shape[0])):  # the same pairs: a tree on b, a search per box
        return tessellation_kernels.query_pairs(build_tree(b), a, float(pad))
    return tree_pairs(build_tree(a), build_tree(b), pad=float(pad))


# ------------------------------------------------------------ overlap boxes
@dataclass(frozen=True, eq=False)
class PatchOverlap:
    """Overlapping patch boxes of two operands (004 §4.2).

    Attributes
    ----------
    pairs : (k, 2) int
        ``(patch of a, patch of b)`` whose (padded) boxes overlap.
    boxes : (k, 2, 3) float
        The overlap boxes: intersection of the two padded boxes of each pair.
    patches_a, patches_b : (ra,) int, (rb,) int
        Sorted distinct patches of each side that take part.
    rects_a, rects_b : (ra, 4) float or None, (rb, 4) float or None
        Their parameter rectangles ``[u0, u1, v0, v1]`` when the side is a
        surface (``None`` for an operand given as plain boxes).
    """

    pairs: NDArray
    boxes: NDArray
    patches_a: NDArray
    patches_b: NDArray
    rects_a: NDArray | None = None
    rects_b: NDArray | None = None


def patch_rectangles(surface: NurbsSurface) -> NDArray:
    """Parameter rectangles of the Bézier patches (knot spans) of a surface.

    Returns
    -------
    (ku * kv, 4) float
        ``[u0, u1, v0, v1]`` of patch ``(i, j)`` at flat index ``i * kv + j`` (the
        order of :func:`surfprep.algorithms.bezier.patch_bounding_boxes`).
    """
    ku, kv = surface.knots_u, surface.knots_v
    p, q = surface.degree_u, surface.degree_v
    nu, nv = surface.n_control
    su = np.flatnonzero(ku[p:nu] < ku[p + 1:nu + 1]) + p
    sv = np.flatnonzero(kv[q:nv] < kv[q + 1:nv + 1]) + q
    iu, iv = np.meshgrid(su, sv, indexing="ij")
    iu, iv = iu.ravel(), iv.ravel()
    return np.stack([ku[iu], ku[iu + 1], kv[iv], kv[iv + 1]], axis=1)


def _blossom_restrict(coeffs: NDArray, s0: NDArray, s1: NDArray) -> NDArray:
    """Bernstein coefficients of Bézier pieces restricted to local ``[s0, s1]`` (axis 1).

    Coefficient ``i`` of the restriction is the blossom ``f(s0^{p-i}, s1^i)``: one
    de Casteljau triangle per output, all rows at once.

    Parameters
    ----------
    coeffs : (k, p + 1, ...) float
    s0, s1 : (k,) float

    Returns
    -------
    (k, p + 1, ...) float
    """
    p = coeffs.shape[1] - 1
    extra = (1,) * (coeffs.ndim - 2)
    i = np.arange(p + 1)
    current = np.repeat(coeffs[:, None], p + 1, axis=1)          # (k, out, p+1, ...)
    for r in range(1, p + 1):
        x = np.where(r <= p - i, s0[:, None], s1[:, None]).reshape((-1, p + 1, 1) + extra)
        current = (1.0 - x) * current[:, :, :-1] + x * current[:, :, 1:]
    return current[:, :, 0]


def _spans(knots: NDArray, degree: int, n: int) -> NDArray:
    """Indices ``i`` of the non-empty knot spans ``[knots[i], knots[i+1])`` of the domain."""
    return np.flatnonzero(knots[degree:n] < knots[degree + 1:n + 1]) + degree


def _blossom_spans(net: NDArray, knots: NDArray, degree: int) -> NDArray:
    """Bernstein coefficients of single knot spans along axis 1, many spans at once.

    ``net (k, p + 1, ...)`` are the ``p + 1`` homogeneous poles of each span and
    ``knots (k, 2p + 2)`` the knots around it (span ``[knots[:, p], knots[:, p+1]]``);
    coefficient ``i`` is the blossom ``f(a^{p-i}, b^i)`` (the de Boor triangle of
    :func:`surfprep.algorithms.bezier.bezier_decompose_array`, per span).
    """
    p = degree
    extra = (1,) * (net.ndim - 2)
    a, b = knots[:, p], knots[:, p + 1]
    i = np.arange(p + 1)
    current = net[:, None]                                          # (k, 1, p+1, ...)
    for r in range(1, p + 1):
        x = np.where(r <= p - i, a[:, None], b[:, None])            # (k, p+1)
        local = np.arange(r, p + 1)
        lo, hi = knots[:, local], knots[:, p + 1 - r + local]        # (k, p+1-r)
        alpha = (x[:, :, None] - lo[:, None, :]) / (hi - lo)[:, None, :]
        alpha = alpha.reshape(alpha.shape + extra)
        current = (1.0 - alpha) * current[:, :, :-1] + alpha * current[:, :, 1:]
    return current[:, :, 0]


def span_patches(surface: NurbsSurface, span_u: ArrayLike, span_v: ArrayLike) -> NDArray:
    """Homogeneous Bernstein coefficients ``(k, p + 1, q + 1, d + 1)`` of the Bézier
    patches on knot spans ``(span_u[i], span_v[i])`` only (knot indices, as
    :func:`surfprep.algorithms.bezier.bezier_patches` gives for all of them)."""
    iu, iv = np.asarray(span_u, dtype=np.int64), np.asarray(span_v, dtype=np.int64)
    p, q = surface.degree_u, surface.degree_v
    pw = surface.homogeneous_points()
    rows = iu[:, None] - p + np.arange(p + 1)                        # (k, p+1)
    cols = iv[:, None] - q + np.arange(q + 1)                        # (k, q+1)
    net = pw[rows[:, :, None], cols[:, None, :]]                      # (k, p+1, q+1, d+1)
    ku = surface.knots_u[iu[:, None] - p + np.arange(2 * p + 2)]
    kv = surface.knots_v[iv[:, None] - q + np.arange(2 * q + 2)]
    if compiled(net.size):                      # the same de Boor triangles, compiled
        net = tessellation_kernels.blossom_spans(np.ascontiguousarray(net, dtype=float),
                                                 np.ascontiguousarray(ku, dtype=float), p)
        net = tessellation_kernels.blossom_spans(np.ascontiguousarray(np.swapaxes(net, 1, 2)),
                                                 np.ascontiguousarray(kv, dtype=float), q)
        return np.swapaxes(net, 1, 2)
    net = _blossom_spans(net, ku, p)
    return np.swapaxes(_blossom_spans(np.swapaxes(net, 1, 2), kv, q), 1, 2)


@dataclass(frozen=True, eq=False)
class RegionPatches:
    """The Bézier patch of every region of a tessellation, extracted once
    (:func:`region_patches`), so that the boxes of sub-rectangles at every refinement
    level need only the restriction (:meth:`boxes`).

    Attributes
    ----------
    coeffs : (r, p + 1, q + 1, d + 1) float
        Homogeneous Bernstein coefficients of the patch holding region ``i``.
    bounds : (r, 4) float
        That patch's parameter rectangle ``[u0, u1, v0, v1]``.
    """

    coeffs: NDArray
    bounds: NDArray

    def boxes(self, rects: NDArray, region: NDArray) -> NDArray:
        """Control-net boxes ``(k, 2, d)`` over ``rects (k, 4)`` inside regions ``region (k,)``
        (as :func:`subpatch_boxes` gives them)."""
        a, b, c, d = self.bounds[region].T
        s0, s1 = (rects[:, 0] - a) / (b - a), (rects[:, 1] - a) / (b - a)
        t0, t1 = (rects[:, 2] - c) / (d - c), (rects[:, 3] - c) / (d - c)
        if compiled(rects.shape[0] * self.coeffs[0].size) and self.coeffs.shape[-1] == 4:
            return tessellation_kernels.restricted_boxes(self.coeffs, region, s0, s1, t0, t1)
        coeffs = _blossom_restrict(self.coeffs[region], s0, s1)
        coeffs = _blossom_restrict(np.swapaxes(coeffs, 1, 2), t0, t1)
        cartesian = coeffs[..., :-1] / coeffs[..., -1:]
        return np.stack([vectors.corner_min(cartesian), vectors.corner_max(cartesian)], axis=1)


def _patch_spans(surface: NurbsSurface, rects: NDArray) -> tuple[NDArray, NDArray]:
    """Knot span indices ``(iu, iv)`` of the Bézier patch holding each rectangle."""
    nu, nv = surface.n_control
    su = _spans(surface.knots_u, surface.degree_u, nu)
    sv = _spans(surface.knots_v, surface.degree_v, nv)
    ku, kv = surface.knots_u, surface.knots_v
    iu = su[np.clip(np.searchsorted(ku[su + 1], rects[:, 0], side="right"), 0, su.size - 1)]
    iv = sv[np.clip(np.searchsorted(kv[sv + 1], rects[:, 2], side="right"), 0, sv.size - 1)]
    a, b, c, d = ku[iu], ku[iu + 1], kv[iv], kv[iv + 1]
    if np.any((rects[:, 0] < a) | (rects[:, 1] > b) | (rects[:, 2] < c) | (rects[:, 3] > d)):
        raise InvalidGeometryError("every rectangle must lie inside one Bézier patch")
    return iu, iv


def region_patches(surface: NurbsSurface, regions: ArrayLike) -> RegionPatches:
    """The Bézier patches holding parameter rectangles ``regions (r, 4)`` (each inside one).

    Raises
    ------
    InvalidGeometryError
        A region spanning more than one Bézier patch.
    """
    regions = np.asarray(regions, dtype=float).reshape(-1, 4)
    iu, iv = _patch_spans(surface, regions)
    ku, kv = surface.knots_u, surface.knots_v
    return RegionPatches(span_patches(surface, iu, iv),
                         np.stack([ku[iu], ku[iu + 1], kv[iv], kv[iv + 1]], axis=1))


def subpatch_boxes(surface: NurbsSurface, rects: ArrayLike) -> NDArray:
    """Control-net boxes of the surface over parameter rectangles inside Bézier patches.

    The restriction of a (rational) Bézier patch to a sub-rectangle is again one,
    whose Cartesian control points bound it (positive weights), so the box
    encloses the surface over the rectangle (004 §4.1's secondary decomposition,
    without building the refined patches). Only the patches holding the
    rectangles are extracted (:func:`span_patches`).

    Parameters
    ----------
    surface : NurbsSurface
    rects : (k, 4) float
        ``[u0, u1, v0, v1]``, each inside one knot span in u and one in v.

    Returns
    -------
    (k, 2, d) float

    Raises
    ------
    InvalidGeometryError
        A rectangle spanning more than one Bézier patch.
    """
    rects = np.asarray(rects, dtype=float).reshape(-1, 4)
    iu, iv = _patch_spans(surface, rects)
    ku, kv = surface.knots_u, surface.knots_v
    a, b, c, d = ku[iu], ku[iu + 1], kv[iv], kv[iv + 1]
    key, inverse = np.unique(iu * (surface.knots_v.size + 1) + iv, return_inverse=True)
    pairs_u, pairs_v = np.divmod(key, surface.knots_v.size + 1)
    coeffs = span_patches(surface, pairs_u, pairs_v)
    if compiled(rects.shape[0] * coeffs[0].size) and coeffs.shape[-1] == 4:   # the blossoms below, compiled
        return tessellation_kernels.restricted_boxes(
            coeffs, inverse.ravel(), (rects[:, 0] - a) / (b - a), (rects[:, 1] - a) / (b - a),
            (rects[:, 2] - c) / (d - c), (rects[:, 3] - c) / (d - c))
    coeffs = coeffs[inverse.ravel()]
    coeffs = _blossom_restrict(coeffs, (rects[:, 0] - a) / (b - a), (rects[:, 1] - a) / (b - a))
    coeffs = _blossom_restrict(np.swapaxes(coeffs, 1, 2), (rects[:, 2] - c) / (d - c),
                               (rects[:, 3] - c) / (d - c))
    cartesian = coeffs[..., :-1] / coeffs[..., -1:]
    return np.stack([vectors.corner_min(cartesian), vectors.corner_max(cartesian)], axis=1)


# ------------------------------------------------------------ span grid trees
def span_hull_boxes(surface: NurbsSurface) -> NDArray:
    """``(ku, kv, 2, d)`` boxes of the ``(p + 1) x (q + 1)`` poles of every non-empty knot
    span: with positive weights the surface over the span lies in their convex
    hull (looser than the Bézier box, but a sliding min/max over the net)."""
    p, q = surface.degree_u, surface.degree_v
    nu, nv = surface.n_control
    su, sv = _spans(surface.knots_u, p, nu), _spans(surface.knots_v, q, nv)
    cp = np.asarray(surface.control_points, dtype=float)
    lo, hi = cp, cp
    for axis, width in ((0, p + 1), (1, q + 1)):             # separable sliding min / max
        count = lo.shape[axis] - width + 1

        def window(x, k, axis=axis, count=count):
            return x[(slice(None),) * axis + (slice(k, k + count),)]

        new_lo, new_hi = window(lo, 0).copy(), window(hi, 0).copy()
        for k in range(1, width):
            np.minimum(new_lo, window(lo, k), out=new_lo)
            np.maximum(new_hi, window(hi, k), out=new_hi)
        lo, hi = new_lo, new_hi
    # window start i - p holds span i
    return np.stack([lo[su - p][:, sv - q], hi[su - p][:, sv - q]], axis=2)


def grid_tree(boxes: ArrayLike) -> BoxTree:
    """Box tree over a ``(ku, kv)`` grid of boxes ``(ku, kv, 2, 3)``, without sorting.

    Nodes are index rectangles of the grid, split in half across their longer
    side; leaf items are flat indices ``i * kv + j``. Built level by level (top
    down), boxes bottom up; ``2 ku kv - 1`` nodes.
    """
    boxes = np.asarray(boxes, dtype=float)
    ku, kv = boxes.shape[:2]
    m = ku * kv
    n = 2 * m - 1
    left = np.full(n, -1, np.int64)
    right = np.full(n, -1, np.int64)
    item = np.full(n, -1, np.int64)
    size = np.zeros(n, np.int64)
    rect = np.zeros((n, 4), np.int64)                      # i0, i1, j0, j1
    rect[0] = (0, ku, 0, kv)
    size[0] = m
    levels, frontier, next_id = [np.array([0])], np.array([0]), 1
    while True:
        split = frontier[size[frontier] > 1]
        if split.size == 0:
            break
        i0, i1, j0, j1 = rect[split].T
        along_u = (i1 - i0) >= (j1 - j0)
        mid_i = np.where(along_u, (i0 + i1) // 2, i1)
        mid_j = np.where(along_u, j1, (j0 + j1) // 2)
        kids = next_id + np.arange(2 * split.size)
        left[split], right[split] = kids[0::2], kids[1::2]
        rect[kids[0::2]] = np.stack([i0, mid_i, j0, mid_j], 1)
        rect[kids[1::2]] = np.stack([np.where(along_u, mid_i, i0), i1,
                                     np.where(along_u, j0, mid_j), j1], 1)
        r = rect[kids]
        size[kids] = (r[:, 1] - r[:, 0]) * (r[:, 3] - r[:, 2])
        next_id += kids.size
        frontier = kids
        levels.append(kids)
    leaves = left < 0
    item[leaves] = rect[leaves, 0] * kv + rect[leaves, 2]
    flat = boxes.reshape(m, 2, -1)
    lo, hi = np.zeros((n, flat.shape[2])), np.zeros((n, flat.shape[2]))
    lo[leaves], hi[leaves] = flat[item[leaves], 0], flat[item[leaves], 1]
    for level in reversed(levels):
        inner = level[left[level] >= 0]
        lo[inner] = np.minimum(lo[left[inner]], lo[right[inner]])
        hi[inner] = np.maximum(hi[left[inner]], hi[right[inner]])
    return BoxTree(lo, hi, left, right, item, size, len(levels))


def surface_tree(surface: NurbsSurface, pad: float = 0.0) -> BoxTree:
    """:func:`grid_tree` over the span hull boxes, widened by ``pad``."""
    boxes = span_hull_boxes(surface)
    return grid_tree(boxes + np.array([-pad, pad])[:, None])


def exact_patch_boxes(surface: NurbsSurface, patches: ArrayLike) -> NDArray:
    """Bézier control-net boxes ``(k, 2, d)`` of patches given by flat index
    ``i * kv + j`` (the order of :func:`surface_patch_boxes`), extracting only them."""
    p, q = surface.degree_u, surface.degree_v
    nu, nv = surface.n_control
    su, sv = _spans(surface.knots_u, p, nu), _spans(surface.knots_v, q, nv)
    patches = np.asarray(patches, dtype=np.int64)
    coeffs = span_patches(surface, su[patches // sv.size], sv[patches % sv.size])
    cartesian = coeffs[..., :-1] / coeffs[..., -1:]
    return np.stack([vectors.corner_min(cartesian), vectors.corner_max(cartesian)], axis=1)


def surface_patch_boxes(surface: NurbsSurface) -> tuple[NDArray, NDArray]:
    """Control-net boxes and parameter rectangles of the Bézier patches, flat.

    Returns
    -------
    boxes : (ku * kv, 2, 3) float
    rects : (ku * kv, 4) float
        Patch ``(i, j)`` at flat index ``i * kv + j``.

    The same boxes as :func:`surfprep.algorithms.bezier.patch_bounding_boxes`, by
    :func:`exact_patch_boxes` on every patch (its span extraction is compiled:
    about half the time).
    """
    rects = patch_rectangles(surface)
    return exact_patch_boxes(surface, np.arange(rects.shape[0])), rects


def overlap_boxes(boxes_a: ArrayLike, boxes_b: ArrayLike, *, pad: float = 0.0
                  ) -> PatchOverlap:
    """Overlap boxes of two sets of boxes; each box is widened by ``pad / 2`` first.

    Parameters
    ----------
    boxes_a : (m, 2, 3) float
    boxes_b : (n, 2, 3) float
    pad : float >= 0
        Total gap tolerated between two boxes.

    Returns
    -------
    PatchOverlap
        Without parameter rectangles.
    """
    pairs = candidate_pairs(boxes_a, boxes_b, pad=pad)
    a = _check_boxes(boxes_a, "boxes_a")[pairs[:, 0]]
    b = _check_boxes(boxes_b, "boxes_b")[pairs[:, 1]]
    h = 0.5 * pad
    boxes = np.stack([np.maximum(a[:, 0], b[:, 0]) - h, np.minimum(a[:, 1], b[:, 1]) + h],
                     axis=1)
    return PatchOverlap(pairs, boxes.reshape(-1, 2, 3), np.unique(pairs[:, 0]),
                        np.unique(pairs[:, 1]))


def overlap_patches(surface_a: NurbsSurface, surface_b: NurbsSurface, *, pad: float = 0.0
                    ) -> PatchOverlap:
    """Bézier patches of two surfaces whose control-net boxes overlap (004 §4.2).

    Parameters
    ----------
    surface_a, surface_b : NurbsSurface, dimension 3
    pad : float >= 0
        Total gap tolerated (use the sum of the two tessellation tolerances,
        so that no pair of triangles within the tolerances is lost).

    Returns
    -------
    PatchOverlap
        With the parameter rectangles of the patches that take part.
    """
    boxes_a, rects_a = surface_patch_boxes(surface_a)
    boxes_b, rects_b = surface_patch_boxes(surface_b)
    ov = overlap_boxes(boxes_a, boxes_b, pad=pad)
    return PatchOverlap(ov.pairs, ov.boxes, ov.patches_a, ov.patches_b,
                        rects_a[ov.patches_a], rects_b[ov.patches_b])
