"""SSI step 5: auxiliary-plane refinement (eqs. 29.18–29.26), chord refinement, simplification.

Exact pairs, all built with numpy only: a plane z = c with a biquadratic paraboloid,
a bicubic height field, a rational sphere patch; two rational quadratic cylinders;
two planes. Starting points are perturbed by ~1e-2 in parameter space.
"""

from __future__ import annotations

import warnings

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
    sphere_plane_start,
)
from hypothesis import given, settings
from hypothesis import strategies as st

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.intersection.refine import (
    project_points,
    refine_curves,
    refine_points,
    segment_distance,
)
from surfprep.errors import InvalidGeometryError, InvalidToleranceError


def height_field(seed: int) -> NurbsSurface:
    """Bicubic z = x + small random bumps over [0, 1]^2 (monotone in x)."""
    rng = np.random.default_rng(seed)
    g = np.linspace(0, 1, 4)
    x, y = np.meshgrid(g, g, indexing="ij")
    z = x + 0.1 * rng.uniform(-1, 1, (4, 4))
    return NurbsSurface(np.stack([x, y, z], -1), [0] * 4 + [1] * 4, [0] * 4 + [1] * 4, 3, 3)



# ---------------------------------------------------------------- points
@given(st.integers(0, 2**32 - 1), st.floats(-1.2, 1.2), st.sampled_from([1e-6, 1e-9, 1e-12]))
@settings(max_examples=25, deadline=None)
def test_plane_sphere_exact_circle(seed, c, tol):
    rng = np.random.default_rng(seed)
    uv_a, uv_b = sphere_plane_start(c, 200, rng, lon=(0.1, 1.4))
    r = refine_points(plane_z(c), sphere_patch(), uv_a, uv_b, tol=tol)
    assert r.converged.all() and not r.singular.any()
    assert r.gap.max() <= tol
    assert np.abs(np.linalg.norm(r.points, axis=1) - R_SPHERE).max() <= tol
    assert np.abs(r.points[:, 2] - c).max() <= tol
    assert r.iterations.max() <= 6            # quadratic convergence from 1e-2 starts


def test_plane_paraboloid_and_swapped_order():
    rng = np.random.default_rng(0)
    c, tol = 0.5, 1e-10
    phi = rng.uniform(0, 2 * np.pi, 300)
    pts = np.stack([np.sqrt(c) * np.cos(phi), np.sqrt(c) * np.sin(phi), np.full(300, c)], 1)
    uv_p = plane_uv(pts) + rng.uniform(-1e-2, 1e-2, (300, 2))
    uv_q = paraboloid_uv(pts) + rng.uniform(-1e-2, 1e-2, (300, 2))
    for a, b, ua, ub in ((plane_z(c), paraboloid(), uv_p, uv_q),
                         (paraboloid(), plane_z(c), uv_q, uv_p)):
        r = refine_points(a, b, ua, ub, tol=tol)
        assert r.converged.all()
        assert np.abs(np.hypot(r.points[:, 0], r.points[:, 1]) - np.sqrt(c)).max() <= tol
        assert np.abs(r.points[:, 2] - c).max() <= tol


def test_plane_bicubic_level_set():
    surf, c, tol = height_field(3), 0.5, 1e-10
    v = np.linspace(0.05, 0.95, 40)
    u = np.array([invert_1d(lambda s, vi=vi: surf.evaluate(s, vi + 0 * s)[:, 2], c) for vi in v])
    rng = np.random.default_rng(3)
    uv_b = np.stack([u, v], 1) + rng.uniform(-1e-2, 1e-2, (40, 2))
    uv_a = plane_uv(surf.evaluate(uv_b[:, 0], uv_b[:, 1])) + rng.uniform(-1e-2, 1e-2, (40, 2))
    r = refine_points(plane_z(c), surf, uv_a, uv_b, tol=tol)
    assert r.converged.all()
    assert np.abs(surf.evaluate(r.uv_b[:, 0], r.uv_b[:, 1])[:, 2] - c).max() <= tol
    assert r.iterations.max() <= 6


@pytest.mark.parametrize("tol", [1e-7, 1e-12])
def test_two_cylinders_exact(tol):
    rng = np.random.default_rng(4)
    th = rng.uniform(0.02, np.pi - 0.02, 500)
    y, z = 0.6 * np.cos(th), 0.6 * np.sin(th)
    x = np.sqrt(1 - y ** 2)
    a, b = cylinder_z(), cylinder_x()
    ua = invert_1d(lambda s: np.arctan2(*a.evaluate(s, 0 * s)[:, [1, 0]].T), np.arctan2(y, x))
    ub = invert_1d(lambda s: np.arctan2(*b.evaluate(s, 0 * s)[:, [2, 1]].T), th)
    uv_a = np.stack([ua, (z + 2) / 4], 1) + rng.uniform(-1e-2, 1e-2, (500, 2))
    uv_b = np.stack([ub, (x + 2) / 4], 1) + rng.uniform(-1e-2, 1e-2, (500, 2))
    r = refine_points(a, b, uv_a, uv_b, tol=tol)
    p = r.points
    assert r.converged.all()
    assert np.abs(np.hypot(p[:, 0], p[:, 1]) - 1).max() <= tol
    assert np.abs(np.hypot(p[:, 1], p[:, 2]) - 0.6).max() <= tol
    assert r.iterations.max() <= 6


def test_start_outside_domain_slides_to_boundary():
    """A start past the patch border converges onto the border (clamped, F_n re-anchored)."""
    rng = np.random.default_rng(5)
    uv_a, uv_b = sphere_plane_start(0.5, 20, rng, perturb=0, lon=(-0.05, -0.01))
    r = refine_points(plane_z(0.5), sphere_patch(), uv_a, uv_b, tol=1e-10,
                      anchors=np.zeros((20, 3)) + [2.0, -0.05, 0.5])
    assert r.converged.all()
    np.testing.assert_allclose(r.uv_b[:, 0], 0.0, atol=0)
    assert np.abs(np.linalg.norm(r.points, axis=1) - R_SPHERE).max() <= 1e-10


@pytest.mark.parametrize("c", [0.0, 1e-14])
def test_near_tangent_points_flagged_not_crashed(c):
    """Plane z = c touching the paraboloid at its apex: normals parallel there."""
    rng = np.random.default_rng(6)
    uv_q = np.array([0.5, 0.5]) + rng.uniform(-1e-9, 1e-9, (8, 2))
    uv_q[0] = [0.5, 0.5]
    uv_p = np.array([0.5, 0.5]) + rng.uniform(-1e-9, 1e-9, (8, 2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = refine_points(plane_z(c), paraboloid(), uv_p, uv_q, tol=1e-12)
    assert np.all(np.isfinite(r.points)) and np.all(np.isfinite(r.uv_a))
    assert r.singular.all()
    assert r.gap.max() <= 1e-12


def test_well_separated_points_not_flagged():
    rng = np.random.default_rng(7)
    uv_a, uv_b = sphere_plane_start(0.3, 10, rng)
    assert not refine_points(plane_z(0.3), sphere_patch(), uv_a, uv_b).singular.any()


# ---------------------------------------------------------------- curves
def circle_sag(points: np.ndarray) -> np.ndarray:
    """Largest distance of the true circle arc from each chord, for points on a circle about z."""
    rho = np.hypot(points[:, 0], points[:, 1]).mean()
    ang = np.unwrap(np.arctan2(points[:, 1], points[:, 0]))
    return rho * (1 - np.cos(np.diff(ang) / 2))


@pytest.mark.parametrize("tol", [1e-3, 1e-6])
def test_chord_refinement_meets_tolerance(tol):
    rng = np.random.default_rng(8)
    c = 0.5
    uv_a, uv_b = sphere_plane_start(c, 4, rng, perturb=1e-3)
    out = refine_curves(plane_z(c), sphere_patch(), [uv_a], [uv_b], [False], tol=tol,
                        simplify=False)
    (curve,) = out
    p = curve.points
    assert curve.converged.all()
    assert circle_sag(p).max() <= tol
    # independent check: the exact circle point at each chord's mid-angle
    ang = np.unwrap(np.arctan2(p[:, 1], p[:, 0]))
    rho = np.sqrt(R_SPHERE ** 2 - c ** 2)
    mid = 0.5 * (ang[1:] + ang[:-1])
    exact = np.stack([rho * np.cos(mid), rho * np.sin(mid), np.full(mid.size, c)], 1)
    assert segment_distance(exact, p[:-1], p[1:]).max() <= tol
    # not over-refined: within a factor 2 of the fewest chords that meet tol
    needed = (ang[-1] - ang[0]) / (2 * np.arccos(1 - tol / rho))
    assert len(p) - 1 <= 2 * np.ceil(needed) + 2
    assert np.all(np.diff(ang) > 0)                       # still ordered


def test_closed_curve_refinement():
    rng = np.random.default_rng(9)
    c, tol = 0.25, 1e-5
    phi = np.linspace(0, 2 * np.pi, 7)[:-1]
    pts = np.stack([0.5 * np.cos(phi), 0.5 * np.sin(phi), np.full(6, c)], 1)
    uv_a = plane_uv(pts) + rng.uniform(-1e-3, 1e-3, (6, 2))
    uv_b = paraboloid_uv(pts) + rng.uniform(-1e-3, 1e-3, (6, 2))
    (curve,) = refine_curves(plane_z(c), paraboloid(), [uv_a], [uv_b], [True], tol=tol)
    assert curve.closed and curve.converged.all()
    closed_pts = np.vstack([curve.points, curve.points[:1]])
    assert circle_sag(closed_pts).max() <= tol
    assert np.abs(np.hypot(curve.points[:, 0], curve.points[:, 1]) - 0.5).max() <= tol


def test_simplify_straight_line_to_two_points():
    c = 0.3
    g = np.array([-2.0, 2.0])
    y, z = np.meshgrid(g, g, indexing="ij")
    tilted = NurbsSurface(np.stack([0.1 - 0.5 * y + 0.2 * z, y, z], -1), [0, 0, 1, 1],
                          [0, 0, 1, 1], 1, 1)           # x + 0.5 y - 0.2 z = 0.1
    rng = np.random.default_rng(10)
    ys = np.linspace(-1, 1, 25)
    xs = 0.1 - 0.5 * ys + 0.2 * c
    uv_a = np.stack([(xs + 2) / 4, (ys + 2) / 4], 1) + rng.uniform(-1e-2, 1e-2, (25, 2))
    uv_b = np.stack([(ys + 2) / 4, np.full(25, (c + 2) / 4)], 1) + rng.uniform(-1e-2, 1e-2, (25, 2))
    dense = refine_curves(plane_z(c), tilted, [uv_a], [uv_b], [False], tol=1e-9, simplify=False)
    (line,) = refine_curves(plane_z(c), tilted, [uv_a], [uv_b], [False], tol=1e-9)
    assert len(dense[0].points) == 25 and len(line.points) == 2
    np.testing.assert_array_equal(line.points, dense[0].points[[0, -1]])
    np.testing.assert_allclose(line.points[:, 0] + 0.5 * line.points[:, 1] - 0.2 * c, 0.1,
                               atol=1e-9)


def test_simplify_dense_arc_keeps_tolerance():
    rng = np.random.default_rng(11)
    c, tol = -0.4, 1e-4
    uv_a, uv_b = sphere_plane_start(c, 400, rng, perturb=1e-4)
    kw = dict(tol=tol)
    (dense,) = refine_curves(plane_z(c), sphere_patch(), [uv_a], [uv_b], [False],
                             simplify=False, **kw)
    (coarse,) = refine_curves(plane_z(c), sphere_patch(), [uv_a], [uv_b], [False], **kw)
    assert len(dense.points) == 400
    assert circle_sag(coarse.points).max() <= tol
    # no redundant point left: dropping any one interior point breaks tol
    ang = np.unwrap(np.arctan2(coarse.points[:, 1], coarse.points[:, 0]))
    rho = np.sqrt(R_SPHERE ** 2 - c ** 2)
    assert np.all(rho * (1 - np.cos((ang[2:] - ang[:-2]) / 2)) > 0.875 * tol)
    needed = (ang[-1] - ang[0]) / (2 * np.arccos(1 - tol / rho))
    assert len(coarse.points) - 1 <= 2 * np.ceil(needed)
    np.testing.assert_array_equal(coarse.points[[0, -1]], dense.points[[0, -1]])


def test_several_curves_in_one_batch():
    rng = np.random.default_rng(12)
    a1, b1 = sphere_plane_start(0.5, 5, rng, perturb=1e-3, lon=(0.0, 0.7))
    a2, b2 = sphere_plane_start(0.5, 3, rng, perturb=1e-3, lon=(0.9, 1.5))
    out = refine_curves(plane_z(0.5), sphere_patch(), [a1, a2], [b1, b2], [False, False],
                        tol=1e-5)
    assert len(out) == 2
    for curve in out:
        assert circle_sag(curve.points).max() <= 1e-5
    assert np.arctan2(out[0].points[-1, 1], out[0].points[-1, 0]) < 0.75
    assert np.arctan2(out[1].points[0, 1], out[1].points[0, 0]) > 0.85


# ---------------------------------------------------------------- mesh x NURBS
def test_project_points_onto_sphere():
    rng = np.random.default_rng(13)
    sph = sphere_patch()
    uv = rng.uniform(0.1, 0.9, (300, 2))
    exact = sph.evaluate(uv[:, 0], uv[:, 1])
    x = exact * (1 + rng.uniform(-1e-3, 1e-3, (300, 1)))     # off the sphere along the normal
    found, foot, ok = project_points(sph, x, uv + rng.uniform(-1e-2, 1e-2, (300, 2)))
    assert ok.all()
    np.testing.assert_allclose(foot, exact, atol=1e-10)
    np.testing.assert_allclose(found, uv, atol=1e-9)


# ---------------------------------------------------------------- validation
def test_validation_errors():
    a, b = plane_z(0.0), sphere_patch()
    with pytest.raises(InvalidToleranceError):
        refine_points(a, b, np.zeros((1, 2)), np.zeros((1, 2)), tol=0)
    with pytest.raises(InvalidGeometryError, match=r"uv_b must have shape \(1, 2\)"):
        refine_points(a, b, np.zeros((1, 2)), np.zeros((2, 2)))
    with pytest.raises(InvalidGeometryError, match="NaN"):
        refine_points(a, b, np.full((1, 2), np.nan), np.zeros((1, 2)))
    with pytest.raises(InvalidGeometryError, match="anchors"):
        refine_points(a, b, np.zeros((1, 2)), np.zeros((1, 2)), anchors=np.zeros(3))
    with pytest.raises(InvalidGeometryError, match="NurbsSurface"):
        refine_points("plane", b, np.zeros((1, 2)), np.zeros((1, 2)))
    with pytest.raises(InvalidGeometryError, match="one entry per curve"):
        refine_curves(a, b, [np.zeros((2, 2))], [], [False])
    with pytest.raises(InvalidGeometryError, match="closed one >= 3"):
        refine_curves(a, b, [np.zeros((2, 2))], [np.zeros((2, 2))], [True])
    assert refine_curves(a, b, [], [], []) == []
