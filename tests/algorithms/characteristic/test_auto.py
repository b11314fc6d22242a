"""The default ``auto`` method per pair (characteristic.auto) and the crossing angle
it routes by (characteristic.crossing)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from helpers.surfaces import bumps_net, flat_crossing, height_field, horizontal_plane, near_coincident

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.characteristic import (
    FoundBy,
    Route,
    auto_intersection,
    characteristic_analysis,
    small_angle,
)
from surfprep.algorithms.intersection import (
    StrayCurves,
    connected_branches,
    curve_set_distance,
    intersect_surfaces,
)
from surfprep.algorithms.projection import distance_to_surface
from surfprep.plugin.occ_reference import intersect_surfaces_occ


def tilted_plane(angle: float) -> NurbsSurface:
    """The plane through the x axis at ``angle`` to z = 0, over [-1, 1]^2."""
    c, s = np.cos(angle), np.sin(angle)
    y = np.array([-1.0, 1.0])
    cp = np.array([[[x, yy * c, yy * s] for yy in y] for x in (-1.0, 1.0)])
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


@pytest.mark.parametrize("angle", [1e-3, 0.02, 0.3, 1.2])
def test_crossing_sine_of_two_planes_is_the_sine_of_their_angle(angle):
    flat = tilted_plane(0.0)
    analysis = characteristic_analysis(tilted_plane(angle), flat, tol=1e-9,
                                       trace_critical=False, borders=False)
    assert analysis.crossing_sine == pytest.approx(np.sin(angle), rel=1e-9)


def test_no_sign_change_no_crossing_sine():
    analysis = characteristic_analysis(horizontal_plane(0.0), horizontal_plane(0.5), tol=1e-9,
                                       trace_critical=False, borders=False)
    assert analysis.crossing_sine == np.inf


def check_within(curves, a, b, tol):
    for c in curves:
        t = c.span_parameters(8).ravel()
        p = np.concatenate([c.points, c.curve3d.evaluate(t)])
        assert distance_to_surface(a, p).max() <= tol
        assert distance_to_surface(b, p).max() <= tol


@pytest.mark.parametrize("slope", [5e-4, 5e-3])
def test_flat_crossing_goes_to_the_characteristic_method(slope):
    """Sheets crossing at 5e-4 / 5e-3 rad along a wavy line: below small_angle (0.019 at
    the default mesh tolerance) the pair goes to the characteristic method, which
    gives the one branch OpenCascade gives too (within tol everywhere; as far from
    IntSS's as points within tol of both surfaces can be at that angle, ``tol /
    slope`` per side). The triangle method alone gives nothing at 5e-4 and 5e-3, tol 1e-8
    (its refined samples fold back over the curve, and such curves are dropped): the
    reason for the route."""
    tol = 1e-8
    a, b = flat_crossing(slope)
    record = auto_intersection(a, b, tol=tol)
    assert record.extra["route"] == Route.SMALL_ANGLE.value
    assert slope < small_angle(a, b)
    assert len(record.curves) == 1 and record.found_by == (FoundBy.CHARACTERISTIC,)
    check_within(record.curves, a, b, tol)
    occ = intersect_surfaces_occ(a, b, tol)
    assert connected_branches(occ, 1e-6) == 1
    occ_tol = max(distance_to_surface(s, c.points).max() for s in (a, b) for c in occ)
    assert curve_set_distance(list(record.curves), occ).hausdorff <= \
        2 * (tol + occ_tol) / slope
    assert record.curves[0].length == pytest.approx(sum(c.length for c in occ), rel=1e-4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh = intersect_surfaces(a, b, tol=tol, stray=StrayCurves.DROP)
    assert len(mesh) != 1


@pytest.mark.parametrize("slope", [5e-4, 5e-3])
def test_flat_crossing_keeps_no_scattered_samples(slope):
    """Samples of a crossing at 5e-4 / 5e-3 rad scatter along the surfaces by
    gap / sin(angle) (1e-7 at tol 1e-9), which is no error: the cubic sampling must
    not take such a sample for a miss and keep it beside another (that gave chords of
    5e-6 among chords of 3e-3, kinks in the interpolants and extra rounds). Kept
    chords stay within a factor 4 of each other and of the median."""
    a, b = flat_crossing(slope)
    (curve,) = auto_intersection(a, b, tol=1e-9).curves
    chords = np.linalg.norm(np.diff(curve.points, axis=0), axis=1)
    assert chords.min() >= 0.25 * np.median(chords)
    check_within([curve], a, b, 1e-9)


def test_steep_pairs_keep_the_triangles_and_the_certificate():
    z = bumps_net(20, [(0.25, 0.25, 0.08, 0.5), (0.72, 0.3, 0.06, 0.45)])
    a, b = height_field(z), horizontal_plane(0.2)
    record = auto_intersection(a, b, tol=1e-9)
    assert record.extra["route"] == Route.CERTIFIED.value
    assert len(record.curves) == 2 and set(record.found_by) == {FoundBy.MESH}


def test_coincident_and_prefiltered_routes():
    a, b = near_coincident(0.0)
    assert auto_intersection(a, b, tol=1e-9).extra["route"] == Route.COINCIDENT.value
    ruled = tilted_plane(0.4)
    record = auto_intersection(ruled, horizontal_plane(0.1), tol=1e-9)
    assert record.extra["route"] == Route.PREFILTER.value and len(record.curves) == 1
