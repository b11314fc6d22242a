"""Exact isoparametric curves."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.strategies import make_surface, scale_of, surfaces
from hypothesis import given, settings
from hypothesis import strategies as st

from surfprep.algorithms import Direction, isocurve
from surfprep.errors import InvalidGeometryError


@settings(max_examples=50, deadline=None)
@given(surfaces(clamped=False) | surfaces(), st.floats(0, 1), st.booleans())
def test_isocurve_lies_on_the_surface(surface, fraction, along_u):
    u0, u1, v0, v1 = surface.domain
    if along_u:
        value = u0 + fraction * (u1 - u0)
        curve = isocurve(surface, value, Direction.U)
        t = np.linspace(v0, v1, 200)
        expected = surface.evaluate(value, t)
        assert curve.domain == (v0, v1) and curve.degree == surface.degree_v
    else:
        value = v0 + fraction * (v1 - v0)
        curve = surface.isocurve(value, Direction.V)
        t = np.linspace(u0, u1, 200)
        expected = surface.evaluate(t, value)
        assert curve.domain == (u0, u1) and curve.degree == surface.degree_u
    assert (curve.weights is None) == (surface.weights is None)
    err = np.abs(curve.evaluate(t) - expected).max()
    assert err <= 1e-12 * scale_of(surface)


def test_isocurve_at_domain_edge_is_the_boundary_row():
    surface = make_surface(2, 3, 2, 1, 1, 1, rational=True)
    u0 = surface.domain[0]
    curve = surface.isocurve(u0, "u")
    np.testing.assert_allclose(curve.control_points, surface.control_points[0], atol=1e-12)
    np.testing.assert_allclose(curve.weights, surface.weights[0], atol=1e-15)


def test_isocurve_rejects_bad_value():
    surface = make_surface(2, 3, 2, 1, 1, 1, rational=False)
    with pytest.raises(InvalidGeometryError, match="outside the domain.*direction V"):
        surface.isocurve(surface.domain[3] + 1.0, Direction.V)
    with pytest.raises(InvalidGeometryError, match="finite"):
        surface.isocurve(np.nan, Direction.U)
