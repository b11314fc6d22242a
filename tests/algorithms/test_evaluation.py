"""The NURBS core: basis functions, evaluation, derivatives, grids, validation."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.strategies import curve_samples, curves, make_curve, scale_of, surfaces
from hypothesis import given, settings
from scipy.interpolate import BSpline

from surfprep.algorithms import NurbsCurve, NurbsSurface
from surfprep.algorithms.basis import (
    basis_derivatives,
    collocation_matrix,
    find_span,
    greville_abscissae,
    span_range,
    validate_knots,
)
from surfprep.errors import InvalidGeometryError

SETTINGS = settings(max_examples=60, deadline=None)


@SETTINGS
@given(curves())
def test_partition_of_unity_and_zero_derivative_sum(curve):
    t = curve_samples(curve, 100)
    matrix = collocation_matrix(curve.knots, curve.degree, t)
    np.testing.assert_allclose(matrix.sum(axis=1), 1.0, atol=1e-13)
    assert np.all(matrix >= -1e-15)
    ders, span = basis_derivatives(curve.knots, curve.degree, t, 2)
    np.testing.assert_allclose(ders[:, 1:].sum(axis=2), 0.0,
                               atol=1e-9 * (np.abs(ders).max() + 1))
    assert np.all((span >= curve.degree) & (span <= curve.n_control - 1))


@SETTINGS
@given(curves(rational=False, clamped=False) | curves(rational=False))
def test_polynomial_curve_matches_scipy_bspline(curve):
    t = curve_samples(curve)
    reference = BSpline(curve.knots, curve.control_points, curve.degree)
    np.testing.assert_allclose(curve.evaluate(t), reference(t), rtol=0,
                               atol=1e-12 * scale_of(curve))
    d_ref = reference.derivative()(t)
    np.testing.assert_allclose(curve.derivatives(t, 1)[:, 1], d_ref, rtol=0,
                               atol=1e-10 * (np.abs(d_ref).max() + 1))


@SETTINGS
@given(curves(rational=True))
def test_rational_curve_is_projection_of_homogeneous_spline(curve):
    t = curve_samples(curve)
    hom = BSpline(curve.knots, curve.homogeneous_points(), curve.degree)(t)
    np.testing.assert_allclose(curve.evaluate(t), hom[:, :-1] / hom[:, -1:], rtol=0,
                               atol=1e-12 * scale_of(curve))


def _away_from_knots(knots, t, gap):
    distance = np.abs(t[:, None] - knots[None, :]).min(axis=1)
    return t[distance > gap]


def _richardson(f, x, h):
    """Central difference of ``f`` at ``x`` with Richardson extrapolation: the
    h^2 truncation term cancels, the error is O(h^4) (tiny knot spans make the
    plain central difference's h^2 term large)."""
    d_h = (f(x + h) - f(x - h)) / (2 * h)
    d_h2 = (f(x + h / 2) - f(x - h / 2)) / h
    return (4 * d_h2 - d_h) / 3


@SETTINGS
@given(curves(max_degree=6))
def test_curve_derivatives_match_finite_differences(curve):
    lo, hi = curve.domain
    h = 1e-4 * (hi - lo)
    t = _away_from_knots(curve.knots, np.linspace(lo, hi, 41)[1:-1], 3 * h)
    d = curve.derivatives(t, 2)
    fd1 = _richardson(curve.evaluate, t, h)
    fd2 = _richardson(lambda x: curve.derivatives(x, 1)[:, 1], t, h)
    np.testing.assert_allclose(d[:, 1], fd1, rtol=0, atol=1e-6 * (np.abs(d[:, 1]).max() + 1))
    np.testing.assert_allclose(d[:, 2], fd2, rtol=0, atol=1e-6 * (np.abs(d[:, 2]).max() + 1))


@settings(max_examples=40, deadline=None)
@given(surfaces(max_degree=4))
def test_surface_derivatives_match_finite_differences(surface):
    u0, u1, v0, v1 = surface.domain
    hu, hv = 1e-4 * (u1 - u0), 1e-4 * (v1 - v0)
    u = _away_from_knots(surface.knots_u, np.linspace(u0, u1, 9)[1:-1], 3 * hu)
    v = _away_from_knots(surface.knots_v, np.linspace(v0, v1, 9)[1:-1], 3 * hv)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    d = surface.derivatives(uu, vv, 1)
    su = _richardson(lambda x: surface.evaluate(x, vv), uu, hu)
    sv = _richardson(lambda y: surface.evaluate(uu, y), vv, hv)
    suv = _richardson(lambda y: surface.derivatives(uu, y, 1)[..., 1, 0, :], vv, hv)
    for got, expected in ((d[..., 1, 0, :], su), (d[..., 0, 1, :], sv), (d[..., 1, 1, :], suv)):
        np.testing.assert_allclose(got, expected, rtol=0,
                                   atol=1e-6 * (np.abs(got).max() + 1))


@settings(max_examples=40, deadline=None)
@given(surfaces())
def test_grid_equals_scattered(surface):
    u = np.linspace(*surface.domain[:2], 13)
    v = np.linspace(*surface.domain[2:], 11)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    grid = surface.derivatives_grid(u, v, 2)
    scattered = surface.derivatives(uu, vv, 2)
    assert grid.shape == scattered.shape == (13, 11, 3, 3, 3)
    np.testing.assert_allclose(grid, scattered, rtol=1e-12,
                               atol=1e-12 * (np.abs(scattered).max() + 1))


def test_empty_parameter_arrays():
    net = np.random.default_rng(0).random((5, 4, 3))
    knots_u, knots_v = [0, 0, 0, 0, 0.5, 1, 1, 1, 1], [0, 0, 0, 0, 1, 1, 1, 1]
    for weights in (None, np.full((5, 4), 2.0)):
        s = NurbsSurface(net, knots_u, knots_v, 3, 3, weights)
        assert s.derivatives(np.zeros(0), np.zeros(0), 2).shape == (0, 3, 3, 3)
        assert s.evaluate(np.zeros((0, 4)), 0.5).shape == (0, 4, 3)


def test_find_span_at_domain_ends_and_outside():
    knots = np.array([0, 0, 0, 1, 2, 2, 3, 3, 3], dtype=float)
    span = find_span(knots, 2, np.array([-1.0, 0.0, 0.5, 1.0, 2.0, 3.0, 4.0]))
    np.testing.assert_array_equal(span, [2, 2, 2, 3, 5, 5, 5])


def test_span_range_skips_empty_end_spans():
    # the domain's first span is empty when a knot at the start repeats degree + 2 times
    assert span_range(np.array([0, 0, 0, 1, 2, 2, 3, 3, 3], dtype=float), 2) == (2, 5)
    knots = np.array([0, 0, 0, 0, 1, 2, 2, 2], dtype=float)
    assert span_range(knots, 2) == (3, 4)
    np.testing.assert_array_equal(find_span(knots, 2, np.array([-1.0, 0.0, 1.5, 2.0, 9.0])),
                                  [3, 3, 4, 4, 4])


def test_greville_abscissae_reproduce_a_line():
    # sum_i g_i N_i(t) = t for the Greville abscissae g_i
    curve = make_curve(5, 4, 3, 2, rational=False)
    g = greville_abscissae(curve.knots, curve.degree)
    line = NurbsCurve(g[:, None], curve.knots, curve.degree)
    t = curve_samples(curve)
    np.testing.assert_allclose(line.evaluate(t)[:, 0], t, atol=1e-12 * (np.abs(t).max() + 1))


def test_arrays_are_read_only_copies():
    points = np.zeros((4, 3))
    curve = NurbsCurve(points, [0, 0, 0, 0, 1, 1, 1, 1], 3)
    points[0, 0] = 5.0
    assert curve.control_points[0, 0] == 0.0
    with pytest.raises(ValueError):
        curve.control_points[0, 0] = 1.0


@pytest.mark.parametrize("kwargs, match", [
    (dict(knots=[0, 0, 0, 0.5, 1, 1, 1]), "expected n_control"),
    (dict(knots=[0, 0, 0, 1, 0.5, 1, 1, 1]), "non-decreasing"),
    (dict(knots=[0, 0, 0, np.nan, 1, 1, 1, 1]), "NaN"),
    (dict(knots=[0, 0, 0, 0, 0, 0, 0, 0]), "empty parameter domain"),
    (dict(weights=[1, 1, -1, 1, 1]), "> 0"),
    (dict(weights=[1, 1, 1, 1]), "shape"),
    (dict(weights=[1, 1, np.nan, 1, 1]), "finite"),
    (dict(points=np.zeros(5)), "shape"),
    (dict(points=np.full((5, 2), np.nan)), "NaN"),
    (dict(degree=0), "degree"),
    (dict(degree=2.5), "degree"),
])
def test_curve_validation(kwargs, match):
    args = dict(points=np.zeros((5, 2)), knots=[0, 0, 0, 0.4, 0.6, 1, 1, 1], degree=2,
                weights=None)
    args.update(kwargs)
    with pytest.raises(InvalidGeometryError, match=match):
        NurbsCurve(args["points"], args["knots"], args["degree"], args["weights"])


@pytest.mark.parametrize("kwargs, match", [
    (dict(knots_u=[0, 0, 1, 1, 1]), "knots_u"),
    (dict(knots_v=[0, 0, 0.5, 1]), "knots_v"),
    (dict(weights=np.ones((3, 3))), "shape"),
    (dict(weights=-np.ones((2, 3))), "> 0"),
    (dict(points=np.zeros((2, 3))), "shape"),
])
def test_surface_validation(kwargs, match):
    args = dict(points=np.zeros((2, 3, 3)), knots_u=[0, 0, 1, 1],
                knots_v=[0, 0, 0.5, 1, 1], weights=None)
    args.update(kwargs)
    with pytest.raises(InvalidGeometryError, match=match):
        NurbsSurface(args["points"], args["knots_u"], args["knots_v"], 1, 1, args["weights"])


def test_from_homogeneous_round_trip():
    curve = make_curve(8, 3, 2, 1, rational=True)
    again = NurbsCurve.from_homogeneous(curve.homogeneous_points(), curve.knots, 3)
    t = curve_samples(curve)
    np.testing.assert_allclose(again.evaluate(t), curve.evaluate(t), rtol=1e-14, atol=1e-13)
    with pytest.raises(InvalidGeometryError, match="> 0"):
        NurbsCurve.from_homogeneous(-curve.homogeneous_points(), curve.knots, 3)


def test_interior_knot_multiplicity_over_degree_plus_one_is_refused():
    """degree + 1 equal interior knots (a break of the curve) pass; degree + 2 do not,
    and the message gives the multiplicity."""
    ok = np.array([0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1], dtype=float)
    np.testing.assert_array_equal(validate_knots(ok, 2, 6), ok)
    bad = np.array([0, 0, 0, 0.5, 0.5, 0.5, 0.5, 1, 1, 1], dtype=float)
    with pytest.raises(InvalidGeometryError, match=r"multiplicity 4 > degree \+ 1 = 3"):
        validate_knots(bad, 2, 7)
    # clamped ends of multiplicity degree + 1 are not interior
    validate_knots(np.array([0, 0, 0, 1, 1, 1], dtype=float), 2, 3)
