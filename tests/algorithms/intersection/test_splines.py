"""interpolate_many (splines.py): every curve equal to its own interpolate_samples, and
SplineSet evaluation equal to NurbsCurve's, densely."""

import numpy as np
import pytest

from surfprep.algorithms.intersection.interpolants import interpolate_samples, sample_parameters
from surfprep.algorithms.intersection.splines import interpolate_many
from surfprep.errors import DegenerateGeometryError, InvalidGeometryError

CASES = [(300, True), (200, False), (3, False), (2, False), (3, True), (4, True), (50, True),
         (4, False)]


def _samples(rng, n: int) -> np.ndarray:
    th = np.sort(rng.uniform(0, 6, n))
    return np.stack([np.cos(th), np.sin(th), 0.1 * th, th, th ** 2, np.sin(3 * th), th], 1)


def test_each_curve_is_its_own_interpolant():
    rng = np.random.default_rng(0)
    values = [_samples(rng, n) for n, _ in CASES]
    closed = [c for _, c in CASES]
    params = [sample_parameters(q[:, :3], c) for q, c in zip(values, closed)]
    curves = interpolate_many(values, params, closed)
    for i, (q, t, c) in enumerate(zip(values, params, closed)):
        reference = interpolate_samples(q, t, c)
        mine = curves.curve(i)
        assert mine.degree == reference.degree
        np.testing.assert_allclose(mine.knots, reference.knots, rtol=0, atol=1e-14)
        np.testing.assert_allclose(mine.control_points, reference.control_points, rtol=0,
                                   atol=1e-12 * np.abs(reference.control_points).max())
        tt = np.linspace(t[0], t[-1], 1001)
        for order in (0, 2):
            ref = reference.derivatives(tt, order)
            np.testing.assert_allclose(curves.derivatives(np.full(tt.size, i), tt, order), ref,
                                       rtol=0, atol=1e-11 * np.abs(ref).max())
        np.testing.assert_allclose(curves.evaluate(np.full(len(q), i), t[:len(q)]), q, atol=1e-12)


def test_mixed_indices_in_one_call():
    rng = np.random.default_rng(1)
    values, closed = [_samples(rng, 40), _samples(rng, 60)], [False, True]
    params = [sample_parameters(q[:, :3], c) for q, c in zip(values, closed)]
    curves = interpolate_many(values, params, closed)
    index = rng.integers(0, 2, 500)
    t = rng.uniform(0, 1, 500) * np.array([p[-1] for p in params])[index]
    expected = np.empty((500, 7))
    for i in range(2):
        expected[index == i] = curves.curve(i).evaluate(t[index == i])
    np.testing.assert_allclose(curves.evaluate(index, t), expected, rtol=0, atol=1e-13)


def test_parameter_count_checked():
    q = np.random.default_rng(2).normal(size=(6, 7))
    with pytest.raises(InvalidGeometryError):
        interpolate_many([q], [sample_parameters(q[:, :3], False)], [True])


def test_coincident_samples_raise():
    q = np.zeros((5, 7))
    q[:, 0] = [0, 1, 1, 2, 3]
    with pytest.raises(DegenerateGeometryError):
        interpolate_many([q], [sample_parameters(q[:, :3], False)], [False])


def test_spline_set_of_curves_evaluates_each_as_its_own():
    """SplineSet.of (the certificate's closest points on known curves) against each
    NurbsCurve, derivatives to second order, with degrees mixed."""
    from surfprep.algorithms.curve import NurbsCurve
    from surfprep.algorithms.intersection.splines import SplineSet
    rng = np.random.default_rng(3)
    values = [_samples(rng, n)[:, :3] for n in (30, 12, 50)]
    closed = [False, True, False]
    params = [sample_parameters(q, c) for q, c in zip(values, closed)]
    curves = [interpolate_samples(q, t, c) for q, t, c in zip(values, params, closed)]
    curves.append(NurbsCurve(rng.normal(size=(5, 3)), [0, 0, 0, 0.3, 0.7, 1, 1, 1], 2))
    splines = SplineSet.of(curves)
    for i, c in enumerate(curves):
        lo, hi = c.domain
        t = np.linspace(lo, hi, 301)
        ref = c.derivatives(t, 2)
        np.testing.assert_allclose(splines.derivatives(np.full(t.size, i), t, 2), ref,
                                   rtol=0, atol=1e-11 * np.abs(ref).max())


def test_spline_set_of_refuses_rational_or_mixed_curves():
    from surfprep.algorithms.curve import NurbsCurve
    from surfprep.algorithms.intersection.splines import SplineSet
    line = NurbsCurve(np.array([[0.0, 0, 0], [1, 0, 0]]), [0, 0, 1, 1], 1)
    arc = NurbsCurve(np.array([[1.0, 0, 0], [1, 1, 0], [0, 1, 0]]), [0, 0, 0, 1, 1, 1], 2,
                     np.array([1, np.sqrt(0.5), 1]))
    flat = NurbsCurve(np.array([[0.0, 0], [1, 0]]), [0, 0, 1, 1], 1)
    for bad in ([], [line, arc], [line, flat]):
        with pytest.raises(InvalidGeometryError):
            SplineSet.of(bad)
