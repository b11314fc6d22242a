"""Degree elevation of curves and surfaces."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.strategies import (
    assert_same_curve,
    assert_same_surface,
    curve_samples,
    curves,
    make_curve,
    surface_samples,
    surfaces,
)
from hypothesis import given, settings
from hypothesis import strategies as st

from surfprep.algorithms import NurbsCurve, bezier_elevation_matrix, elevate_degree, elevate_degree_surface
from surfprep.errors import InvalidGeometryError


def interior_multiplicities(knots, degree):
    n = knots.size - degree - 1
    lo, hi = knots[degree], knots[n]
    values, counts = np.unique(knots[(knots > lo) & (knots < hi)], return_counts=True)
    return values, counts


@settings(max_examples=80, deadline=None)
@given(curves(clamped=False) | curves(), st.integers(1, 3))
def test_elevation_keeps_geometry_and_raises_multiplicities(curve, t):
    result = elevate_degree(curve, t)
    assert result.degree == curve.degree + t
    assert result.domain == curve.domain
    assert (result.weights is None) == (curve.weights is None)
    values, counts = interior_multiplicities(curve.knots, curve.degree)
    new_values, new_counts = interior_multiplicities(result.knots, result.degree)
    np.testing.assert_array_equal(new_values, values)
    np.testing.assert_array_equal(new_counts, counts + t)
    # clamped ends of multiplicity p + t + 1
    assert np.all(result.knots[:result.degree + 1] == curve.domain[0])
    assert np.all(result.knots[-result.degree - 1:] == curve.domain[1])
    assert_same_curve(result, curve, curve_samples(curve))


@pytest.mark.parametrize("degree", range(1, 10))
@pytest.mark.parametrize("rational", [False, True])
def test_every_degree_elevates_exactly(degree, rational):
    curve = make_curve(100 + degree, degree, 4, degree, rational)
    result = elevate_degree(curve, 2)
    assert result.n_control == curve.n_control + 2 * (np.unique(curve.knots).size - 1)
    assert_same_curve(result, curve, curve_samples(curve))
    # derivatives agree too: the parametrization is unchanged
    t = np.linspace(*curve.domain, 57)
    d0, d1 = curve.derivatives(t, 1)[:, 1], result.derivatives(t, 1)[:, 1]
    assert np.abs(d0 - d1).max() <= 1e-9 * (np.abs(d0).max() + 1)


def test_elevated_line_has_evenly_spaced_poles():
    # a degree-1 segment raised to degree 3 has poles at thirds (exact Bezier elevation)
    curve = NurbsCurve([[0.0, 0.0], [3.0, 6.0]], [1, 1, 2, 2], 1)
    result = elevate_degree(curve, 2)
    np.testing.assert_allclose(result.control_points, [[0, 0], [1, 2], [2, 4], [3, 6]],
                               atol=1e-14)
    np.testing.assert_array_equal(result.knots, [1, 1, 1, 1, 2, 2, 2, 2])


def test_discontinuous_curve_is_elevated_piecewise():
    poles = np.array([[0, 0], [1, 1], [2, 0], [5, 5], [6, 6], [7, 5]], dtype=float)
    curve = NurbsCurve(poles, [0, 0, 0, 1, 1, 1, 2, 2, 2], 2, np.linspace(1, 2, 6))
    result = elevate_degree(curve, 1)
    assert np.count_nonzero(result.knots == 1.0) == 4
    assert_same_curve(result, curve, curve_samples(curve))
    np.testing.assert_allclose(result.evaluate(1 - 1e-13), poles[2], atol=1e-9)


@pytest.mark.parametrize("degree, t", [(1, 1), (3, 2), (5, 4), (2, 7)])
def test_bezier_elevation_matrix_is_affine_and_interpolates_ends(degree, t):
    e = bezier_elevation_matrix(degree, t)
    assert e.shape == (degree + t + 1, degree + 1)
    np.testing.assert_allclose(e.sum(axis=1), 1.0, atol=1e-15)
    assert np.all(e >= 0)
    assert e[0, 0] == 1.0 and e[-1, -1] == 1.0


@settings(max_examples=40, deadline=None)
@given(surfaces(max_degree=5), st.integers(0, 2), st.integers(0, 2))
def test_surface_elevation_keeps_geometry(surface, t_u, t_v):
    result = elevate_degree_surface(surface, t_u, t_v)
    assert (result.degree_u, result.degree_v) == (surface.degree_u + t_u,
                                                  surface.degree_v + t_v)
    assert result.domain == surface.domain
    assert_same_surface(result, surface, *surface_samples(surface))


def test_surface_facade_and_errors():
    from helpers.strategies import make_surface
    surface = make_surface(9, 2, 3, 2, 1, 2, rational=True)
    result = surface.elevate_degree(1, 2)
    assert (result.degree_u, result.degree_v) == (3, 5)
    assert_same_surface(result, surface, *surface_samples(surface))
    with pytest.raises(InvalidGeometryError, match="integer >= 0"):
        surface.elevate_degree(-1, 0)
    curve = make_curve(1, 2, 1, 1, False)
    with pytest.raises(InvalidGeometryError, match="integer >= 1"):
        curve.elevate_degree(0)
    with pytest.raises(InvalidGeometryError, match="integer >= 1"):
        curve.elevate_degree(1.5)


@pytest.mark.parametrize("degrees", [(9, 1), (1, 9), (7, 8)])
def test_high_degree_surface_elevation(degrees):
    from helpers.strategies import make_surface
    surface = make_surface(sum(degrees), *degrees, 2, 1, 3, rational=True)
    result = surface.elevate_degree(1, 1)
    assert_same_surface(result, surface, *surface_samples(surface))
