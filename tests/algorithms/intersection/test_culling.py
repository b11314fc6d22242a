"""Box trees and overlap boxes: exactly the brute-force pairs, and work that follows the intersection."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import sphere_band
from hypothesis import given, settings
from hypothesis import strategies as st

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection.culling import (
    build_tree,
    candidate_pairs,
    overlap_boxes,
    overlap_patches,
    surface_patch_boxes,
    tree_pairs,
)
from surfprep.errors import InvalidGeometryError


def brute_force_pairs(a, b, pad=0.0):
    """Reference: every pair of closed boxes within ``pad`` on all axes."""
    if len(a) == 0 or len(b) == 0:
        return np.zeros((0, 2), int)
    hit = np.all((a[:, None, 0] <= b[None, :, 1] + pad) & (b[None, :, 0] <= a[:, None, 1] + pad),
                 axis=-1)
    return np.argwhere(hit)


def random_boxes(rng, m, size, grid=False):
    centre = rng.random((m, 3))
    if grid:                                   # many exact ties and touching boxes
        centre = np.round(centre * 4) / 4
    half = rng.random((m, 3)) * size
    if grid:
        half = np.round(half * 8) / 8
    return np.stack([centre - half, centre + half], axis=1)


def plane(x, y, z):
    cp = np.array([[[x[0], y[0], z], [x[0], y[1], z]], [[x[1], y[0], z], [x[1], y[1], z]]], float)
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


# -------------------------------------------------------------------- trees
@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), m=st.integers(0, 120), n=st.integers(0, 120),
       size=st.sampled_from([0.0, 0.02, 0.1, 0.5]), grid=st.booleans(),
       pad=st.sampled_from([0.0, 0.05]))
def test_tree_pairs_equal_brute_force(seed, m, n, size, grid, pad):
    rng = np.random.default_rng(seed)
    a, b = random_boxes(rng, m, size, grid), random_boxes(rng, n, size, grid)
    got = candidate_pairs(a, b, pad=pad)
    np.testing.assert_array_equal(got, brute_force_pairs(a, b, pad))


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), m=st.integers(1, 200))
def test_tree_structure(seed, m):
    boxes = random_boxes(np.random.default_rng(seed), m, 0.1)
    tree = build_tree(boxes)
    assert tree.n_nodes == 2 * m - 1
    leaves = tree.left < 0
    assert np.array_equal(np.sort(tree.item[leaves]), np.arange(m))
    assert np.all(tree.item[~leaves] == -1) and np.all(tree.right[leaves] == -1)
    inner = np.flatnonzero(~leaves)
    # children's boxes inside the parent's, sizes add up, median split (sizes differ by <= 1)
    for child in (tree.left[inner], tree.right[inner]):
        assert np.all(tree.lo[child] >= tree.lo[inner]) and np.all(tree.hi[child] <= tree.hi[inner])
    assert np.all(tree.size[tree.left[inner]] + tree.size[tree.right[inner]] == tree.size[inner])
    assert np.all(np.abs(tree.size[tree.left[inner]] - tree.size[tree.right[inner]]) <= 1)
    np.testing.assert_array_equal(tree.lo[0], boxes[:, 0].min(axis=0))
    assert tree.depth <= int(np.ceil(np.log2(m))) + 1


def test_tree_pairs_is_symmetric():
    rng = np.random.default_rng(3)
    a, b = random_boxes(rng, 300, 0.05), random_boxes(rng, 200, 0.05)
    ab = tree_pairs(build_tree(a), build_tree(b))
    ba = tree_pairs(build_tree(b), build_tree(a))
    assert ab.shape[0] > 0
    np.testing.assert_array_equal(ab, ba[np.lexsort((ba[:, 0], ba[:, 1]))][:, ::-1])


def test_tree_traversal_beats_all_pairs():
    """Thin boxes along two crossing planes: candidates ~ M, not M N."""
    rng = np.random.default_rng(0)
    m = 4000
    xy = rng.random((m, 2))
    a = np.stack([np.c_[xy, np.zeros(m)] - 0.005, np.c_[xy, np.zeros(m)] + 0.005], axis=1)
    b = a[:, :, [0, 2, 1]] + [0, 0.5, 0]                  # the plane y = 0.5
    pairs = candidate_pairs(a, b)
    np.testing.assert_array_equal(pairs, brute_force_pairs(a, b))
    assert 0 < pairs.shape[0] < m * m / 500


@pytest.mark.parametrize("boxes, match", [
    (np.zeros((3, 3, 3)), "shape"), (np.full((2, 2, 3), np.nan), "finite"),
    (np.array([[[1, 0, 0], [0, 1, 1]]], float), "min <= max")])
def test_bad_boxes(boxes, match):
    with pytest.raises(InvalidGeometryError, match=match):
        candidate_pairs(boxes, boxes)


def test_bad_pad():
    with pytest.raises(InvalidGeometryError, match="pad"):
        candidate_pairs(np.zeros((1, 2, 3)), np.zeros((1, 2, 3)), pad=-1.0)


# ------------------------------------------------------------ overlap boxes
def test_overlap_boxes_are_intersections():
    a = np.array([[[0, 0, 0], [2, 2, 2]], [[5, 5, 5], [6, 6, 6]]], float)
    b = np.array([[[1, 1, 1], [3, 3, 3]], [[10, 10, 10], [11, 11, 11]]], float)
    ov = overlap_boxes(a, b)
    np.testing.assert_array_equal(ov.pairs, [[0, 0]])
    np.testing.assert_array_equal(ov.boxes, [[[1, 1, 1], [2, 2, 2]]])
    np.testing.assert_array_equal(ov.patches_a, [0])
    assert ov.rects_a is None


def test_sphere_patches_in_overlap_with_a_small_plane():
    """A plane over one quadrant of the sphere zone selects only the patches near it."""
    band = sphere_band()
    small = plane((0.5, 1.5), (0.5, 1.5), 0.0)
    ov = overlap_patches(band, small)
    boxes, rects = surface_patch_boxes(band)
    np.testing.assert_array_equal(ov.pairs, brute_force_pairs(boxes, surface_patch_boxes(small)[0]))
    assert ov.patches_a.size < boxes.shape[0]
    np.testing.assert_array_equal(ov.rects_a, rects[ov.patches_a])
    assert np.all(ov.rects_b == [[0, 1, 0, 1]])


def test_far_apart_surfaces_have_no_overlap():
    ov = overlap_patches(sphere_band(), sphere_band(centre=(10, 0, 0)), pad=0.1)
    assert ov.pairs.shape == (0, 2) and ov.patches_a.size == 0 and ov.rects_b.shape == (0, 4)
    # a pad larger than the gap makes them overlap
    near = overlap_patches(sphere_band(), sphere_band(centre=(2.5, 0, 0)), pad=0.6)
    assert near.pairs.shape[0] > 0


def test_subpatch_boxes_enclose_the_surface():
    from surfprep.algorithms.intersection.culling import patch_rectangles, subpatch_boxes
    surface = sphere_band()
    rects = patch_rectangles(surface)
    rng = np.random.default_rng(5)
    k = rng.integers(0, rects.shape[0], 300)
    t, w = np.sort(rng.random((300, 2)), axis=1), np.sort(rng.random((300, 2)), axis=1)
    u0, u1, v0, v1 = rects[k].T
    sub = np.stack([u0 + (u1 - u0) * t[:, 0], u0 + (u1 - u0) * t[:, 1],
                    v0 + (v1 - v0) * w[:, 0], v0 + (v1 - v0) * w[:, 1]], axis=1)
    boxes = subpatch_boxes(surface, sub)
    g = np.linspace(0, 1, 9)
    u = sub[:, :1] + (sub[:, 1:2] - sub[:, :1]) * g
    v = sub[:, 2:3] + (sub[:, 3:4] - sub[:, 2:3]) * g
    points = surface.evaluate(u[:, :, None], v[:, None, :])
    assert np.all(points >= boxes[:, None, None, 0] - 1e-14)
    assert np.all(points <= boxes[:, None, None, 1] + 1e-14)
    # whole patches: the patch control-net boxes
    np.testing.assert_allclose(subpatch_boxes(surface, rects), surface_patch_boxes(surface)[0],
                               atol=1e-15)
    # small rectangles: tight boxes
    tiny = np.array([[0.1, 0.1 + 1e-4, 0.5, 0.5 + 1e-4]])
    assert np.all(np.ptp(subpatch_boxes(surface, tiny)[0], axis=0) < 1e-3)
    with pytest.raises(InvalidGeometryError, match="one Bézier patch"):
        subpatch_boxes(surface, [[0.2, 0.3, 0, 1]])


# ---------------------------------------------------------------- span grid trees
def random_bspline(rng, n_u: int, n_v: int, rational: bool) -> NurbsSurface:
    """A random bicubic (biquadratic in v) net with interior knots, some repeated."""
    def knots(n, p):
        inner = np.sort(rng.choice(np.linspace(0.1, 0.9, 9), n - p - 1))
        return np.concatenate([[0.0] * (p + 1), inner, [1.0] * (p + 1)])
    cp = rng.normal(size=(n_u, n_v, 3))
    w = rng.uniform(0.5, 2.0, (n_u, n_v)) if rational else None
    return NurbsSurface(cp, knots(n_u, 3), knots(n_v, 2), 3, 2, w)


@pytest.mark.parametrize("seed, rational", [(0, False), (1, True), (2, True)])
def test_span_hulls_exact_boxes_and_grid_tree(seed, rational):
    from surfprep.algorithms.bezier import patch_bounding_boxes
    from surfprep.algorithms.intersection.culling import (
        exact_patch_boxes,
        grid_tree,
        span_hull_boxes,
    )
    s = random_bspline(np.random.default_rng(seed), 9, 7, rational)
    exact = patch_bounding_boxes(s)[0].reshape(-1, 2, 3)     # whole Bezier decomposition
    np.testing.assert_allclose(exact_patch_boxes(s, np.arange(exact.shape[0])), exact,
                               atol=1e-12)
    np.testing.assert_allclose(surface_patch_boxes(s)[0], exact, atol=1e-12)
    hull = span_hull_boxes(s).reshape(-1, 2, 3)
    assert hull.shape == exact.shape
    assert np.all(hull[:, 0] <= exact[:, 0] + 1e-12) and np.all(hull[:, 1] >= exact[:, 1] - 1e-12)
    tree = grid_tree(span_hull_boxes(s))
    leaves = tree.item >= 0
    assert np.array_equal(np.sort(tree.item[leaves]), np.arange(hull.shape[0]))
    inner = ~leaves                                          # parents hold their children
    for side in (tree.left, tree.right):
        assert np.all(tree.lo[inner] <= tree.lo[side[inner]])
        assert np.all(tree.hi[inner] >= tree.hi[side[inner]])
    np.testing.assert_array_equal(tree.lo[leaves], hull[tree.item[leaves], 0])


def test_hierarchical_overlap_equals_exact_patch_overlap():
    """mesh_segments' culling (hull grid trees, then exact boxes of the candidates only)
    gives exactly the pairs of overlapping exact Bezier boxes."""
    from surfprep.algorithms.intersection.segments import _overlap
    rng = np.random.default_rng(5)
    a = random_bspline(rng, 12, 10, True)
    b = random_bspline(rng, 8, 9, False)
    pad = 0.05
    ov = _overlap(a, b, pad, pad)
    ea, _ = surface_patch_boxes(a)
    eb, _ = surface_patch_boxes(b)
    ref = brute_force_pairs(ea + [[-pad], [pad]], eb + [[-pad], [pad]])
    assert ref.shape[0] > 0
    np.testing.assert_array_equal(ov.pairs[np.lexsort(ov.pairs.T[::-1])],
                                  ref[np.lexsort(ref.T[::-1])])
