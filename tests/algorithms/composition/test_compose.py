"""Composing two trivariate solids: the curves where their boundaries meet, classification."""

from __future__ import annotations

import math

import numpy as np
import pytest

from surfprep.algorithms.composition import compose
from surfprep.algorithms.volume_builders import block, solid_sphere
from surfprep.errors import InvalidGeometryError


def test_two_balls_meet_in_one_circle_and_points_are_classified_exactly():
    r, d = 5.0, 6.0
    c = compose(solid_sphere(r, (0, 0, 0)), solid_sphere(r, (d, 0, 0)))
    assert len(c.curves) >= 1
    points = np.vstack([curve.points for _, _, curve in c.curves])
    # the circle x = d / 2, radius sqrt(r^2 - (d/2)^2), to the tolerance
    np.testing.assert_allclose(points[:, 0], d / 2, atol=10 * c.tol)
    np.testing.assert_allclose(np.hypot(points[:, 1], points[:, 2]), math.sqrt(r * r - d * d / 4),
                               atol=10 * c.tol)
    # the whole circle, once: its points cover every angle
    angles = np.sort(np.arctan2(points[:, 2], points[:, 1]))
    assert np.max(np.diff(np.concatenate([angles, [angles[0] + 2 * np.pi]]))) < 0.5
    rng = np.random.default_rng(7)
    samples = rng.uniform([-6, -6, -6], [12, 6, 6], (10_000, 3))
    exact = (np.linalg.norm(samples, axis=1) <= r).astype(int) \
        + 2 * (np.linalg.norm(samples - [d, 0, 0], axis=1) <= r).astype(int)
    labels = c.classify(samples)
    near = np.minimum(np.abs(np.linalg.norm(samples, axis=1) - r),
                      np.abs(np.linalg.norm(samples - [d, 0, 0], axis=1) - r)) < 1e-6
    assert np.array_equal(labels[~near], exact[~near])
    assert {0, 1, 2, 3} <= set(labels.tolist())


def test_tangent_balls_touch_in_one_point_and_have_no_curve():
    c = compose(solid_sphere(1.0), solid_sphere(1.0, (2, 0, 0)))
    assert c.curves == () and c.hierarchy.loops == ()
    assert c.volume("common") == 0.0
    assert c.volume("union") == pytest.approx(8 / 3 * math.pi, rel=1e-12)
    # the contact point is on both boundaries: in both, within tol
    assert c.classify([[1, 0, 0], [0.5, 0, 0], [1.5, 0, 0], [1, 0.1, 0]]).tolist() == [3, 1, 2, 0]


def test_a_ball_inside_a_block_meets_nothing():
    c = compose(block(10.0, origin=(-5, -5, -5)), solid_sphere(2.0, (1, 1, 1)))
    assert c.curves == ()
    labels = c.classify([[1, 1, 1], [4, 4, 4], [20, 0, 0]])
    assert labels.tolist() == [3, 1, 0]
    where = c.locate([[1, 1, 1]])
    assert where["in_a"][0] and where["in_b"][0]
    np.testing.assert_allclose(block(10.0, origin=(-5, -5, -5)).evaluate(*where["uvw_a"][0]), [1, 1, 1],
                               atol=1e-9)


def test_compose_refuses_what_is_not_a_solid():
    with pytest.raises(InvalidGeometryError, match="NurbsVolume"):
        compose(solid_sphere(1.0), "ball")
    with pytest.raises(InvalidGeometryError, match="tol"):
        compose(solid_sphere(1.0), solid_sphere(1.0, (1, 0, 0)), tol=-1.0)


def test_the_hierarchy_is_built_once_and_a_solid_s_level_1_is_reused():
    ball = solid_sphere(5.0)
    first = compose(ball, solid_sphere(5.0, (6, 0, 0)))
    h = first.hierarchy
    assert first.hierarchy is h                          # kept
    assert h.counts()["loops"] == 1
    # the hierarchy's loop and the intersection's curves: the same circle
    for points in [h.loops[0].points] + [c.points for _, _, c in first.curves]:
        np.testing.assert_allclose(points[:, 0], 3.0, atol=first.tol)
        np.testing.assert_allclose(np.hypot(points[:, 1], points[:, 2]), 4.0, atol=first.tol)
    second = compose(ball, solid_sphere(5.0, (0, 7, 0)), reuse=first)
    assert second.hierarchy.a is h.a                     # the ball's Bezier patches
    assert second.hierarchy.b is not h.b
    assert second.hierarchy.counts()["loops"] == 1
    with pytest.raises(InvalidGeometryError, match="reuse"):
        compose(ball, ball, reuse="first")
    with pytest.raises(InvalidGeometryError, match="mesh_tol"):
        first.build_hierarchy(mesh_tol=0.1 * first.tol)
    sweep = first.build_hierarchy(candidates="sweep")
    assert sweep.counts() == h.counts()


def test_ray_and_inversion_classify_alike():
    a, b = block(4.0, origin=(-2, -2, -2)), solid_sphere(2.5)
    c = compose(a, b)
    points = np.random.default_rng(5).uniform(-3, 3, (3000, 3))
    ray, inversion = c.classify(points), c.classify(points, method="inversion")
    np.testing.assert_array_equal(ray, inversion)
    exact = np.all(np.abs(points) <= 2, axis=1).astype(int) + 2 * (np.linalg.norm(points, axis=1) <= 2.5)
    np.testing.assert_array_equal(ray, exact)
    with pytest.raises(InvalidGeometryError, match="method"):
        c.classify(points, method="winding")
    assert [f.name for f in c.boundary_faces("B")] == ["u1"]
