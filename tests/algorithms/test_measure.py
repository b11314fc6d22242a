"""Bounding boxes, surface normals and arc length."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.strategies import curve_samples, curves, make_curve, scale_of, surfaces
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from surfprep.algorithms import (
    NurbsCurve,
    NurbsSurface,
    arc_length,
    bounding_box,
    cumulative_arc_length,
    normal_turn,
    normals,
)
from surfprep.errors import DegenerateGeometryError, InvalidGeometryError, InvalidToleranceError

S2 = np.sqrt(0.5)


def nurbs_circle(radius=1.0, center=(0.0, 0.0, 0.0)):
    """Full circle in the xy plane: rational quadratic, 9 poles, domain [0, 4] (P&T 7.5)."""
    square = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1],
                       [1, -1], [1, 0]], dtype=float)
    points = np.concatenate([square * radius, np.zeros((9, 1))], axis=1) + center
    weights = np.array([1, S2, 1, S2, 1, S2, 1, S2, 1])
    knots = [0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4]
    return NurbsCurve(points, knots, 2, weights)


def nurbs_sphere(radius=1.0, center=(0.0, 0.0, 0.0)):
    """Sphere: u the longitude (full circle), v the latitude (half circle from -z to +z)."""
    circle = nurbs_circle()
    # meridian half circle in the (r, z) plane from the south pole to the north pole
    meridian = np.array([[0, -1], [1, -1], [1, 0], [1, 1], [0, 1]], dtype=float)
    w_v = np.array([1, S2, 1, S2, 1])
    ring = circle.control_points[:, :2]
    net = np.empty((9, 5, 3))
    net[:, :, :2] = ring[:, None, :] * meridian[None, :, 0, None]
    net[:, :, 2] = meridian[None, :, 1]
    weights = circle.weights[:, None] * w_v[None, :]
    return NurbsSurface(net * radius + np.asarray(center), circle.knots,
                        [0, 0, 0, 1, 1, 2, 2, 2], 2, 2, weights)


# ------------------------------------------------------------- bounding box
@settings(max_examples=50, deadline=None)
@given(curves())
def test_curve_box_contains_curve(curve):
    box = bounding_box(curve)
    assert box.shape == (2, curve.dimension)
    points = curve.evaluate(curve_samples(curve))
    tol = 1e-12 * scale_of(curve)
    assert np.all(points >= box[0] - tol) and np.all(points <= box[1] + tol)
    np.testing.assert_array_equal(box[0], curve.control_points.min(axis=0))


@settings(max_examples=30, deadline=None)
@given(surfaces())
def test_surface_box_contains_surface(surface):
    box = surface.bounding_box()
    assert box.shape == (2, 3)
    points = surface.evaluate_grid(np.linspace(*surface.domain[:2], 40),
                                   np.linspace(*surface.domain[2:], 40))
    tol = 1e-12 * scale_of(surface)
    assert np.all(points >= box[0] - tol) and np.all(points <= box[1] + tol)


# ------------------------------------------------------------------ normals
@pytest.mark.parametrize("rational", [False, True])
def test_plane_normals(rational):
    rng = np.random.default_rng(1)
    x, y = np.meshgrid(np.arange(5.0), np.arange(4.0), indexing="ij")
    net = np.stack([x + rng.uniform(-0.2, 0.2, x.shape), y + rng.uniform(-0.2, 0.2, x.shape),
                    np.zeros_like(x)], axis=2)
    weights = rng.uniform(0.5, 2, x.shape) if rational else None
    plane = NurbsSurface(net, [0, 0, 0, 0.3, 0.6, 1, 1, 1], [2, 2, 2, 3, 4, 4, 4], 2, 2,
                         weights)
    u, v = np.meshgrid(np.linspace(0, 1, 40), np.linspace(2, 4, 40), indexing="ij")
    n = normals(plane, u, v)
    assert n.shape == (40, 40, 3)
    np.testing.assert_allclose(n, np.broadcast_to([0, 0, 1.0], n.shape), atol=1e-12)


@pytest.mark.parametrize("radius, center", [(1.0, (0, 0, 0)), (2.5, (1.0, -3.0, 0.5))])
def test_sphere_normals_are_radial_including_poles(radius, center):
    sphere = nurbs_sphere(radius, center)
    u = np.linspace(0, 4, 40)
    v = np.concatenate([np.linspace(0, 2, 40), [0.0, 2.0]])   # both poles, twice
    uu, vv = np.meshgrid(u, v, indexing="ij")
    n = sphere.normals(uu, vv)
    radial = (sphere.evaluate(uu, vv) - np.asarray(center)) / radius
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-14)
    # outward or inward consistently: the parametrization fixes the sign
    sign = np.sign(np.sum(n[5, 20] * radial[5, 20]))
    np.testing.assert_allclose(n, sign * radial, atol=1e-9)
    poles = sphere.normals(np.array([0.0, 1.3, 4.0, 0.0, 2.7]), np.array([0, 0, 0, 2, 2.0]))
    expected = sign * np.array([[0, 0, -1], [0, 0, -1], [0, 0, -1], [0, 0, 1], [0, 0, 1.0]])
    np.testing.assert_allclose(poles, expected, atol=1e-12)


def test_sphere_normals_near_the_poles():
    sphere = nurbs_sphere(2.0, (1.0, 2.0, 3.0))
    v = np.array([1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-14, 2 - 1e-8, 2 - 1e-9, 2 - 1e-13])
    u = np.linspace(0.1, 3.9, v.size)
    n = sphere.normals(u, v)
    radial = (sphere.evaluate(u, v) - [1.0, 2.0, 3.0]) / 2.0
    sign = np.sign(np.sum(sphere.normals(1.0, 1.0) * (sphere.evaluate(1.0, 1.0) - [1, 2, 3])))
    # near a degenerate point the attainable accuracy is about sqrt(eps) (see normals())
    np.testing.assert_allclose(n, sign * radial, atol=5e-8)


def test_collapsed_edge_of_triangle_patch():
    # bilinear patch with the edge u = 0 collapsed to one point: a planar triangle
    net = np.array([[[0, 0, 0], [0, 0, 0]], [[1, 0, 0], [1, 1, 0]]], dtype=float)
    tri = NurbsSurface(net, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    n = tri.normals(np.zeros(5), np.linspace(0, 1, 5))
    np.testing.assert_allclose(n, np.tile([0, 0, 1.0], (5, 1)), atol=1e-14)


def test_surface_collapsed_to_a_curve_has_no_normal():
    net = np.zeros((3, 3, 3))
    net[:, :, 0] = np.arange(3.0)[:, None]                # every v column identical
    ribbon = NurbsSurface(net, [0, 0, 0, 1, 1, 1], [0, 0, 0, 1, 1, 1], 2, 2)
    with pytest.raises(DegenerateGeometryError, match="no normal direction"):
        ribbon.normals(0.5, 0.5)


@settings(max_examples=30, deadline=None)
@given(surfaces(max_degree=4))
def test_normals_are_unit_and_orthogonal_to_tangents(surface):
    u = np.linspace(*surface.domain[:2], 7)[1:-1]
    v = np.linspace(*surface.domain[2:], 7)[1:-1]
    uu, vv = np.meshgrid(u, v, indexing="ij")
    d = surface.derivatives(uu, vv, 1)
    cross = np.cross(d[..., 1, 0, :], d[..., 0, 1, :])
    ok = np.linalg.norm(cross, axis=-1) > 1e-6 * np.abs(surface.control_points).max() ** 2
    n = normals(surface, uu, vv)
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-12)
    dots = np.abs(np.einsum("...c,...c->...", n, cross / np.linalg.norm(cross, axis=-1,
                                                                       keepdims=True)))
    assert np.all(dots[ok] > 1 - 1e-9)


def test_normals_reject_bad_input():
    sphere = nurbs_sphere()
    with pytest.raises(InvalidGeometryError, match="finite"):
        sphere.normals(np.nan, 0.5)
    flat = NurbsSurface(np.zeros((2, 2, 2)), [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    with pytest.raises(InvalidGeometryError, match="3D"):
        normals(flat, 0.5, 0.5)


# --------------------------------------------------------------- arc length
@pytest.mark.parametrize("radius", [0.01, 1.0, 37.5])
def test_circle_length_is_two_pi_r(radius):
    circle = nurbs_circle(radius, (3.0, -1.0, 2.0))
    assert arc_length(circle) == pytest.approx(2 * np.pi * radius, rel=1e-12)
    # a quarter of the circle is one knot span pair: [0, 1]
    assert circle.arc_length(0, 1) == pytest.approx(0.5 * np.pi * radius, rel=1e-12)


@pytest.mark.parametrize("degree", [1, 2, 3, 7])
def test_straight_line_length(degree):
    rng = np.random.default_rng(degree)
    n = degree + 5
    direction = rng.normal(size=3)
    # increasing collinear poles: a monotone (variation-diminishing) parametrization
    positions = np.sort(rng.uniform(0, 4, n))
    line = NurbsCurve(positions[:, None] * direction + [1, 2, 3], np.concatenate(
        [np.zeros(degree), np.linspace(0, 2, n - degree + 1), np.full(degree, 2.0)]), degree)
    expected = (positions[-1] - positions[0]) * np.linalg.norm(direction)
    assert arc_length(line) == pytest.approx(expected, rel=1e-12)


@settings(max_examples=30, deadline=None)
@given(curves(max_degree=6), st.floats(0.1, 0.9))
def test_arc_length_matches_scipy_quad_and_is_additive(curve, fraction):
    lo, hi = curve.domain
    mid = lo + fraction * (hi - lo)
    breaks = np.unique(np.concatenate([[lo, hi], curve.knots[(curve.knots > lo)
                                                             & (curve.knots < hi)]]))

    def speed(t):
        return np.linalg.norm(curve.derivatives(t, 1)[1])

    reference = sum(quad(speed, a, b, epsabs=0, epsrel=1e-13, limit=200)[0]
                    for a, b in zip(breaks[:-1], breaks[1:]))
    total = arc_length(curve)
    assert total == pytest.approx(reference, rel=1e-9)
    assert arc_length(curve, lo, mid) + arc_length(curve, mid, hi) == pytest.approx(
        total, rel=1e-11)


@settings(max_examples=30, deadline=None)
@given(curves(max_degree=5))
def test_cumulative_arc_length(curve):
    lo, hi = curve.domain
    t = np.random.default_rng(0).permutation(np.linspace(lo, hi, 23))
    s = curve.cumulative_arc_length(t)
    assert s.shape == t.shape
    order = np.argsort(t)
    assert np.all(np.diff(s[order]) >= 0)
    assert s[order[0]] == 0.0
    assert s[order[-1]] == pytest.approx(arc_length(curve), rel=1e-11)
    k = order[11]
    assert s[k] == pytest.approx(arc_length(curve, lo, t[k]), rel=1e-10, abs=1e-12)
    # knot insertion does not change the length function
    refined = curve.insert_knot(t[order[5]]) if np.count_nonzero(
        curve.knots == t[order[5]]) < curve.degree else curve
    np.testing.assert_allclose(cumulative_arc_length(refined, t), s, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("offset", [0.0, 1e6])
def test_a_tiny_end_span_far_away_keeps_the_length(offset):
    """A quarter circle (radius 3) and a straight last knot span 2e-8 wide and 2e-8
    long, as a STEP file written at 1e6 gives it: the speed on that span is known only
    to the rounding of its control-point differences; the length is still right (and
    the estimate no longer bisects that span to the cap)."""
    r, h, length = 3.0, 2e-8, 2e-8
    end = np.array([0.0, r, 0.0])
    points = np.array([[r, 0, 0], [r, r, 0], end, end + [-0.5 * length, 0, 0],
                       end + [-length, 0, 0]]) + offset
    curve = NurbsCurve(points, [0, 0, 0, 1, 1, 1 + h, 1 + h, 1 + h], 2, [1, S2, 1, 1, 1])
    quarter = 0.5 * np.pi * r
    rel = 1e-12 if offset == 0 else 1e-10     # poles at 1e6 are themselves rounded to 1e-10
    assert arc_length(curve) == pytest.approx(quarter + length, rel=rel)
    s = cumulative_arc_length(curve, np.array([0.5, 1.0, 1.0 + 0.5 * h, 1.0 + h]))
    np.testing.assert_allclose(s, [0.5 * quarter, quarter, quarter + 0.5 * length,
                                   quarter + length], rtol=rel)


def test_translated_curves_and_surfaces_are_moved_exactly():
    circle = nurbs_circle(2.0, (1.0, 2.0, 3.0))
    moved = circle.translated([10.0, 0.0, -5.0])
    t = np.linspace(*circle.domain, 50)
    np.testing.assert_allclose(moved.evaluate(t), circle.evaluate(t) + [10.0, 0.0, -5.0],
                               rtol=0, atol=1e-12)
    np.testing.assert_array_equal(moved.weights, circle.weights)
    assert arc_length(moved.translated([1e6, 1e6, 1e6])) == pytest.approx(arc_length(circle),
                                                                             rel=1e-10)
    with pytest.raises(InvalidGeometryError, match="3 finite numbers"):
        circle.translated([1.0, np.nan, 0.0])
    with pytest.raises(InvalidGeometryError, match="3 finite numbers"):
        circle.translated([1.0, 2.0])


def test_arc_length_rejects_bad_arguments():
    curve = make_curve(0, 3, 1, 1, False)
    lo, hi = curve.domain
    with pytest.raises(InvalidGeometryError, match="t0 <= t1"):
        arc_length(curve, hi, lo)
    with pytest.raises(InvalidGeometryError, match="outside the domain"):
        arc_length(curve, lo - 1, hi)
    with pytest.raises(InvalidGeometryError, match="finite"):
        cumulative_arc_length(curve, [lo, np.nan])
    with pytest.raises(InvalidToleranceError, match="> 0"):
        arc_length(curve, tol=0)
    with pytest.raises(InvalidToleranceError, match="positive number"):
        arc_length(curve, tol="x")
    assert arc_length(curve, lo, lo) == 0.0


# ---------------------------------------------------------------- normal_turn
def _graph(height, degree: int = 3, n: int = 6) -> NurbsSurface:
    """The graph ``z = height(x, y)`` over the unit square, x = u, y = v (interpolated
    exactly when ``height`` is a polynomial of degree <= ``degree`` in each)."""
    from surfprep.algorithms.fitting import interpolate_surface

    t = np.linspace(0, 1, n)
    x, y = np.meshgrid(t, t, indexing="ij")
    return interpolate_surface(np.stack([x, y, height(x, y)], axis=-1), degree_u=degree,
                               degree_v=degree, params_u=t, params_v=t)


def test_normal_turn_of_a_plane_turned_rigidly_is_the_rotation_angle():
    x, y = np.meshgrid([0.0, 1.0], [0.0, 1.0], indexing="ij")
    knots = [0, 0, 1, 1]
    flat = NurbsSurface(np.stack([x, y, 0 * x], -1), knots, knots, 1, 1)
    for angle in (1e-9, 1e-4, 0.3, 2.5):
        turned = NurbsSurface(np.stack([x, y * np.cos(angle), y * np.sin(angle)], -1),
                              knots, knots, 1, 1)
        u, v = np.random.default_rng(1).random((2, 50))
        assert np.allclose(normal_turn(flat, turned, u, v), angle, rtol=1e-10, atol=0)


def test_normal_turn_of_a_bump_is_the_slope_angle_of_its_graph():
    # z = c u^2: the normal (-2 c u, 0, 1) against (0, 0, 1) turns by arctan(2 c u)
    c = 0.05
    flat, bump = _graph(lambda x, y: 0 * x), _graph(lambda x, y: c * x * x)
    u, v = np.meshgrid(np.linspace(0, 1, 31), np.linspace(0, 1, 7), indexing="ij")
    assert np.allclose(normal_turn(flat, bump, u, v), np.arctan(2 * c * u), rtol=0, atol=1e-12)


def test_normal_turn_of_a_folded_surface_is_above_a_right_angle():
    x, y = np.meshgrid([0.0, 1.0], [0.0, 1.0], indexing="ij")
    knots = [0, 0, 1, 1]
    flat = NurbsSurface(np.stack([x, y, 0 * x], -1), knots, knots, 1, 1)
    mirrored = NurbsSurface(np.stack([x, -y, 0 * x], -1), knots, knots, 1, 1)
    assert np.allclose(normal_turn(flat, mirrored, [0.5], [0.5]), np.pi)


def test_normal_turn_is_nan_only_at_a_collapsed_side():
    # a triangle: the side u = 1 collapsed to one point, |Su x Sv| -> 0 there
    x = np.array([[0.0, 0.0], [1.0, 1.0]])
    y = np.array([[0.0, 1.0], [0.5, 0.5]])
    knots = [0, 0, 1, 1]
    triangle = NurbsSurface(np.stack([x, y, 0 * x], -1), knots, knots, 1, 1)
    lifted = NurbsSurface(np.stack([x, y, 0.1 * x], -1), knots, knots, 1, 1)
    u = np.array([0.0, 0.5, 0.9, 1.0])
    angle = normal_turn(triangle, lifted, u, 0.5 + 0 * u)
    assert np.isnan(angle[-1]) and np.all(np.isfinite(angle[:-1]))
    assert np.allclose(angle[:-1], np.arctan(0.1))


def test_normal_turn_refuses_what_it_cannot_measure():
    x, y = np.meshgrid([0.0, 1.0], [0.0, 1.0], indexing="ij")
    knots = [0, 0, 1, 1]
    flat = NurbsSurface(np.stack([x, y, 0 * x], -1), knots, knots, 1, 1)
    planar = NurbsSurface(np.stack([x, y], -1), knots, knots, 1, 1)
    with pytest.raises(InvalidGeometryError, match="3D"):
        normal_turn(flat, planar, [0.5], [0.5])
    with pytest.raises(InvalidGeometryError, match="finite"):
        normal_turn(flat, flat, [np.nan], [0.5])
    with pytest.raises(InvalidGeometryError, match="degenerate"):
        normal_turn(flat, flat, [0.5], [0.5], degenerate=2.0)


def test_normal_turn_is_nan_where_the_surface_given_has_a_cusp():
    """Where before's two derivatives are nearly parallel (a face's corner where its
    sides meet tangentially: t4m's face 11 at sin = 3.5e-4) its tangent plane is barely
    defined and any change turns it: NaN there, the angle elsewhere."""
    # x = u + v, y = u + (1 + eps) v: S_u = (1, 1, 0), S_v = (1, 1 + eps, 0), sin ~ eps / 2
    for eps, defined in ((1e-5, False), (1e-1, True)):
        x = np.array([[0.0, 1.0], [1.0, 2.0]])
        y = np.array([[0.0, 1.0 + eps], [1.0, 2.0 + eps]])
        knots = [0, 0, 1, 1]
        sheared = NurbsSurface(np.stack([x, y, 0 * x], -1), knots, knots, 1, 1)
        lifted = NurbsSurface(np.stack([x, y, 1e-6 * np.array([[0.0, 1.0], [0.0, 1.0]])], -1),
                              knots, knots, 1, 1)
        angle = normal_turn(sheared, lifted, [0.5], [0.5])
        assert np.isfinite(angle[0]) == defined
