"""SSI step 6: IntersectionCurve (samples + interpolants), its deviation check, and the
topology -> refinement -> interpolation pipeline on synthetic segment soups."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.surfaces import (
    R_SPHERE,
    cylinder_x,
    cylinder_z,
    invert_1d,
    paraboloid,
    paraboloid_uv,
    plane_uv,
    plane_z,
    sphere_patch,
    sphere_uv,
)

from surfprep.algorithms.intersection.refine import refine_points
from surfprep.algorithms.intersection.result import (
    IntersectionCurve,
    interpolate_samples,
    intersection_curves,
)
from surfprep.algorithms.intersection.topology import EndKind, build_topology
from surfprep.errors import InvalidGeometryError


def soup(points, uv_a, uv_b, rng, closed=False):
    """Shuffled, randomly flipped segments of a sampled curve, ends jittered by 1e-12."""
    idx = np.arange(len(points))
    pairs = np.stack([idx, np.roll(idx, -1)], 1) if closed else np.stack([idx[:-1], idx[1:]], 1)
    pairs = pairs[rng.permutation(len(pairs))]
    flip = rng.random(len(pairs)) < 0.5
    pairs[flip] = pairs[flip, ::-1]
    pts = points[pairs] + rng.uniform(-1e-12, 1e-12, (len(pairs), 2, 3))
    return (pts, None if uv_a is None else uv_a[pairs], None if uv_b is None else uv_b[pairs])


def sphere_plane_samples(c, n, rng, noise=1e-3):
    """Samples of the latitude circle z = c over the sphere patch, uv perturbed like a mesh."""
    phi = np.linspace(0, np.pi / 2, n)
    rho = np.sqrt(R_SPHERE ** 2 - c ** 2)
    pts = np.stack([rho * np.cos(phi), rho * np.sin(phi), np.full(n, c)], 1)
    uv_a, uv_b = plane_uv(pts), sphere_uv(pts)
    uv_b[[0, -1], 0] = [0.0, 1.0]                  # the ends lie on the patch border
    uv_a[1:-1] += rng.uniform(-noise, noise, (n - 2, 2))
    uv_b[1:-1] += rng.uniform(-noise, noise, (n - 2, 2))
    return pts, uv_a, uv_b


def exact_samples(c, n):
    """Refined samples (to 1e-13) of the latitude circle z = c on the sphere patch."""
    _pts, uv_a, uv_b = sphere_plane_samples(c, n, np.random.default_rng(0), noise=0)
    r = refine_points(plane_z(c), sphere_patch(), uv_a, uv_b, tol=1e-13)
    assert r.converged.all()
    return r


# ---------------------------------------------------------------- IntersectionCurve
def test_interpolants_pass_through_samples():
    r = exact_samples(0.5, 40)
    curve = IntersectionCurve.from_samples(r.points, r.uv_a, r.uv_b, False,
                                           EndKind.BOUNDARY, EndKind.BOUNDARY)
    t = curve.parameters
    np.testing.assert_allclose(curve.curve3d.evaluate(t), r.points, atol=1e-12)
    np.testing.assert_allclose(curve.pcurve_a.evaluate(t), r.uv_a, atol=1e-12)
    np.testing.assert_allclose(curve.pcurve_b.evaluate(t), r.uv_b, atol=1e-12)
    assert curve.curve3d.degree == 3 and curve.pcurve_a.dimension == 2
    # the length is curve3d's: the arc (to the interpolation error), longer than the polyline
    arc = np.sqrt(R_SPHERE ** 2 - 0.25) * np.pi / 2
    assert curve.length == pytest.approx(arc, rel=1e-6)
    assert curve.length > np.linalg.norm(np.diff(r.points, axis=0), axis=1).sum()
    with pytest.raises(ValueError):
        curve.points[0, 0] = 1.0                     # read-only


def test_max_deviation_small_for_dense_samples():
    r = exact_samples(0.5, 200)
    curve = IntersectionCurve.from_samples(r.points, r.uv_a, r.uv_b, False,
                                           EndKind.BOUNDARY, EndKind.BOUNDARY)
    dev = curve.max_deviation(plane_z(0.5), sphere_patch())
    assert dev.max <= 1e-8
    assert dev.to_a <= 1e-8 and dev.to_b <= 1e-8 and dev.gap <= 1e-8


def test_max_deviation_sees_errors_between_samples():
    """Three samples of a quarter circle: exact at the samples, far off between them."""
    r = exact_samples(0.5, 3)
    curve = IntersectionCurve.from_samples(r.points, r.uv_a, r.uv_b, False,
                                           EndKind.BOUNDARY, EndKind.BOUNDARY)
    dev = curve.max_deviation(plane_z(0.5), sphere_patch(), samples_per_span=1)
    assert dev.max > 1e-3
    a, b, g = curve.span_deviation(plane_z(0.5), sphere_patch(), 1)
    # the plane is linear in (u, v): its pcurve maps exactly onto curve3d; the sphere does not
    assert a.shape == (2,) and np.all(a < 1e-12)
    assert np.all(b > 1e-4) and np.all(g > 1e-4)


def test_max_deviation_sees_a_wrong_pcurve():
    r = exact_samples(0.5, 200)
    uv_b = r.uv_b.copy()
    uv_b[100, 1] += 1e-4                              # one parameter sample off the curve
    curve = IntersectionCurve.from_samples(r.points, r.uv_a, uv_b, False,
                                           EndKind.BOUNDARY, EndKind.BOUNDARY)
    dev = curve.max_deviation(plane_z(0.5), sphere_patch())
    assert dev.to_b > 1e-5 and dev.gap > 1e-5 and dev.to_a <= 1e-8


def test_closed_interpolants_close():
    phi = np.linspace(0, 2 * np.pi, 13)[:-1]
    pts = np.stack([np.cos(phi), np.sin(phi), np.zeros(12)], 1)
    curve = IntersectionCurve.from_samples(pts, pts[:, :2], None, True, EndKind.CLOSED,
                                           EndKind.CLOSED)
    assert curve.parameters.shape == (13,) and curve.pcurve_b is None
    t0, t1 = curve.curve3d.domain
    np.testing.assert_allclose(curve.curve3d.evaluate(t1), curve.curve3d.evaluate(t0), atol=1e-14)
    d = curve.curve3d.derivatives(np.array([t0, t1]), 1)[:, 1]
    np.testing.assert_allclose(d[0], d[1], atol=1e-12)          # C1 closure
    assert curve.length == pytest.approx(2 * np.pi, rel=1e-3)         # curve3d, not the chords
    assert curve.length > 12 * 2 * np.sin(np.pi / 12)


def test_interpolate_samples_low_counts():
    c = interpolate_samples(np.array([[0.0, 0.0], [1.0, 2.0]]), np.array([0.0, 1.0]), False)
    assert c.degree == 1
    c = interpolate_samples(np.eye(3), np.array([0.0, 1.0, 2.0]), False)
    assert c.degree == 2


def test_from_samples_validation():
    pts = np.zeros((3, 3))
    pts[:, 0] = [0, 1, 2]
    with pytest.raises(InvalidGeometryError, match=r"\(n, 3\)"):
        IntersectionCurve.from_samples(pts[:, :2], None, None, False, EndKind.OPEN, EndKind.OPEN)
    with pytest.raises(InvalidGeometryError, match=r"uv_a must have shape \(3, 2\)"):
        IntersectionCurve.from_samples(pts, np.zeros((2, 2)), None, False, EndKind.OPEN,
                                       EndKind.OPEN)
    with pytest.raises(InvalidGeometryError, match="closed curve needs >= 3"):
        IntersectionCurve.from_samples(pts[:2], None, None, True, EndKind.CLOSED, EndKind.CLOSED)
    with pytest.raises(InvalidGeometryError, match="coincident"):
        IntersectionCurve.from_samples(pts[[0, 0, 1]], None, None, False, EndKind.OPEN,
                                       EndKind.OPEN)
    curve = IntersectionCurve.from_samples(pts, None, None, False, EndKind.OPEN, EndKind.OPEN,
                                           interpolate=False)
    assert curve.curve3d is None
    with pytest.raises(InvalidGeometryError, match="without interpolants"):
        curve.max_deviation(None, None)
    curve = IntersectionCurve.from_samples(pts, None, None, False, EndKind.OPEN, EndKind.OPEN)
    with pytest.raises(InvalidGeometryError, match="samples_per_span"):
        curve.max_deviation(None, None, samples_per_span=0)


# ---------------------------------------------------------------- pipeline
@pytest.mark.parametrize("tol", [1e-4, 1e-7])
def test_pipeline_plane_sphere_open_arc(tol):
    rng = np.random.default_rng(1)
    c = 0.5
    pts, uv_a, uv_b = sphere_plane_samples(c, 15, rng)
    a, b = plane_z(c), sphere_patch()
    topo = build_topology(*soup(pts, uv_a, uv_b, rng), tol=1e-9, domain_a=a.domain,
                          domain_b=b.domain)
    (curve,) = intersection_curves(topo, a, b, tol=tol)
    assert curve.start_kind is EndKind.BOUNDARY and curve.end_kind is EndKind.BOUNDARY
    assert not curve.closed
    assert curve.max_deviation(a, b, samples_per_span=5).max <= tol
    q = curve.curve3d.evaluate(np.linspace(*curve.curve3d.domain, 4001))
    assert np.abs(np.linalg.norm(q, axis=1) - R_SPHERE).max() <= tol
    assert np.abs(q[:, 2] - c).max() <= tol
    # the ends were refined onto the patch border
    ends = np.sort(curve.uv_b[[0, -1], 0])
    np.testing.assert_allclose(ends, [0.0, 1.0], atol=0)


def test_pipeline_plane_paraboloid_closed_loop():
    rng = np.random.default_rng(2)
    c, tol = 0.36, 1e-6
    phi = np.linspace(0, 2 * np.pi, 19)[:-1]
    pts = np.stack([0.6 * np.cos(phi), 0.6 * np.sin(phi), np.full(18, c)], 1)
    uv_a = plane_uv(pts) + rng.uniform(-1e-3, 1e-3, (18, 2))
    uv_b = paraboloid_uv(pts) + rng.uniform(-1e-3, 1e-3, (18, 2))
    a, b = plane_z(c), paraboloid()
    topo = build_topology(*soup(pts, uv_a, uv_b, rng, closed=True), tol=1e-9)
    (curve,) = intersection_curves(topo, a, b, tol=tol)
    assert curve.closed and curve.start_kind is EndKind.CLOSED
    assert curve.max_deviation(a, b, samples_per_span=5).max <= tol
    q = curve.curve3d.evaluate(np.linspace(*curve.curve3d.domain, 4001))
    assert np.abs(np.hypot(q[:, 0], q[:, 1]) - 0.6).max() <= tol
    np.testing.assert_allclose(q[0], q[-1], atol=1e-14)


def test_pipeline_two_cylinders():
    rng = np.random.default_rng(3)
    tol = 1e-6
    th = np.linspace(0, np.pi, 25)
    y, z = 0.6 * np.cos(th), 0.6 * np.sin(th)
    x = np.sqrt(1 - y ** 2)
    a, b = cylinder_z(), cylinder_x()
    ua = invert_1d(lambda s: np.arctan2(*a.evaluate(s, 0 * s)[:, [1, 0]].T), np.arctan2(y, x))
    ub = np.linspace(0, 1, 25)
    uv_a = np.stack([ua, (z + 2) / 4], 1) + rng.uniform(-1e-3, 1e-3, (25, 2))
    uv_b = np.stack([ub, (x + 2) / 4], 1)
    uv_b[1:-1] += rng.uniform(-1e-3, 1e-3, (23, 2))
    pts = np.stack([x, y, z], 1)
    topo = build_topology(*soup(pts, uv_a, uv_b, rng), tol=1e-9, domain_a=a.domain,
                          domain_b=b.domain)
    (curve,) = intersection_curves(topo, a, b, tol=tol)
    assert curve.start_kind is EndKind.BOUNDARY
    assert curve.max_deviation(a, b, samples_per_span=5).max <= tol
    q = curve.curve3d.evaluate(np.linspace(*curve.curve3d.domain, 4001))
    assert np.abs(np.hypot(q[:, 0], q[:, 1]) - 1).max() <= tol
    assert np.abs(np.hypot(q[:, 1], q[:, 2]) - 0.6).max() <= tol


def test_pipeline_mesh_nurbs_projects_onto_exact_side():
    rng = np.random.default_rng(4)
    pts, _, uv_b = sphere_plane_samples(0.5, 30, rng)
    noisy = pts * (1 + rng.uniform(-1e-3, 1e-3, (30, 1)))      # mesh points off the sphere
    topo = build_topology(*soup(noisy, None, uv_b, rng), tol=1e-9)
    (curve,) = intersection_curves(topo, None, sphere_patch(), tol=1e-8)
    assert curve.uv_a is None and curve.pcurve_a is None and curve.pcurve_b is not None
    assert np.abs(np.linalg.norm(curve.points, axis=1) - R_SPHERE).max() <= 1e-9
    dev = curve.max_deviation(None, sphere_patch())
    assert np.isnan(dev.to_a) and np.isnan(dev.gap) and dev.to_b < 1e-3


def test_pipeline_mesh_mesh_keeps_polyline():
    rng = np.random.default_rng(5)
    pts = np.stack([np.linspace(0, 1, 10), np.zeros(10), np.zeros(10)], 1)
    topo = build_topology(*soup(pts, None, None, rng), tol=1e-9)
    (curve,) = intersection_curves(topo, None, None)
    assert curve.curve3d is None and curve.uv_a is None
    assert curve.start_kind is EndKind.OPEN
    np.testing.assert_allclose(np.sort(curve.points[:, 0]), pts[:, 0], atol=1e-11)


def test_pipeline_needs_uv_for_refinement():
    rng = np.random.default_rng(6)
    pts = np.stack([np.linspace(0, 1, 4), np.zeros(4), np.zeros(4)], 1)
    topo = build_topology(*soup(pts, None, None, rng), tol=1e-9)
    with pytest.raises(InvalidGeometryError, match="uv_a and uv_b"):
        intersection_curves(topo, plane_z(0), sphere_patch())
    with pytest.raises(InvalidGeometryError, match="exact side"):
        intersection_curves(topo, None, sphere_patch())


def test_length_bounded_where_rounding_stalls_the_quadrature():
    """A unit-radius arc far from the origin (coordinates 1e8): rounding in the
    derivative (relative 1e-8) keeps the adaptive quadrature's estimates from ever
    agreeing to a relative 1e-12, and the bisection used to double its pending
    intervals every pass (about 1 GB asked for here). Now bounded: the length is
    right to the rounding level, fast and in little memory."""
    import tracemalloc

    from surfprep.algorithms.fitting import interpolate_curve
    from surfprep.algorithms.measure import arc_length

    t = np.linspace(0, 1, 200)
    far = 1e8 + np.stack([np.cos(3 * t), np.sin(3 * t), np.zeros_like(t)], axis=1)
    curve = interpolate_curve(far, degree=3)
    tracemalloc.start()
    try:
        length = arc_length(curve, tol=1e-12)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert length == pytest.approx(3.0, rel=1e-6)
    assert peak < 200e6, peak
    c = IntersectionCurve.from_samples(far, None, None, False, EndKind.OPEN, EndKind.OPEN)
    assert c.length == pytest.approx(3.0, rel=1e-6)
