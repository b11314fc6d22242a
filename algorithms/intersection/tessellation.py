"""Adaptive, crack-free triangulation of a NURBS surface over chosen parameter regions.

Step 1 of the SSI algorithm of 000 §29.4.1 ("triangulate the surfaces"),
restricted as in 004 §4.3 ("selective tessellation") to the parameter regions
that can take part in the intersection (the Bézier patches that meet an overlap
box, :mod:`.culling`), so the work follows the intersection, not the area.

Refinement (000 §29.4.2, recursive subdivision) is breadth-first and
vectorized: at each level the test points of *all* candidate rectangles are
evaluated in one :meth:`NurbsSurface.evaluate` call and the rectangles that
fail the tolerance are split; there is no per-rectangle recursion.

Flatness criterion
------------------
Not 004's eq. (4.1): that planarity measure of the corner quadrilateral is zero
on any ruled strip (a cylinder strip's four corners are coplanar) and so does
not bound the chord error. The criterion here is the *parametric chord
error*: on a ``5 x 5`` grid of test points of the rectangle (the corners,
edge quarter points and interior), the largest distance between the surface
point ``S(u, v)`` and the piecewise-linear interpolant of the rectangle's two
triangles at the same ``(u, v)``, for the better of the two diagonals. It is
the quantity the tests measure (surface at the barycentric-interpolated
``(u, v)`` against the triangle point), in model units. Rectangles are split
until it is below ``0.8 tol``, a margin for what the grid misses. A rectangle is split in
u, in v or both according to the chord errors of its u- and v-lines, so
ruled strips are split one way only.

Cracks
------
Leaves of different sizes meet with T-junctions. Every leaf rectangle that
has corners of finer neighbours on its edges ("hanging" vertices) is
triangulated as a fan from its centre through all its boundary vertices
(corners and hanging ones, counter-clockwise); a leaf without hanging vertices
gets two triangles. Every interior edge is then shared by exactly two
triangles and no balance condition is needed.

Pruning
-------
With ``keep_boxes`` (overlap boxes, or the triangle boxes of the other
operand) every level first drops the rectangles whose sub-patch control-net
box (which encloses the surface there) is farther than ``keep_pad`` from all
keep boxes (004 §4.2-4.3: only the parts of the patches in overlap boxes are
tessellated). The leaves kept are leaves of the unpruned tessellation; only
the fans next to dropped rectangles lose their hanging vertices.

Vertices are identified by their exact ``(u, v)``: every split value is the
floating-point midpoint of its parent interval, computed the same way in every
rectangle that has it on its boundary, so equal parameters are bitwise equal.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError, InvalidToleranceError
from ..basis import find_span
from ..jit import compiled
from ..surface import NurbsSurface
from . import tessellation_kernels
from .culling import (
    BoxTree,
    RegionPatches,
    build_tree,
    patch_rectangles,
    region_patches,
    subpatch_boxes,
    tree_pairs,
)
from .mesh import TriangleMesh, collinear_mask

__all__ = ["Tessellation", "patch_rectangles", "tessellate"]

_SAMPLES = 5                 # test grid per rectangle and direction (quarter points)
#: leaves are split until their estimated error is below _MARGIN * tol: the margin
#: covers what the test grid misses between its points and in fan triangles (the
#: densely measured error exceeded the estimate by up to 7 % on 600 random
#: bicubic tessellations)
_MARGIN = 0.8
_MAX_LEAVES = 4_000_000
#: per-region keep tests are used while they cost less than this many box tests per
#: rectangle and keep box; a tree over all keep boxes otherwise
_REGION_BUDGET = 16


@dataclass(frozen=True, eq=False)
class Tessellation:
    """The result of :func:`tessellate`.

    Attributes
    ----------
    mesh : TriangleMesh
        With ``uv`` (the exact parameters of every vertex) and ``patch`` (the
        leaf id of every triangle, an index into ``leaves``).
    leaves : (L, 4) float
        Leaf parameter rectangles ``[u0, u1, v0, v1]``.
    leaf_region : (L,) int
        Index of the input region each leaf subdivides.
    leaf_error : (L,) float
        Estimated chord error of each leaf (<= 0.8 tol unless ``max_depth`` stopped it).
    depth : int
        Number of refinement levels used.
    """

    mesh: TriangleMesh
    leaves: NDArray
    leaf_region: NDArray
    leaf_error: NDArray
    depth: int


# ------------------------------------------------------------ chord error
def _interpolation_weights(s: NDArray) -> tuple[NDArray, NDArray]:
    """Weights (n, n, 4) of the corners ``[c00, c10, c11, c01]`` for both diagonals.

    Diagonal 0 joins c00-c11, diagonal 1 joins c10-c01; ``s`` along u, ``t`` along v.
    """
    S, T = np.meshgrid(s, s, indexing="ij")
    z = np.zeros_like(S)
    low = S >= T
    w0 = np.where(low[..., None],
                  np.stack([1 - S, S - T, T, z], axis=-1),
                  np.stack([1 - T, z, S, T - S], axis=-1))
    below = S + T <= 1
    w1 = np.where(below[..., None],
                  np.stack([1 - S - T, S, z, T], axis=-1),
                  np.stack([z, 1 - T, S + T - 1, 1 - S], axis=-1))
    return w0, w1


def _chord_errors(surface: NurbsSurface, rects: NDArray
                  ) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """Chord errors of rectangles, all test points in one evaluation.

    Parameters
    ----------
    rects : (k, 4) float

    Returns
    -------
    error : (k,) float
        Max distance of the surface from the better two-triangle interpolant.
    diagonal : (k,) int
        0 for the c00-c11 diagonal, 1 for c10-c01.
    error_u, error_v : (k,) float
        Max distance of the u-lines (v-lines) of the grid from their chords.
    """
    s = np.linspace(0.0, 1.0, _SAMPLES)
    u = (1 - s) * rects[:, :1] + s * rects[:, 1:2]                  # (k, n)
    v = (1 - s) * rects[:, 2:3] + s * rects[:, 3:4]
    fast = compiled(u.size * _SAMPLES * (surface.degree_u + 1) * (surface.degree_v + 1))
    if fast:                                    # basis functions once per grid line
        su = find_span(surface.knots_u, surface.degree_u, u.ravel()).reshape(u.shape)
        sv = find_span(surface.knots_v, surface.degree_v, v.ravel()).reshape(v.shape)
        grid = tessellation_kernels.grid_points(
            surface.knots_u, surface.knots_v, surface.degree_u, surface.degree_v,
            surface.homogeneous_net, u, v, su, sv, surface.weights is not None)
    else:
        grid = surface.evaluate(u[:, :, None], v[:, None, :])      # (k, n, n, 3)
    if fast:                                    # the formulas below, compiled
        return tessellation_kernels.chord_errors_from_grid(grid, s)
    corners = grid[:, [0, -1, -1, 0], [0, 0, -1, -1]]               # (k, 4, 3)
    w0, w1 = _interpolation_weights(s)
    e0 = np.linalg.norm(grid - np.einsum("abc,kcd->kabd", w0, corners), axis=-1)
    e1 = np.linalg.norm(grid - np.einsum("abc,kcd->kabd", w1, corners), axis=-1)
    e0, e1 = e0.max(axis=(1, 2)), e1.max(axis=(1, 2))
    sc = s[None, :, None, None]
    chord_u = (1 - sc) * grid[:, :1] + sc * grid[:, -1:]
    chord_v = (1 - s[None, None, :, None]) * grid[:, :, :1] + s[None, None, :, None] * grid[:, :, -1:]
    error_u = np.linalg.norm(grid - chord_u, axis=-1).max(axis=(1, 2))
    error_v = np.linalg.norm(grid - chord_v, axis=-1).max(axis=(1, 2))
    return np.minimum(e0, e1), (e1 < e0).astype(np.int64), error_u, error_v


def _split(rects: NDArray, region: NDArray, split_u: NDArray, split_v: NDArray
           ) -> tuple[NDArray, NDArray]:
    """Children of rectangles split at their midpoints in u, v or both."""
    u0, u1, v0, v1 = rects.T
    um, vm = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
    nu = np.where(split_u, 2, 1)
    nv = np.where(split_v, 2, 1)
    u_cuts = np.stack([u0, np.where(split_u, um, u1), u1], axis=1)
    v_cuts = np.stack([v0, np.where(split_v, vm, v1), v1], axis=1)
    count = nu * nv
    parent = np.repeat(np.arange(rects.shape[0]), count)
    local = np.arange(parent.size) - np.repeat(np.cumsum(count) - count, count)
    a = local // nv[parent]                    # u child index
    b = local % nv[parent]                     # v child index
    ua = u_cuts[parent, a]
    ub = np.where(nu[parent] == 2, u_cuts[parent, a + 1], u_cuts[parent, 2])
    va = v_cuts[parent, b]
    vb = np.where(nv[parent] == 2, v_cuts[parent, b + 1], v_cuts[parent, 2])
    return np.stack([ua, ub, va, vb], axis=1), region[parent]


@dataclass(frozen=True, eq=False)
class _RegionBoxes:
    """Keep boxes grouped by the region they belong to: ``boxes[start[r]:start[r + 1]]``."""

    boxes: NDArray
    start: NDArray
    tree: BoxTree | None = None        # over all boxes, built when the regions are too big


def _region_boxes(boxes: NDArray, owner: NDArray, n_regions: int) -> _RegionBoxes:
    order = np.argsort(owner, kind="stable")
    counts = np.bincount(owner, minlength=n_regions)
    return _RegionBoxes(boxes[order], np.concatenate([[0], np.cumsum(counts)]))


def _near(surface: NurbsSurface, rects: NDArray, region: NDArray,
          keep: BoxTree | _RegionBoxes | None, pad: float,
          patches: RegionPatches | None = None) -> NDArray:
    """Mask of rectangles whose sub-patch box is within ``pad`` of some keep box (of
    their own region only, for keep boxes given per region); ``patches`` the Bézier
    patches of the regions, extracted once per tessellation."""
    if keep is None:
        return np.ones(rects.shape[0], bool)
    boxes = subpatch_boxes(surface, rects) if patches is None else patches.boxes(rects, region)
    if isinstance(keep, BoxTree):
        if compiled(8 * boxes.shape[0]):
            return tessellation_kernels.any_overlap(keep, boxes, pad)
        pairs = tree_pairs(build_tree(boxes), keep, pad=pad)
        mask = np.zeros(rects.shape[0], bool)
        mask[pairs[:, 0]] = True
        return mask
    lo, hi = keep.start[region], keep.start[region + 1]
    counts = hi - lo
    if counts.sum() > _REGION_BUDGET * (rects.shape[0] + keep.boxes.shape[0]):
        # few large regions (a face of one or two Bezier patches): a tree is cheaper
        if keep.tree is None:
            object.__setattr__(keep, "tree", build_tree(keep.boxes))
        return _near(surface, rects, region, keep.tree, pad, patches)
    if compiled(int(counts.sum())):              # each rectangle against its region's boxes
        return tessellation_kernels.any_overlap_in_range(boxes, lo, hi, keep.boxes, pad)
    rect = np.repeat(np.arange(rects.shape[0]), counts)
    other = np.repeat(lo - np.cumsum(counts) + counts, counts) + np.arange(rect.size)
    k = keep.boxes[other]
    hit = np.all((boxes[rect, 0] <= k[:, 1] + pad) & (k[:, 0] <= boxes[rect, 1] + pad), axis=1)
    return np.bincount(rect[hit], minlength=rects.shape[0]) > 0


def _refine(surface: NurbsSurface, regions: NDArray, tol: float, max_depth: int,
            keep: BoxTree | _RegionBoxes | None, pad: float
            ) -> tuple[NDArray, NDArray, NDArray, NDArray, int]:
    """Breadth-first refinement: leaves, their regions, errors and diagonals."""
    rects, region = regions, np.arange(regions.shape[0])
    patches = None if keep is None else region_patches(surface, regions)
    out_rects, out_region = [np.zeros((0, 4))], [np.zeros(0, np.int64)]
    out_err, out_diag = [np.zeros(0)], [np.zeros(0, np.int64)]
    depth = 0
    while rects.shape[0]:
        near = _near(surface, rects, region, keep, pad, patches)
        rects, region = rects[near], region[near]
        if rects.shape[0] == 0:
            break
        err, diag, eu, ev = _chord_errors(surface, rects)
        done = (err <= _MARGIN * tol) | (depth >= max_depth)
        out_rects.append(rects[done])
        out_region.append(region[done])
        out_err.append(err[done])
        out_diag.append(diag[done])
        todo = ~done
        if not todo.any():
            break
        err, eu, ev = err[todo], eu[todo], ev[todo]
        worst = np.maximum(eu, ev)
        twist = worst <= 0.25 * err                 # neither direction explains the error
        split_u = twist | (eu >= 0.5 * worst)
        split_v = twist | (ev >= 0.5 * worst)
        rects, region = _split(rects[todo], region[todo], split_u, split_v)
        if sum(r.shape[0] for r in out_rects) + rects.shape[0] > _MAX_LEAVES:
            raise InvalidToleranceError(
                f"tolerance {tol!r} needs more than {_MAX_LEAVES} parameter rectangles")
        depth += rects.shape[0] > 0
    return (np.concatenate(out_rects), np.concatenate(out_region),
            np.concatenate(out_err), np.concatenate(out_diag), depth)


# ------------------------------------------------------- crack-free mesh
def _ragged(starts: NDArray, counts: NDArray, reverse: NDArray) -> tuple[NDArray, NDArray]:
    """Flat indices ``starts[g] + i`` (or ``starts[g] + counts[g] - 1 - i``) per group g.

    Returns the group id and the index of every element, groups in order.
    """
    group = np.repeat(np.arange(counts.size), counts)
    local = np.arange(group.size) - np.repeat(np.cumsum(counts) - counts, counts)
    index = np.where(reverse[group], starts[group] + counts[group] - 1 - local,
                     starts[group] + local)
    return group, index


def _boundary_loops(leaves: NDArray, iu: NDArray, iv: NDArray, corner_ids: NDArray
                    ) -> tuple[NDArray, NDArray]:
    """Counter-clockwise boundary vertex loop of every leaf, hanging vertices included.

    Parameters
    ----------
    leaves : (L, 4) float
    iu, iv : (n,) int
        Ranks of the u and v values of the unique leaf corners.
    corner_ids : (L, 4) int
        Ids of ``[c00, c10, c11, c01]`` among the unique corners.

    Returns
    -------
    loop : (total,) int
        Vertex ids, leaf after leaf.
    loop_count : (L,) int
        Length of each leaf's loop (4 when it has no hanging vertex).
    """
    n_u, n_v = int(iu.max()) + 1, int(iv.max()) + 1
    key_h = iv * n_u + iu                        # rows: v then u
    key_v = iu * n_v + iv                        # columns: u then v
    order_h, order_v = np.argsort(key_h), np.argsort(key_v)
    sorted_h, sorted_v = key_h[order_h], key_v[order_v]
    cu, cv = iu[corner_ids], iv[corner_ids]      # (L, 4) ranks of the corners
    # side k runs from corner k to corner k + 1 (bottom, right, top, left)
    lo_h = np.stack([cv[:, 0] * n_u + cu[:, 0], cv[:, 3] * n_u + cu[:, 3]], axis=1)
    hi_h = np.stack([cv[:, 1] * n_u + cu[:, 1], cv[:, 2] * n_u + cu[:, 2]], axis=1)
    lo_v = np.stack([cu[:, 1] * n_v + cv[:, 1], cu[:, 0] * n_v + cv[:, 0]], axis=1)
    hi_v = np.stack([cu[:, 2] * n_v + cv[:, 2], cu[:, 3] * n_v + cv[:, 3]], axis=1)
    start_h = np.searchsorted(sorted_h, lo_h, side="right")
    count_h = np.searchsorted(sorted_h, hi_h, side="left") - start_h
    start_v = np.searchsorted(sorted_v, lo_v, side="right")
    count_v = np.searchsorted(sorted_v, hi_v, side="left") - start_v
    # sides in loop order: bottom (h, forward), right (v, forward), top (h, back), left (v, back)
    starts = np.stack([start_h[:, 0], start_v[:, 0], start_h[:, 1], start_v[:, 1]], axis=1)
    counts = np.stack([count_h[:, 0], count_v[:, 0], count_h[:, 1], count_v[:, 1]], axis=1)
    is_h = np.tile([True, False, True, False], leaves.shape[0])
    reverse = np.tile([False, False, True, True], leaves.shape[0])
    seg_len = 1 + counts.ravel()
    seg_start = np.cumsum(seg_len) - seg_len
    loop = np.empty(int(seg_len.sum()), dtype=np.int64)
    loop[seg_start] = corner_ids.ravel()
    group, index = _ragged(starts.ravel(), counts.ravel(), reverse)
    local = np.arange(group.size) - np.repeat(np.cumsum(counts.ravel()) - counts.ravel(),
                                               counts.ravel())
    loop[seg_start[group] + 1 + local] = np.where(is_h[group], order_h[index], order_v[index])
    return loop, seg_len.reshape(-1, 4).sum(axis=1)


def _triangulate_leaves(leaves: NDArray, diagonal: NDArray
                        ) -> tuple[NDArray, NDArray, NDArray]:
    """Crack-free triangles over the leaves.

    Returns
    -------
    uv : (n, 2) float
        Unique vertex parameters (leaf corners, then fan centres).
    triangles : (m, 3) int
        Counter-clockwise in (u, v).
    leaf_of : (m,) int
    """
    u0, u1, v0, v1 = leaves.T
    corners = np.stack([np.stack([u0, v0], 1), np.stack([u1, v0], 1),
                        np.stack([u1, v1], 1), np.stack([u0, v1], 1)], axis=1)   # (L, 4, 2)
    # unique corners in (u, v) lexicographic order, by one integer key of the
    # ranks of their u and v values (a row-wise unique sorts much slower)
    values_u, rank_u = np.unique(corners[..., 0], return_inverse=True)
    values_v, rank_v = np.unique(corners[..., 1], return_inverse=True)
    key = rank_u.reshape(-1) * values_v.size + rank_v.reshape(-1)
    unique_key, inverse = np.unique(key, return_inverse=True)
    iu, iv = unique_key // values_v.size, unique_key % values_v.size
    uv = np.stack([values_u[iu], values_v[iv]], axis=1)
    corner_ids = inverse.reshape(-1, 4)
    loop, loop_count = _boundary_loops(leaves, iu, iv, corner_ids)
    leaf_ids = np.arange(leaves.shape[0])
    # two triangles where no neighbour hangs on the leaf
    plain = loop_count == 4
    c = corner_ids[plain]
    d = diagonal[plain][:, None] == 1
    first = np.where(d, c[:, [0, 1, 3]], c[:, [0, 1, 2]])
    second = np.where(d, c[:, [1, 2, 3]], c[:, [0, 2, 3]])
    tri_plain = np.concatenate([first, second])
    leaf_plain = np.tile(leaf_ids[plain], 2)
    # fans from the centre through the boundary loop elsewhere
    fan = ~plain
    centres = np.stack([0.5 * (u0 + u1), 0.5 * (v0 + v1)], axis=1)[fan]
    centre_id = uv.shape[0] + np.arange(centres.shape[0])
    loop_start = np.cumsum(loop_count) - loop_count
    group, pos = _ragged(loop_start[fan], loop_count[fan], np.zeros(fan.sum(), bool))
    nxt = np.where(pos + 1 == loop_start[fan][group] + loop_count[fan][group],
                   loop_start[fan][group], pos + 1)
    tri_fan = np.stack([centre_id[group], loop[pos], loop[nxt]], axis=1)
    triangles = np.concatenate([tri_plain, tri_fan])
    leaf_of = np.concatenate([leaf_plain, leaf_ids[fan][group]])
    return np.concatenate([uv, centres]), triangles, leaf_of


def _one_leaf(leaf: NDArray, diagonal: int) -> tuple[NDArray, NDArray, NDArray]:
    """:func:`_triangulate_leaves` of a single leaf (a plane's one patch: no neighbour
    can hang on it), without the sorting and loop bookkeeping: the same corners in
    the same (u, v) order and the same two triangles."""
    u0, u1, v0, v1 = leaf
    uv = np.array([[u0, v0], [u0, v1], [u1, v0], [u1, v1]])
    triangles = np.array([[0, 2, 1], [2, 3, 1]] if diagonal == 1 else [[0, 2, 3], [0, 3, 1]])
    return uv, triangles, np.zeros(2, dtype=np.int64)


# ------------------------------------------------------------------- public
def _check_regions(surface: NurbsSurface, regions: ArrayLike | None) -> NDArray:
    if regions is None:
        return patch_rectangles(surface)
    r = np.array(regions, dtype=float).reshape(-1, 4) if np.size(regions) else np.zeros((0, 4))
    if not np.all(np.isfinite(r)):
        raise InvalidGeometryError("regions contain NaN or infinite values")
    if np.any(r[:, 0] >= r[:, 1]) or np.any(r[:, 2] >= r[:, 3]):
        raise InvalidGeometryError("every region [u0, u1, v0, v1] needs u0 < u1 and v0 < v1")
    a, b, c, d = surface.domain
    if np.any(r[:, 0] < a) or np.any(r[:, 1] > b) or np.any(r[:, 2] < c) or np.any(r[:, 3] > d):
        raise InvalidGeometryError(
            f"regions must lie in the surface domain {surface.domain}")
    return r


def tessellate(surface: NurbsSurface, tol: float, regions: ArrayLike | None = None, *,
               max_depth: int = 24, keep_boxes: ArrayLike | None = None,
               keep_pad: float = 0.0, keep_region: ArrayLike | None = None) -> Tessellation:
    """Adaptive crack-free triangulation of ``surface`` over parameter regions.

    Parameters
    ----------
    surface : NurbsSurface, dimension 3
    tol : float > 0
        Chord tolerance in model units: the parametric chord error (module
        docstring) of every leaf is at most ``tol`` on its test grid.
    regions : (r, 4) float, optional
        Non-overlapping parameter rectangles ``[u0, u1, v0, v1]`` to triangulate
        (whole Bézier patches or their dyadic sub-rectangles, so shared edges
        carry equal parameter values); by default every Bézier patch
        (:func:`patch_rectangles`), i.e. the whole surface.
    max_depth : int
        Refinement levels at most; leaves still above ``tol`` then are kept
        (their ``leaf_error`` says so).
    keep_boxes : (b, 2, 3) float, optional
        Overlap boxes (004 §4.2): at every level, rectangles whose sub-patch
        control-net box (:func:`.culling.subpatch_boxes`, which encloses the
        surface there) is farther than ``keep_pad`` from every keep box are
        dropped, so only the surface near the boxes is triangulated. Needs every
        region inside one Bézier patch (as the default regions are).
    keep_pad : float >= 0
    keep_region : (b,) int, optional
        The region each keep box belongs to: a rectangle is then tested against
        the keep boxes of its own region only (the overlap boxes of its patch),
        in work proportional to their number instead of a tree over all of them.

    Returns
    -------
    Tessellation
        Zero-area triangles (at a collapsed edge such as a pole) are left out.

    Raises
    ------
    InvalidToleranceError
        ``tol`` not finite and positive, or so small that more than four million
        rectangles would be needed.
    InvalidGeometryError
        A surface not in 3D, or regions outside its domain or empty.
    """
    if surface.dimension != 3:
        raise InvalidGeometryError(f"tessellate needs a surface in 3D, got {surface.dimension}")
    if not (np.isfinite(tol) and tol > 0):
        raise InvalidToleranceError(f"tol must be finite and > 0, got {tol!r}")
    regions = _check_regions(surface, regions)
    keep = None
    if keep_boxes is not None:
        boxes = np.reshape(keep_boxes, (-1, 2, 3))
        if keep_region is None:
            keep = build_tree(boxes)
        else:
            owner = np.asarray(keep_region, dtype=np.int64).reshape(-1)
            if owner.shape != (boxes.shape[0],) or np.any((owner < 0) | (owner >= regions.shape[0])):
                raise InvalidGeometryError("keep_region needs one region index per keep box")
            keep = _region_boxes(boxes, owner, regions.shape[0])
    leaves, region, err, diag, depth = _refine(surface, regions, float(tol), int(max_depth),
                                               keep, float(keep_pad))
    if leaves.shape[0] == 0:
        empty = TriangleMesh(np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros((0, 2)),
                             np.zeros(0, np.int64))
        return Tessellation(empty, leaves, region, err, depth)
    uv, triangles, leaf_of = (_one_leaf(leaves[0], diag[0]) if leaves.shape[0] == 1
                              else _triangulate_leaves(leaves, diag))
    xyz = surface.evaluate(uv[:, 0], uv[:, 1])
    solid = ~collinear_mask(xyz[triangles])
    mesh = TriangleMesh.from_checked(xyz, triangles[solid], uv, leaf_of[solid])   # solid: checked
    return Tessellation(mesh, leaves, region, err, depth)
