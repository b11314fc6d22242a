"""Interpolation and least-squares fitting (surfprep.algorithms.fitting)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from helpers.strategies import (
    assert_same_curve,
    assert_same_surface,
    curve_samples,
    curves,
    make_surface,
    scale_of,
    surface_samples,
)
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import make_interp_spline

from surfprep.algorithms import NurbsCurve
from surfprep.algorithms.basis import greville_abscissae
from surfprep.algorithms.fitting import (
    approximate_curve,
    approximation_knots,
    averaged_knots,
    chord_length_parameters,
    interpolate_curve,
    interpolate_surface,
    knots_from_breakpoints,
)
from surfprep.errors import DegenerateGeometryError, InvalidGeometryError


@st.composite
def point_sequences(draw, min_points=2, max_points=30):
    n = draw(st.integers(min_points, max_points))
    d = draw(st.sampled_from([2, 3]))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    # a random walk: consecutive points apart, occasionally a sharp turn
    steps = rng.uniform(-1, 1, (n - 1, d)) * rng.uniform(0.05, 3.0, (n - 1, 1))
    return np.concatenate([rng.uniform(-5, 5, (1, d)), steps]).cumsum(axis=0)


# ----------------------------------------------------------------- parameters
def test_chord_length_of_collinear_points_is_proportional_to_distance():
    rng = np.random.default_rng(3)
    s = np.sort(rng.uniform(0, 7, 15))
    direction = np.array([1.0, -2.0, 0.5])
    points = np.array([4.0, 1.0, -3.0]) + s[:, None] * direction
    t = chord_length_parameters(points)
    np.testing.assert_allclose(t, (s - s[0]) / (s[-1] - s[0]), rtol=0, atol=1e-14)
    t2 = chord_length_parameters(points, interval=(2.0, 5.0))
    np.testing.assert_allclose(t2, 2 + 3 * (s - s[0]) / (s[-1] - s[0]), rtol=0, atol=1e-13)
    assert t2[0] == 2.0 and t2[-1] == 5.0
    c = chord_length_parameters(points, centripetal=True)
    root = np.concatenate([[0], np.cumsum(np.sqrt(np.diff(s) * np.linalg.norm(direction)))])
    np.testing.assert_allclose(c, root / root[-1], atol=1e-14)


def test_repeated_points_get_equal_parameters_and_all_equal_points_fail():
    points = np.array([[0, 0], [1, 0], [1, 0], [3, 0]], dtype=float)
    np.testing.assert_allclose(chord_length_parameters(points), [0, 1 / 3, 1 / 3, 1])
    with pytest.raises(DegenerateGeometryError, match="coincide"):
        chord_length_parameters(np.ones((5, 3)))


def test_averaged_knots_equation_9_8():
    t = np.array([0, 5 / 17, 9 / 17, 14 / 17, 1])       # the example of P&T 9.2.1
    k = averaged_knots(t, 3)
    np.testing.assert_allclose(k, [0, 0, 0, 0, 28 / 51, 1, 1, 1, 1])
    assert averaged_knots(t, 2, end_derivatives=True).size == t.size + 2 + 3


def test_not_a_knot_knots():
    t = np.linspace(0, 1, 8)
    np.testing.assert_allclose(knots_from_breakpoints(t, 3),
                               np.r_[[0] * 4, t[2:6], [1] * 4])
    np.testing.assert_allclose(knots_from_breakpoints(t, 3, end_condition="clamped"),
                               np.r_[[0] * 4, t[1:7], [1] * 4])


# ------------------------------------------------------------ interpolation
@settings(max_examples=60, deadline=None)
@given(point_sequences(), st.integers(1, 5), st.booleans())
def test_interpolation_passes_through_points(points, degree, centripetal):
    n = points.shape[0]
    degree = min(degree, n - 1)
    curve = interpolate_curve(points, degree=degree, centripetal=centripetal)
    t = chord_length_parameters(points, centripetal=centripetal)
    assert curve.degree == degree and curve.n_control == n
    err = np.abs(curve.evaluate(t) - points).max()
    assert err <= 1e-12 * scale_of(curve), err


@settings(max_examples=40, deadline=None)
@given(point_sequences(min_points=2), st.integers(2, 5), st.integers(0, 2**32 - 1))
def test_interpolation_with_end_derivatives(points, degree, seed):
    n, d = points.shape
    degree = min(degree, n + 1)
    derivs = np.random.default_rng(seed).uniform(-20, 20, (2, d))
    curve = interpolate_curve(points, degree=degree, end_derivatives=derivs)
    t = chord_length_parameters(points)
    scale = scale_of(curve)
    assert np.abs(curve.evaluate(t) - points).max() <= 1e-12 * scale
    np.testing.assert_allclose(curve.derivatives(t[[0, -1]], 1)[:, 1], derivs,
                               atol=1e-10 * scale)


@settings(max_examples=30, deadline=None)
@given(point_sequences(min_points=4), st.integers(0, 2**32 - 1))
def test_cubic_matches_scipy_not_a_knot_and_clamped(points, seed):
    t = chord_length_parameters(points)
    dense = np.linspace(0, 1, 301)
    ours = interpolate_curve(points, parameters=t, knots=knots_from_breakpoints(t))
    theirs = make_interp_spline(t, points, k=3)
    scale = scale_of(ours)
    assert np.abs(ours.evaluate(dense) - theirs(dense)).max() <= 1e-9 * scale
    derivs = np.random.default_rng(seed).uniform(-5, 5, (2, points.shape[1]))
    ours = interpolate_curve(points, parameters=t, end_derivatives=derivs)
    theirs = make_interp_spline(t, points, k=3, bc_type=([(1, derivs[0])], [(1, derivs[1])]))
    assert np.abs(ours.evaluate(dense) - theirs(dense)).max() <= 1e-9 * scale_of(ours)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([2, 3]), st.integers(4, 25))
def test_cubic_polynomial_is_reproduced(seed, d, n):
    rng = np.random.default_rng(seed)
    coefficients = rng.uniform(-3, 3, (4, d))
    a, b = sorted(rng.uniform(-4, 4, 2))
    b += 0.5

    def cubic(t):
        return np.polynomial.polynomial.polyval(t, coefficients).T

    t = np.sort(rng.uniform(a, b, n))
    t[0], t[-1] = a, b
    curve = interpolate_curve(cubic(t), parameters=t)
    dense = np.linspace(a, b, 500)
    scale = np.abs(cubic(dense)).max() + 1
    assert np.abs(curve.evaluate(dense) - cubic(dense)).max() <= 1e-9 * scale


@settings(max_examples=40, deadline=None)
@given(curves(max_degree=5, rational=False))
def test_bspline_curve_is_reproduced_from_greville_samples(curve):
    t = greville_abscissae(curve.knots, curve.degree)
    fitted = interpolate_curve(curve.evaluate(t), degree=curve.degree, parameters=t,
                               knots=curve.knots)
    assert_same_curve(fitted, curve, curve_samples(curve), rtol=1e-9)


def test_closed_points_close_and_smooth_closure_is_c1():
    angle = np.linspace(0, 2 * np.pi, 11)
    points = np.c_[np.cos(angle), 2 * np.sin(angle), 0.3 * np.cos(2 * angle)]
    points[-1] = points[0]
    plain = interpolate_curve(points)
    ends = plain.evaluate(np.array([0.0, 1.0]))
    np.testing.assert_array_equal(ends[0], ends[1])
    smooth = interpolate_curve(points, smooth_closure=True)
    d = smooth.derivatives(np.array([0.0, 1.0]), 1)
    np.testing.assert_array_equal(d[0, 0], d[1, 0])
    np.testing.assert_allclose(d[0, 1], d[1, 1], atol=1e-12)
    # the plain closure has a visible kink the smooth one removes
    d_plain = plain.derivatives(np.array([0.0, 1.0]), 1)
    assert np.linalg.norm(d_plain[0, 1] - d_plain[1, 1]) > 1e-3
    t = chord_length_parameters(points)
    assert np.abs(smooth.evaluate(t) - points).max() <= 1e-13



def test_smooth_closure_is_as_accurate_at_the_seam_as_inside():
    """The seam tangent of a closed interpolant is of the quartic through five samples
    (fourth-order accurate): on an ellipse sampled evenly from a seam where its
    curvature changes fastest, the spans at the seam are off the true curve by no
    more than the worst interior span (measured 0.29 of it). Bessel's parabola
    (second order) left them 7.3 times worse."""
    angle = 0.7 + np.linspace(0.0, 2 * np.pi, 40)
    points = np.c_[np.cos(angle), 0.6 * np.sin(angle)]
    points[-1] = points[0]
    t = chord_length_parameters(points)
    curve = interpolate_curve(points, parameters=t, smooth_closure=True)
    fine = np.linspace(0.0, 1.0, 40001)
    x, y = curve.evaluate(fine).T          # distance to the ellipse, F / |grad F| (first order)
    dist = np.abs(x ** 2 + (y / 0.6) ** 2 - 1) / np.hypot(2 * x, 2 * y / 0.36)
    span = np.clip(np.searchsorted(t, fine, side="right") - 1, 0, t.size - 2)
    seam = (span <= 1) | (span >= t.size - 3)
    assert dist[seam].max() <= dist[~seam].max()

# ------------------------------------------------------------------- surfaces
@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 5), st.integers(1, 5), st.integers(0, 4),
       st.integers(0, 4))
def test_surface_reproduced_from_greville_grid(seed, p, q, breaks_u, breaks_v):
    surface = make_surface(seed, p, q, breaks_u, breaks_v, max_mult=1, rational=False)
    gu = greville_abscissae(surface.knots_u, p)
    gv = greville_abscissae(surface.knots_v, q)
    fitted = interpolate_surface(surface.evaluate_grid(gu, gv), degree_u=p, degree_v=q,
                                 params_u=gu, params_v=gv, knots_u=surface.knots_u,
                                 knots_v=surface.knots_v)
    assert_same_surface(fitted, surface, *surface_samples(surface, 30), rtol=1e-9)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 12), st.integers(2, 12), st.integers(1, 4),
       st.integers(1, 4))
def test_surface_interpolation_passes_through_grid(seed, nu, nv, p, q):
    rng = np.random.default_rng(seed)
    p, q = min(p, nu - 1), min(q, nv - 1)
    x, y = np.meshgrid(np.arange(nu, dtype=float), np.arange(nv, dtype=float), indexing="ij")
    grid = np.stack([x, y, np.zeros_like(x)], axis=2) + rng.uniform(-0.3, 0.3, (nu, nv, 3))
    surface = interpolate_surface(grid, degree_u=p, degree_v=q)
    assert surface.n_control == (nu, nv)
    # the default parameters, recomputed: chord lengths averaged over the columns
    chords = np.linalg.norm(np.diff(grid, axis=0), axis=2)
    tu = np.r_[0, np.mean(np.cumsum(chords, axis=0) / chords.sum(axis=0), axis=1)]
    chords = np.linalg.norm(np.diff(grid, axis=1), axis=2).T
    tv = np.r_[0, np.mean(np.cumsum(chords, axis=0) / chords.sum(axis=0), axis=1)]
    assert np.abs(surface.evaluate_grid(tu, tv) - grid).max() <= 1e-11 * scale_of(surface)


def test_surface_with_a_pole_row():
    # points of a hemisphere: the first u-row collapses to the pole
    u = np.linspace(0, np.pi / 2, 6)
    v = np.linspace(0, np.pi, 7)
    grid = np.stack([np.outer(np.sin(u), np.cos(v)), np.outer(np.sin(u), np.sin(v)),
                     np.outer(np.cos(u), np.ones_like(v))], axis=2)
    surface = interpolate_surface(grid)
    pole = surface.evaluate_grid(np.array([0.0]), np.linspace(0, 1, 9))
    np.testing.assert_allclose(pole, np.broadcast_to([0, 0, 1.0], pole.shape), atol=1e-14)


# -------------------------------------------------------------- least squares
def test_approximation_error_decreases_with_more_control_points():
    t = np.linspace(0, 1, 400)
    points = np.c_[np.cos(5 * t), np.sin(3 * t), t ** 2]
    params = chord_length_parameters(points)
    errors = []
    for n_control in (5, 8, 12, 20, 35, 60):
        curve = approximate_curve(points, n_control)
        assert curve.n_control == n_control
        np.testing.assert_array_equal(curve.control_points[[0, -1]], points[[0, -1]])
        errors.append(np.linalg.norm(curve.evaluate(params) - points, axis=1).max())
    assert all(b < a for a, b in itertools.pairwise(errors)), errors
    assert errors[-1] < 1e-5


@settings(max_examples=30, deadline=None)
@given(point_sequences(min_points=6, max_points=40), st.integers(1, 4), st.data())
def test_approximation_is_the_least_squares_solution(points, degree, data):
    m = points.shape[0]
    # eq. 9.68 knots can leave the first span with only the (fixed) end point when
    # n_control is within degree of m; n_control == m is interpolation (eq. 9.8 knots)
    n_control = data.draw(st.one_of(st.integers(degree + 1, max(degree + 1, m - degree - 1)),
                                    st.just(m)))
    curve = approximate_curve(points, n_control, degree=degree)
    t = chord_length_parameters(points)
    # no perturbation of the interior control points lowers the squared error:
    # the gradient of sum |Q_k - C(t_k)|^2 in the interior poles vanishes
    basis = np.stack([NurbsCurve(np.eye(n_control)[:, [i]], curve.knots, degree).evaluate(t)[:, 0]
                      for i in range(n_control)], axis=1)
    residual = points - curve.evaluate(t)
    gradient = basis[:, 1:-1].T @ residual
    assert np.max(np.abs(gradient), initial=0.0) <= 1e-9 * scale_of(curve) * m
    if n_control == m:      # as many poles as points: interpolation
        assert np.abs(residual).max() <= 1e-9 * scale_of(curve)


def test_approximation_knots_hold_a_parameter_in_every_span():
    t = chord_length_parameters(np.random.default_rng(0).normal(size=(50, 3)).cumsum(axis=0))
    for n_control in (4, 10, 30, 50):
        knots = approximation_knots(t, n_control, 3)
        spans = np.unique(knots)
        counts = np.histogram(t, bins=spans)[0]
        assert np.all(counts >= 1)


# --------------------------------------------------------------------- errors
@pytest.mark.parametrize("call, error, message", [
    (lambda: interpolate_curve(np.zeros((1, 3))), InvalidGeometryError, "at least 2 points"),
    (lambda: interpolate_curve(np.ones(3)), InvalidGeometryError, r"shape \(n, d\)"),
    (lambda: interpolate_curve([[0, 0, 0], [1, np.nan, 0], [2, 0, 0]], degree=2),
     InvalidGeometryError, "NaN"),
    (lambda: interpolate_curve([[0, 0], [1, 0], [1, 0], [2, 1]], degree=2),
     DegenerateGeometryError, "points 1 and 2"),
    (lambda: interpolate_curve(np.ones((4, 2)), degree=2), DegenerateGeometryError, "coincide"),
    (lambda: interpolate_curve(np.eye(3), degree=3), InvalidGeometryError, "degree = 3 needs"),
    (lambda: interpolate_curve(np.eye(3), degree=0), InvalidGeometryError, "integer >= 1"),
    (lambda: interpolate_curve(np.eye(4), parameters=[0, 0.5, 1]), InvalidGeometryError,
     r"shape \(4,\)"),
    (lambda: interpolate_curve(np.eye(4), parameters=[0, 0.7, 0.5, 1]), InvalidGeometryError,
     "non-decreasing"),
    (lambda: interpolate_curve(np.eye(4), knots=[.5, .5, .5, .5, 2, 2, 2, 2]), InvalidGeometryError,
     "outside the knots' domain"),
    (lambda: interpolate_curve(np.eye(4), degree=1, knots=[0, 0, 0.1, 0.2, 1, 1],
                               parameters=[0, 0.5, 0.6, 1]),
     DegenerateGeometryError, "Schoenberg-Whitney"),
    (lambda: interpolate_curve(np.eye(4), smooth_closure=True), InvalidGeometryError, "closed"),
    (lambda: interpolate_curve(np.eye(4), end_derivatives=[[1, 0, 0, 0]]), InvalidGeometryError,
     "end_derivatives"),
    (lambda: knots_from_breakpoints([0, 1, 2, 3], 3, end_condition="natural"),
     InvalidGeometryError, "end_condition"),
    (lambda: interpolate_surface(np.zeros((4, 4))), InvalidGeometryError, "n_u, n_v, d"),
    (lambda: interpolate_surface(np.random.default_rng(0).normal(size=(3, 5, 3))),
     InvalidGeometryError, "degree_u = 3 needs"),
    (lambda: approximate_curve(np.eye(4), 5), InvalidGeometryError, "n_control"),
    (lambda: approximate_curve(np.eye(4), 3, degree=3), InvalidGeometryError, "degree = 3"),
])
def test_bad_input_is_refused(call, error, message):
    with pytest.raises(error, match=message):
        call()
