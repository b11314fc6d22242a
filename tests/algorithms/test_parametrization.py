"""Chord-length parametrization quality (eqs. 29.1/29.2)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.parametrization import (
    MIN_INTERVALS,
    ParametrizationQuality,
    parametrization_quality,
    quality_grid,
)


def bilinear_plane(width: float = 3.0, height: float = 2.0) -> NurbsSurface:
    cp = np.array([[[0, 0, 0], [0, height, 0]], [[width, 0, 0], [width, height, 0]]], float)
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def cubic_in_u_plane() -> NurbsSurface:
    """The unit square with x = u**3: a cubic Bezier in u whose poles sit at x = 0,0,0,1."""
    xs = np.array([0.0, 0.0, 0.0, 1.0])  # Bernstein coefficients of u**3
    cp = np.zeros((4, 2, 3))
    cp[:, :, 0] = xs[:, None]
    cp[:, 1, 1] = 1.0
    return NurbsSurface(cp, [0, 0, 0, 0, 1, 1, 1, 1], [0, 0, 1, 1], 3, 1)


def test_uniform_bilinear_plane_is_perfect():
    q = parametrization_quality(bilinear_plane())
    assert isinstance(q, ParametrizationQuality)
    assert q.worst_u == pytest.approx(1.0, abs=1e-12)
    assert q.worst_v == pytest.approx(1.0, abs=1e-12)
    assert q.worst == pytest.approx(1.0, abs=1e-12)
    assert q.is_chord_length
    assert q.grid_shape == (MIN_INTERVALS + 1, MIN_INTERVALS + 1)


def test_plane_with_non_uniform_knots_but_chord_length_net_is_perfect():
    # degree 1 with knots placed at the control points' x positions: x = u exactly
    xs = np.array([0.0, 0.1, 0.5, 0.6, 1.0])
    cp = np.zeros((5, 2, 3))
    cp[:, :, 0] = xs[:, None]
    cp[:, 1, 1] = 1.0
    knots_u = np.concatenate([[0.0], xs, [1.0]])
    q = parametrization_quality(NurbsSurface(cp, knots_u, [0, 0, 1, 1], 1, 1))
    assert q.worst == pytest.approx(1.0, abs=1e-12)


def test_cubic_reparametrization_is_flagged_in_u_only():
    q = parametrization_quality(cubic_in_u_plane())
    # first interior node of 8 uniform intervals: chords 1 and 7 (in units of 1/8**3)
    assert q.worst_u == pytest.approx(7.0, rel=1e-12)
    assert q.worst_v == pytest.approx(1.0, abs=1e-12)
    assert q.worst == q.worst_u
    assert q.worst_at == q.worst_u_at
    assert q.worst_u_at[0] == pytest.approx(1 / 8)
    assert not q.is_chord_length


def test_mismatch_is_symmetric_under_parameter_reversal():
    s = cubic_in_u_plane()
    reversed_cp = s.control_points[::-1]
    r = NurbsSurface(reversed_cp, s.knots_u, s.knots_v, 3, 1)
    assert parametrization_quality(r).worst_u == pytest.approx(
        parametrization_quality(s).worst_u, rel=1e-12)


def test_collapsed_edge_is_skipped_not_divided_by_zero():
    # triangle as a degenerate bilinear patch: the v = 1 edge collapses to a point
    cp = np.array([[[0, 0, 0], [0.5, 1, 0]], [[1, 0, 0], [0.5, 1, 0]]], float)
    with np.errstate(all="raise"):
        q = parametrization_quality(NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1))
    assert math.isfinite(q.worst)
    assert q.worst == pytest.approx(1.0, abs=1e-9)


def test_fully_collapsed_surface_gives_nan():
    cp = np.ones((2, 2, 3))
    q = parametrization_quality(NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1))
    assert math.isnan(q.worst) and q.worst_at is None


def test_quality_grid_keeps_every_distinct_knot_and_has_enough_intervals():
    knots = np.array([0, 0, 0, 0, 0.1, 0.1, 0.7, 1, 1, 1, 1], float)
    grid = quality_grid(knots, 3, 7)
    assert len(grid) - 1 >= MIN_INTERVALS
    for k in (0.0, 0.1, 0.7, 1.0):
        assert np.any(grid == k)
    assert np.all(np.diff(grid) > 0)
    many = np.concatenate([[0, 0], np.linspace(0, 1, 21), [1, 1]])
    assert len(quality_grid(many, 2, len(many) - 3)) == 21  # 20 spans: no subdivision


def test_rational_surface_is_evaluated_with_weights():
    # quarter cylinder (exact rational quadratic): chord-length up to the circle's non-uniform speed
    s2 = math.sqrt(0.5)
    arc = np.array([[1, 0], [1, 1], [0, 1]], float)
    cp = np.zeros((3, 2, 3))
    cp[:, :, :2] = arc[:, None, :]
    cp[:, 1, 2] = 1.0
    w = np.array([[1, 1], [s2, s2], [1, 1]])
    q = parametrization_quality(NurbsSurface(cp, [0, 0, 0, 1, 1, 1], [0, 0, 1, 1], 2, 1, w))
    assert q.worst_v == pytest.approx(1.0, abs=1e-12)
    assert 1.0 < q.worst_u < 1.5  # the rational quarter circle's speed varies by sqrt(2)
