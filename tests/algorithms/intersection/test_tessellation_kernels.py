"""The compiled chord errors and sub-patch boxes (tessellation_kernels.py) against their
numpy forms in tessellation.py / culling.py."""

import numpy as np
import pytest
from helpers.surfaces import sphere_band

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import tessellation_kernels
from surfprep.algorithms.intersection.culling import patch_rectangles, subpatch_boxes
from surfprep.algorithms.intersection.tessellation import _chord_errors


def test_compiled_kernels_are_available():
    # numba is a declared dependency: without it the numpy fallbacks would run
    # silently and the comparisons below would compare a form with itself
    assert tessellation_kernels.AVAILABLE


def _bumpy() -> NurbsSurface:
    rng = np.random.default_rng(4)
    x = np.linspace(0, 1, 9)
    X, Y = np.meshgrid(x, x, indexing="ij")
    k = np.concatenate([[0.0] * 3, np.linspace(0, 1, 7), [1.0] * 3])
    return NurbsSurface(np.stack([X, Y, 0.2 * rng.normal(size=X.shape)], -1), k, k, 3, 3)


def _high_degree() -> NurbsSurface:
    """Degrees 6 x 5 on uneven knots with a double interior knot, random weights."""
    rng = np.random.default_rng(8)
    ku = np.concatenate([[0.0] * 7, [0.15, 0.4, 0.4, 0.7], [1.0] * 7])
    kv = np.concatenate([[0.0] * 6, [0.3, 0.55, 0.9], [1.0] * 6])
    n_u, n_v = ku.size - 7, kv.size - 6
    return NurbsSurface(rng.normal(size=(n_u, n_v, 3)), ku, kv, 6, 5,
                        rng.uniform(0.5, 2.0, (n_u, n_v)))


def _sub_rectangles(surface, rng, per_patch: int = 20) -> np.ndarray:
    rects = np.repeat(patch_rectangles(surface), per_patch, axis=0)
    a = rng.uniform(0, 1, (rects.shape[0], 2, 2))
    a.sort(axis=1)
    a[:, 1] = np.maximum(a[:, 1], a[:, 0] + 1e-3).clip(max=1.0)
    lo_u, hi_u = rects[:, 0], rects[:, 1]
    lo_v, hi_v = rects[:, 2], rects[:, 3]
    return np.stack([lo_u + a[:, 0, 0] * (hi_u - lo_u), lo_u + a[:, 1, 0] * (hi_u - lo_u),
                     lo_v + a[:, 0, 1] * (hi_v - lo_v), lo_v + a[:, 1, 1] * (hi_v - lo_v)], 1)


@pytest.mark.parametrize("surface", [sphere_band(1.5), _bumpy(), _high_degree()],
                         ids=["rational", "bicubic", "degree 6 x 5"])
def test_compiled_forms_match_numpy(monkeypatch, surface):
    rects = _sub_rectangles(surface, np.random.default_rng(9))
    errors, boxes = _chord_errors(surface, rects), subpatch_boxes(surface, rects)
    monkeypatch.setattr(tessellation_kernels, "AVAILABLE", False)
    errors_np, boxes_np = _chord_errors(surface, rects), subpatch_boxes(surface, rects)
    scale = np.abs(boxes_np).max()
    np.testing.assert_allclose(boxes, boxes_np, rtol=0, atol=1e-14 * scale)
    for mine, ref in zip(errors, errors_np):
        np.testing.assert_allclose(mine, ref, rtol=0, atol=1e-14 * scale)
    # the boxes hold the surface over their rectangles (densely)
    s = np.linspace(0, 1, 9)
    u = rects[:, :1] + s * (rects[:, 1:2] - rects[:, :1])
    v = rects[:, 2:3] + s * (rects[:, 3:4] - rects[:, 2:3])
    pts = surface.evaluate(u[:, :, None], v[:, None, :]).reshape(len(rects), -1, 3)
    assert np.all(pts >= boxes[:, None, 0] - 1e-12 * scale)
    assert np.all(pts <= boxes[:, None, 1] + 1e-12 * scale)


def _random_boxes(rng, n: int, size: float) -> np.ndarray:
    lo = rng.uniform(0, 1, (n, 3))
    return np.stack([lo, lo + rng.uniform(0, size, (n, 3))], axis=1)


@pytest.mark.parametrize("pad", [0.0, 0.02])
def test_overlap_queries_match_brute_force(pad):
    from surfprep.algorithms.intersection.culling import build_tree

    rng = np.random.default_rng(11)
    keep, query = _random_boxes(rng, 700, 0.03), _random_boxes(rng, 400, 0.05)
    near = np.all((query[:, None, 0] <= keep[None, :, 1] + pad)
                  & (keep[None, :, 0] <= query[:, None, 1] + pad), axis=2)      # (400, 700)
    np.testing.assert_array_equal(
        tessellation_kernels.any_overlap(build_tree(keep), query, pad), near.any(axis=1))
    first = rng.integers(0, 700, 400)
    last = np.minimum(first + rng.integers(0, 300, 400), 700)
    cols = np.arange(700)
    in_range = (cols >= first[:, None]) & (cols < last[:, None])
    np.testing.assert_array_equal(
        tessellation_kernels.any_overlap_in_range(query, first, last, keep, pad),
        (near & in_range).any(axis=1))


@pytest.mark.parametrize("pad", [0.0, 0.01])
def test_candidate_pairs_match_tree_pairs(monkeypatch, pad):
    from surfprep.algorithms.intersection.culling import candidate_pairs

    rng = np.random.default_rng(12)
    a, b = _random_boxes(rng, 300, 0.5), _random_boxes(rng, 200, 0.5)
    pairs = candidate_pairs(a, b, pad=pad)
    monkeypatch.setattr(tessellation_kernels, "AVAILABLE", False)
    np.testing.assert_array_equal(pairs, candidate_pairs(a, b, pad=pad))
    assert pairs.shape[0] > 4 * 300                     # the buffer had to grow


@pytest.mark.parametrize("surface", [sphere_band(1.5), _bumpy()], ids=["rational", "bicubic"])
def test_region_patch_boxes_equal_subpatch_boxes(surface):
    from surfprep.algorithms.intersection.culling import region_patches

    rng = np.random.default_rng(13)
    regions = patch_rectangles(surface)
    rects = _sub_rectangles(surface, rng, per_patch=5)
    region = np.repeat(np.arange(regions.shape[0]), 5)
    boxes = region_patches(surface, regions).boxes(rects, region)
    np.testing.assert_array_equal(boxes, subpatch_boxes(surface, rects))


@pytest.mark.parametrize("surface", [sphere_band(1.5), _bumpy()], ids=["rational", "bicubic"])
def test_grid_points_bitwise_equal_to_scattered_evaluation(surface):
    """The test grids of the tessellation, basis functions once per grid line, are
    bitwise the points of NurbsSurface.evaluate (so the tessellation is unchanged),
    also for rectangles across knot lines."""
    from surfprep.algorithms.basis import find_span

    rng = np.random.default_rng(5)
    a, b, c, d = surface.domain
    lo = rng.uniform(0, 0.7, (400, 2))
    span = rng.uniform(1e-6, 0.3, (400, 2))
    s = np.linspace(0.0, 1.0, 5)
    u = a + (b - a) * (lo[:, :1] + s * span[:, :1])
    v = c + (d - c) * (lo[:, 1:] + s * span[:, 1:])
    su = find_span(surface.knots_u, surface.degree_u, u.ravel()).reshape(u.shape)
    sv = find_span(surface.knots_v, surface.degree_v, v.ravel()).reshape(v.shape)
    assert np.any((su[:, 0] != su[:, -1]) | (sv[:, 0] != sv[:, -1]))
    grid = tessellation_kernels.grid_points(
        surface.knots_u, surface.knots_v, surface.degree_u, surface.degree_v,
        surface.homogeneous_points(), u, v, su, sv, surface.weights is not None)
    np.testing.assert_array_equal(grid, surface.evaluate(u[:, :, None], v[:, None, :]))


@pytest.mark.parametrize("surface", [sphere_band(1.5), _bumpy(), _high_degree()],
                         ids=["rational", "bicubic", "degree 6 x 5"])
def test_compiled_span_patches_are_the_bezier_patches(monkeypatch, surface):
    """culling.span_patches by the compiled blossoms equals its numpy form and the
    global Bézier decomposition (bezier_patches) to rounding."""
    from surfprep.algorithms.bezier import bezier_patches
    from surfprep.algorithms.intersection.culling import _spans, span_patches
    p, q = surface.degree_u, surface.degree_v
    su = _spans(surface.knots_u, p, surface.n_control[0])
    sv = _spans(surface.knots_v, q, surface.n_control[1])
    flat = np.random.default_rng(3).permutation(su.size * sv.size)
    compiled = span_patches(surface, su[flat // sv.size], sv[flat % sv.size])
    monkeypatch.setattr(tessellation_kernels, "AVAILABLE", False)
    reference = span_patches(surface, su[flat // sv.size], sv[flat % sv.size])
    scale = np.abs(reference).max()
    np.testing.assert_allclose(compiled, reference, rtol=0, atol=1e-14 * scale)
    whole = bezier_patches(surface)[0].reshape(-1, p + 1, q + 1, 4)[flat]
    np.testing.assert_allclose(compiled, whole, rtol=0, atol=1e-13 * np.abs(whole).max())
