"""The triangle method's small-angle limit (algorithms.intersection.angles) and its warning."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from helpers.surfaces import flat_crossing

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection import SmallAngleWarning, StrayCurves, intersect_surfaces
from surfprep.algorithms.intersection.angles import normal_sines, small_crossing_sine


def plane(angle: float) -> NurbsSurface:
    c, s = np.cos(angle), np.sin(angle)
    cp = np.array([[[x, y * c, y * s] for y in (-1.0, 1.0)] for x in (-1.0, 1.0)])
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def test_limit_follows_the_square_root_of_the_mesh_tolerance():
    assert small_crossing_sine(2.0, 2e-3) == pytest.approx(0.6 * np.sqrt(1e-3))
    assert small_crossing_sine(2.0, 2e-5) == pytest.approx(0.06 * np.sqrt(1e-3))


@pytest.mark.parametrize("angle", [1e-3, 0.1, 1.0])
def test_soup_sine_of_two_planes(angle):
    uv = np.random.default_rng(0).uniform(0, 1, (20, 2))
    np.testing.assert_allclose(normal_sines(plane(angle), plane(0.0), uv, uv),
                               np.sin(angle), rtol=1e-12)


def _small_angle_warnings(a, b) -> list:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        intersect_surfaces(a, b, tol=1e-8, stray=StrayCurves.DROP)
    return [w for w in caught if issubclass(w.category, SmallAngleWarning)]


def test_a_flat_crossing_is_warned_about_a_steep_one_not():
    """Sheets crossing at 5e-3 rad (the triangle method returns nothing there at tol
    1e-8) give a SmallAngleWarning naming the angle; at 0.1 rad none."""
    (w,) = _small_angle_warnings(*flat_crossing(5e-3))
    assert "about 0.0048 rad" in str(w.message) and "auto" in str(w.message)
    assert _small_angle_warnings(*flat_crossing(0.1)) == []


def test_a_double_point_is_not_a_flat_crossing():
    """Equal-radius cylinders cross with parallel normals at their two double points, but
    only over a short stretch round them: no warning."""
    from helpers.occ_shapes import cylinder
    assert _small_angle_warnings(cylinder(1.0, 1.5), cylinder(1.0, 2.0, normal=(1, 0, 0))) == []


def test_a_curve_running_over_itself_is_not_returned():
    """At 5e-3 rad the triangle method's refined samples land on one stretch of the
    curve twice (a fold): every point within tol of both surfaces, but the curve 20 %
    longer than the intersection (1.21-1.26 against 1.0189). Such a curve is left out
    with a StrayCurveWarning (or raised), never returned."""
    from surfprep.algorithms.characteristic import auto_intersection
    from surfprep.algorithms.intersection import StrayCurveWarning
    from surfprep.errors import InvalidGeometryError
    a, b = flat_crossing(5e-3)
    (exact,) = auto_intersection(a, b, tol=1e-8).curves
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        curves = intersect_surfaces(a, b, tol=1e-8, stray=StrayCurves.DROP)
    assert sum(c.length for c in curves) <= exact.length * (1 + 1e-4)
    if not curves:
        assert any(issubclass(w.category, StrayCurveWarning) and "fold" in str(w.message)
                   for w in caught)
        with pytest.raises(InvalidGeometryError, match="fold back"):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", SmallAngleWarning)
                intersect_surfaces(a, b, tol=1e-8)
