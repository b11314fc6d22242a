"""Curves of critical points (ridges.py): a torus cut by planes normal to its axis.

phi on the torus is constant along its circles of latitude (phi_u = 0
identically), so the critical points form ridges (the top and bottom circles).
Exact answers: the plane z = minor - gap meets the torus (major R, minor r) in
the circles of radii R +- sqrt(r^2 - (r - gap)^2) (gap > 0), touches it along
the top circle (gap = 0), misses it (gap < 0).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from helpers.surfaces import torus, torus_and_plane

from surfprep.algorithms.characteristic import FoundBy, certify
from surfprep.algorithms.intersection import EndKind

TOL = 1e-9
MAJOR, MINOR = 1.0, 0.3


def test_torus_is_exact():
    t = torus(MAJOR, MINOR)
    u, v = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 41))
    p = t.evaluate(u.ravel(), v.ravel())
    rho = np.hypot(p[:, 0], p[:, 1])
    np.testing.assert_allclose(np.hypot(rho - MAJOR, p[:, 2]), MINOR, atol=1e-14)


def radii_and_heights(curve, n=400):
    """Radius about the axis and height of a dense sample of the curve's interpolant."""
    t = np.linspace(curve.parameters[0], curve.parameters[-1], n)
    p = curve.curve3d.evaluate(t)
    return np.hypot(p[:, 0], p[:, 1]), p[:, 2]


@pytest.mark.parametrize("gap", [1e-2, 1e-6])
def test_certificate_alone_finds_both_circles_beside_the_top_ridge(gap):
    """With no curve given, the ridge of maxima (phi = gap > tol) makes the certificate
    start rays across it and trace the two circles flanking it; each is checked
    densely against its exact radius and height."""
    a, b = torus_and_plane(gap, MAJOR, MINOR)
    rec = certify(a, b, [], tol=TOL)
    assert len(rec.curves) == 2
    assert all(f is FoundBy.CHARACTERISTIC for f in rec.found_by)
    half = np.sqrt(MINOR ** 2 - (MINOR - gap) ** 2)
    found = []
    for c in rec.curves:
        rho, z = radii_and_heights(c)
        np.testing.assert_allclose(z, MINOR - gap, atol=10 * TOL)
        found.append(rho.mean())
        target = MAJOR + half if rho.mean() > MAJOR else MAJOR - half
        # a point within tol of both surfaces: radial error <= tol / sin(angle)
        assert np.abs(rho - target).max() <= 1e-6 * max(1.0, 1e-3 / half)
    assert min(found) < MAJOR < max(found)


def test_tangent_plane_gives_one_tangential_curve_not_fragments():
    """gap = 0: the plane touches the torus along its top circle. The certificate
    reports that circle as one curve (the triangle method's fragments along it are
    replaced) and returns quickly."""
    a, b = torus_and_plane(0.0, MAJOR, MINOR)
    rec = certify(a, b, [], tol=TOL)
    assert len(rec.curves) == 1
    c = rec.curves[0]
    rho, z = radii_and_heights(c)
    np.testing.assert_allclose(z, MINOR, atol=TOL)
    # along a tangency a point within tol of both surfaces may sit sqrt(2 r tol) off
    assert np.abs(rho - MAJOR).max() <= np.sqrt(2 * MINOR * TOL) * 1.5
    # the whole circle: it ends on the seam sides (u = 0 and u = 1 of the torus)
    assert np.ptp(c.uv_a[:, 0]) > 0.99
    assert c.start_kind is EndKind.BOUNDARY and c.end_kind is EndKind.BOUNDARY
    counts = rec.counts()
    assert counts.get("cusp", 0) >= 1


def test_plane_above_the_torus_meets_nothing():
    a, b = torus_and_plane(-1e-3, MAJOR, MINOR)
    rec = certify(a, b, [], tol=TOL)
    assert rec.curves == () and rec.isolated_points == ()


@pytest.mark.slow
def test_triangle_fragments_along_the_top_circle_are_replaced_by_it():
    """The triangle method leaves fragments along the tangential top circle; the
    certificate drops every one of them (each lies along the circle) and reports the
    circle once."""
    from surfprep.algorithms.intersection import (
        SmallAngleWarning,
        StrayCurves,
        StrayCurveWarning,
        intersect_surfaces,
    )

    a, b = torus_and_plane(0.0, MAJOR, MINOR)
    with warnings.catch_warnings():
        # some fragments along the tangential circle stray or fold and are left out
        # (what the triangle method can do here; the certificate replaces them all)
        warnings.simplefilter("ignore", StrayCurveWarning)
        with pytest.warns(SmallAngleWarning):     # the triangle method says it may fail
            mesh = intersect_surfaces(a, b, tol=TOL, stray=StrayCurves.DROP)
    assert len(mesh) > 1
    rec = certify(a, b, mesh, tol=TOL)
    assert rec.dropped == len(mesh)
    assert len(rec.curves) == 1 and rec.found_by == (FoundBy.CHARACTERISTIC,)
    rho, z = radii_and_heights(rec.curves[0])
    np.testing.assert_allclose(z, MINOR, atol=TOL)
    assert np.abs(rho - MAJOR).max() <= np.sqrt(2 * MINOR * TOL) * 1.5
    # a curve of the triangle method away from the circle is kept: the plane lowered
    # a little cuts two circles, neither along a tangential curve
    a, b = torus_and_plane(1e-3, MAJOR, MINOR)
    mesh = intersect_surfaces(a, b, tol=TOL, stray=StrayCurves.DROP)
    rec = certify(a, b, mesh, tol=TOL)
    assert rec.dropped == 0 and len(rec.curves) >= len(mesh) > 0


def test_triangle_method_told_the_tangential_curve_leaves_out_its_fragments():
    """intersect_surfaces(tangential=...): given the traced top circle (the analysis's
    tangential ridge), the triangle method returns none of its fragments along it (so
    no marching and no retries on them), and the certificate then reports the circle;
    curves away from a given tangential curve are kept (the plane 1e-2 lower, told the
    top circle, still gives its two circles)."""
    from surfprep.algorithms.characteristic import characteristic_analysis, tangential_curves
    from surfprep.algorithms.intersection import SmallAngleWarning, StrayCurves, intersect_surfaces

    a, b = torus_and_plane(0.0, MAJOR, MINOR)
    analysis = characteristic_analysis(a, b, tol=TOL, trace_critical=False, borders=False)
    top = tangential_curves(analysis, TOL)
    assert len(top) == 1
    with pytest.warns(SmallAngleWarning):
        mesh = intersect_surfaces(a, b, tol=TOL, stray=StrayCurves.DROP, tangential=top)
    assert mesh == []
    rec = certify(a, b, mesh, tol=TOL, analysis=analysis, tangential=top)
    assert len(rec.curves) == 1 and rec.found_by == (FoundBy.CHARACTERISTIC,)
    lower, plane = torus_and_plane(1e-2, MAJOR, MINOR)
    kept = intersect_surfaces(lower, plane, tol=TOL, stray=StrayCurves.DROP, tangential=top)
    assert len(kept) == 2
    half = np.sqrt(MINOR ** 2 - (MINOR - 1e-2) ** 2)
    np.testing.assert_allclose(sorted(radii_and_heights(c)[0].mean() for c in kept),
                               [MAJOR - half, MAJOR + half], atol=1e-6)


def test_tangential_curve_samples_lie_on_the_ridge_and_are_few():
    """New samples of the tangential top circle are put on the ridge (the lateral
    corrector of its characteristic curve), not anywhere in the band of points within
    tol of both surfaces (sqrt(2 r tol) = 2.4e-5 wide): at tol 1e-9 the interpolant
    lies on the circle to 5e-10 (5.8e-6 while samples scattered in the band) with a
    few times the samples the C2 cubic needs for a circle of that radius (813; it
    was 12 465)."""
    tol = 1e-9
    a, b = torus_and_plane(0.0, MAJOR, MINOR)
    (c,) = certify(a, b, [], tol=tol).curves
    rho, z = radii_and_heights(c)
    assert np.abs(rho - MAJOR).max() <= tol
    radius = MAJOR
    h = (384 * 0.5 * tol * radius ** 3) ** 0.25            # the cubic's interior spacing
    assert c.points.shape[0] <= 4 * (2 * np.pi * radius / h)
    assert c.max_deviation(a, b, 16).max <= tol
