"""Bézier decomposition of curves and surfaces, and per-patch bounding boxes."""

from __future__ import annotations

import numpy as np
from helpers.strategies import (
    assert_same_curve,
    assert_same_surface,
    curve_samples,
    curves,
    make_curve,
    make_surface,
    scale_of,
    surfaces,
)
from hypothesis import given, settings
from scipy.special import comb

from surfprep.algorithms import (
    NurbsCurve,
    NurbsSurface,
    bezier_curves,
    bezier_patches,
    bezier_segments,
    bezier_surfaces,
    patch_bounding_boxes,
)

SETTINGS = settings(max_examples=50, deadline=None)


def bernstein(degree, s):
    """Bernstein polynomials ``(m, degree + 1)`` at local parameters ``s`` in [0, 1]."""
    k = np.arange(degree + 1)
    s = np.asarray(s)[:, None]
    return comb(degree, k) * s**k * (1 - s) ** (degree - k)


def eval_rational_bezier(coefficients_w, s):
    """Rational Bézier curve from homogeneous coefficients (p+1, d+1) by its definition."""
    hom = bernstein(coefficients_w.shape[0] - 1, s) @ coefficients_w
    return hom[:, :-1] / hom[:, -1:]


def n_spans(knots, degree):
    lo, hi = knots[degree], knots[knots.size - degree - 1]
    return np.unique(knots[(knots >= lo) & (knots <= hi)]).size - 1


@SETTINGS
@given(curves(clamped=False) | curves())
def test_segments_are_the_polynomial_pieces(curve):
    segments, intervals = bezier_segments(curve)
    k, p = n_spans(curve.knots, curve.degree), curve.degree
    assert segments.shape == (k, p + 1, curve.dimension + 1)
    assert intervals.shape == (k, 2)
    # the intervals tile the domain, in order, with the original knot values
    lo, hi = curve.domain
    assert intervals[0, 0] == lo and intervals[-1, 1] == hi
    np.testing.assert_array_equal(intervals[1:, 0], intervals[:-1, 1])
    s = np.linspace(0, 1, 25)
    for seg, (a, b) in zip(segments, intervals):
        expected = curve.evaluate(a + s * (b - a))
        got = eval_rational_bezier(seg, s)
        assert np.abs(got - expected).max() <= 1e-12 * scale_of(curve)


@SETTINGS
@given(curves())
def test_bezier_curves_cover_the_curve(curve):
    pieces = bezier_curves(curve)
    for piece in pieces:
        assert piece.degree == curve.degree
        assert (piece.weights is None) == (curve.weights is None)
        a, b = piece.domain
        assert_same_curve(piece, curve, curve_samples(curve, 30, a, b))


def test_single_bezier_curve_decomposes_to_itself():
    poles = np.random.default_rng(0).normal(size=(5, 3))
    weights = np.array([1.0, 0.5, 2.0, 0.7, 1.3])
    curve = NurbsCurve(poles, [2, 2, 2, 2, 2, 3, 3, 3, 3, 3], 4, weights)
    segments, intervals = bezier_segments(curve)
    np.testing.assert_allclose(segments[0], curve.homogeneous_points(), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(intervals, [[2.0, 3.0]])


def test_discontinuous_knot_gives_separate_segments():
    # multiplicity p + 1 = 3 at 1: the curve jumps; each side is its own segment
    poles = np.array([[0, 0], [1, 1], [2, 0], [5, 5], [6, 6], [7, 5]], dtype=float)
    curve = NurbsCurve(poles, [0, 0, 0, 1, 1, 1, 2, 2, 2], 2)
    segments, intervals = bezier_segments(curve)
    np.testing.assert_array_equal(intervals, [[0, 1], [1, 2]])
    np.testing.assert_allclose(segments[0, :, :2], poles[:3])
    np.testing.assert_allclose(segments[1, :, :2], poles[3:])


@settings(max_examples=30, deadline=None)
@given(surfaces(clamped=False) | surfaces())
def test_patches_are_the_polynomial_pieces(surface):
    patches, int_u, int_v = bezier_patches(surface)
    p, q = surface.degree_u, surface.degree_v
    ku, kv = n_spans(surface.knots_u, p), n_spans(surface.knots_v, q)
    assert patches.shape == (ku, kv, p + 1, q + 1, 4)
    assert int_u.shape == (ku, 2) and int_v.shape == (kv, 2)
    s = np.linspace(0, 1, 8)
    bu, bv = bernstein(p, s), bernstein(q, s)
    for i, (a, b) in enumerate(int_u):
        for j, (c, d) in enumerate(int_v):
            hom = np.einsum("ai,bj,ijc->abc", bu, bv, patches[i, j])
            got = hom[..., :3] / hom[..., 3:]
            expected = surface.evaluate_grid(a + s * (b - a), c + s * (d - c))
            assert np.abs(got - expected).max() <= 1e-12 * scale_of(surface)


@settings(max_examples=20, deadline=None)
@given(surfaces(max_degree=4))
def test_bezier_surfaces_cover_the_surface(surface):
    grid = bezier_surfaces(surface)
    for row in grid:
        for patch in row:
            u0, u1, v0, v1 = patch.domain
            assert_same_surface(patch, surface, np.linspace(u0, u1, 10),
                                np.linspace(v0, v1, 10))


@settings(max_examples=30, deadline=None)
@given(surfaces())
def test_patch_boxes_contain_their_patches(surface):
    boxes, int_u, int_v = patch_bounding_boxes(surface)
    assert boxes.shape == (int_u.shape[0], int_v.shape[0], 2, 3)
    assert np.all(boxes[:, :, 0] <= boxes[:, :, 1])
    tol = 1e-12 * scale_of(surface)
    for i, (a, b) in enumerate(int_u):
        for j, (c, d) in enumerate(int_v):
            points = surface.evaluate_grid(np.linspace(a, b, 12), np.linspace(c, d, 12))
            assert np.all(points >= boxes[i, j, 0] - tol)
            assert np.all(points <= boxes[i, j, 1] + tol)
    # every patch box lies in the box of the whole net (the decomposition is local)
    whole = surface.bounding_box()
    assert np.all(boxes[:, :, 0] >= whole[0] - tol) and np.all(boxes[:, :, 1] <= whole[1] + tol)


def test_patch_boxes_are_tight_for_a_bilinear_patch_grid():
    # bilinear surface z = 0 over [0,3]x[0,2] with knots at integers: each patch is a unit square
    x, y = np.meshgrid(np.arange(4.0), np.arange(3.0), indexing="ij")
    net = np.stack([x, y, np.zeros_like(x)], axis=2)
    surface = NurbsSurface(net, [0, 0, 1, 2, 3, 3], [0, 0, 1, 2, 2], 1, 1)
    boxes, _, _ = patch_bounding_boxes(surface)
    i, j = np.meshgrid(np.arange(3.0), np.arange(2.0), indexing="ij")
    np.testing.assert_array_equal(boxes[:, :, 0, 0], i)
    np.testing.assert_array_equal(boxes[:, :, 1, 0], i + 1)
    np.testing.assert_array_equal(boxes[:, :, 0, 1], j)
    np.testing.assert_array_equal(boxes[:, :, 1, 1], j + 1)


def test_facade_methods():
    curve = make_curve(4, 3, 2, 2, rational=True)
    seg, intervals = curve.bezier_segments()
    assert seg.shape[0] == intervals.shape[0] == n_spans(curve.knots, 3)
    surface = make_surface(4, 2, 3, 1, 2, 2, rational=True)
    patches, int_u, int_v = surface.bezier_patches()
    boxes, _, _ = surface.patch_bounding_boxes()
    assert boxes.shape[:2] == patches.shape[:2] == (int_u.shape[0], int_v.shape[0])
