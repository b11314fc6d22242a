"""Point distributions: the spacings asked for are the spacings measured."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep import NurbsCurve
from surfprep.algorithms.grid import by_curvature, geometric, points_along, stretched, uniform
from surfprep.algorithms.measure import cumulative_arc_length
from surfprep.errors import DegenerateGeometryError, InvalidGeometryError


def _is_distribution(x, n):
    assert x.shape == (n,)
    assert x[0] == 0.0 and x[-1] == 1.0
    assert np.all(np.diff(x) > 0)


@pytest.mark.parametrize("n, first", [(41, 1e-3), (41, 1e-6), (11, 0.05), (41, 0.05), (41, 0.1)])
def test_one_sided_tanh_hits_the_first_spacing(n, first):
    x = stretched(n, first=first)
    _is_distribution(x, n)
    assert x[1] == pytest.approx(first, rel=1e-10)


@pytest.mark.parametrize("n, last", [(41, 2e-3), (21, 0.2)])
def test_one_sided_tanh_hits_the_last_spacing(n, last):
    x = stretched(n, last=last)
    _is_distribution(x, n)
    assert 1.0 - x[-2] == pytest.approx(last, rel=1e-10)


@pytest.mark.parametrize("n, first, last", [(41, 1e-3, 1e-2), (41, 0.04, 0.04), (11, 0.2, 0.3),
                                            (101, 1e-6, 1e-6), (101, 1e-6, 0.1)])
def test_two_sided_tanh_hits_both_spacings(n, first, last):
    x = stretched(n, first=first, last=last)
    _is_distribution(x, n)
    assert x[1] == pytest.approx(first, rel=1e-9)
    assert 1.0 - x[-2] == pytest.approx(last, rel=1e-9)


def test_tanh_laws_are_smooth():
    """Consecutive spacings of a stretching law change by a bounded ratio (no kink)."""
    x = stretched(81, first=1e-4, last=1e-3)
    legs = np.diff(x)
    ratio = legs[1:] / legs[:-1]
    assert np.all(ratio < 1.3) and np.all(ratio > 1 / 1.3)


def test_geometric_has_a_constant_ratio():
    x = geometric(21, growth=1.2)
    legs = np.diff(x)
    np.testing.assert_allclose(legs[1:] / legs[:-1], 1.2, rtol=1e-12)
    y = geometric(21, first=0.01)
    assert y[1] == pytest.approx(0.01, rel=1e-12)
    ratio = np.diff(y)[1:] / np.diff(y)[:-1]
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-10)
    np.testing.assert_allclose(geometric(5, growth=1.0), uniform(5))


@pytest.mark.parametrize("call, match", [
    (lambda: stretched(11), "give a first"),
    (lambda: stretched(11, first=1.5), "in \\(0, 1\\)"),
    (lambda: stretched(11, first=float("nan")), "in \\(0, 1\\)"),
    (lambda: stretched(11, first=0.6, last=0.5), "below 1"),
    (lambda: stretched(2, first=0.1), "one spacing"),
    (lambda: stretched(101, first=0.5), "round to zero"),
    (lambda: uniform(1), "at least 2"),
    (lambda: uniform(3.5), "integer"),
    (lambda: geometric(5), "exactly one"),
    (lambda: geometric(5, growth=-1.0), "positive"),
])
def test_bad_arguments_are_refused(call, match):
    with pytest.raises(InvalidGeometryError, match=match):
        call()


def _curve():
    return NurbsCurve(np.array([[0, 0, 0], [1, 2, 0], [3, -1, 0], [4, 0, 1.0]]),
                      np.array([0, 0, 0, 0, 1, 1, 1, 1.0]), 3)


def test_points_along_places_nodes_at_exact_arc_length():
    curve = _curve()
    x = stretched(31, first=0.002, last=0.01)
    t = points_along(curve, x)
    s = cumulative_arc_length(curve, t)
    np.testing.assert_allclose(s / s[-1], x, atol=1e-12)
    assert t[0] == curve.domain[0] and t[-1] == curve.domain[1]


def test_points_along_refuses_a_curve_of_zero_length():
    point = NurbsCurve(np.ones((4, 3)), np.array([0, 0, 0, 0, 1, 1, 1, 1.0]), 3)
    with pytest.raises(DegenerateGeometryError, match="zero length"):
        points_along(point, uniform(5))
    with pytest.raises(InvalidGeometryError, match="non-decreasing"):
        points_along(_curve(), [0.0, 0.6, 0.5, 1.0])


def test_curvature_law_is_denser_where_the_curve_bends():
    # a straight run, a tight bend, a straight run (quadratic B-spline through a corner)
    curve = NurbsCurve(np.array([[0, 0, 0], [4, 0, 0], [4.2, 0, 0], [4.2, 0.2, 0], [4.2, 4, 0.0]]),
                       np.array([0, 0, 0, 0.45, 0.55, 1, 1, 1.0]), 2)
    x = by_curvature(curve, 41, strength=2.0)
    _is_distribution(x, 41)
    t = points_along(curve, x)
    legs = np.diff(cumulative_arc_length(curve, t))
    d = curve.derivatives(0.5 * (t[1:] + t[:-1]), 2)
    d1, d2 = d[:, 1], d[:, 2]
    kappa = np.linalg.norm(np.cross(d1, d2), axis=1) / np.linalg.norm(d1, axis=1) ** 3
    assert legs[np.argmax(kappa)] < 0.01 * legs.max()          # the straight runs: long legs
    np.testing.assert_allclose(by_curvature(curve, 11, strength=0.0), uniform(11), atol=1e-3)
