"""Builders of trivariate solids (004 §3, Figs. 3 and 8): every boundary face against the
exact shape, collapsed and exterior faces, orientation, volumes."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.volume import FACES, NurbsVolume
from surfprep.algorithms.volume_builders import block, extrude, revolve, ruled, solid_sphere, solid_torus
from surfprep.errors import InvalidGeometryError

R2 = np.sqrt(0.5)


def face_grid(face: NurbsSurface, n: int = 41) -> np.ndarray:
    """Points ``(n, n, 3)`` of a face on a uniform grid of its domain."""
    u0, u1, v0, v1 = face.domain
    return face.evaluate_grid(np.linspace(u0, u1, n), np.linspace(v0, v1, n))


def volume_samples(volume: NurbsVolume, n: int = 2000, seed: int = 0) -> np.ndarray:
    lo, hi = np.array(volume.domain[0::2]), np.array(volume.domain[1::2])
    return lo + (hi - lo) * np.random.default_rng(seed).random((n, 3))


def right_handed(volume: NurbsVolume) -> bool:
    return bool(np.linalg.det(volume.jacobian(*volume_samples(volume).T)).min() > 0)


def collapsed_names(volume: NurbsVolume) -> list[str]:
    return [name for name, flag in volume.collapsed_faces().items() if flag]


def rectangle(x0, x1, z0, z1) -> NurbsSurface:
    """The rectangle ``[x0, x1] x {0} x [z0, z1]`` (u along x, v along z)."""
    cp = np.array([[[x0, 0, z0], [x0, 0, z1]], [[x1, 0, z0], [x1, 0, z1]]], float)
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


# -------------------------------------------------------------------- block
def test_block_faces_are_the_box_faces():
    origin, size = np.array([1.0, -2.0, 0.5]), np.array([2.0, 3.0, 0.25])
    cube = block(size, origin, degrees=(2, 3, 1))
    assert cube.degrees == (2, 3, 1) and cube.n_control == (3, 4, 2) and cube.domain == (0, 1) * 3
    x = volume_samples(cube)
    np.testing.assert_allclose(cube.evaluate(*x.T), origin + size * x, rtol=0, atol=1e-15)
    faces = cube.boundary()
    for axis, letter in enumerate("uvw"):
        for end in (0, 1):
            points = face_grid(faces[f"{letter}{end}"])
            np.testing.assert_allclose(points[..., axis], origin[axis] + end * size[axis], rtol=0,
                                       atol=4e-15)
            others = [k for k in range(3) if k != axis]
            assert np.all(points[..., others] >= origin[others] - 1e-15)
            assert np.all(points[..., others] <= origin[others] + size[others] + 1e-15)
    assert collapsed_names(cube) == [] and tuple(cube.exterior_faces()) == FACES
    assert right_handed(cube) and cube.volume() == pytest.approx(1.5, rel=1e-14)
    np.testing.assert_array_equal(block(2.0).bounding_box(), [[0, 0, 0], [2, 2, 2]])


@pytest.mark.parametrize("kwargs, message", [
    ({"size": 0.0}, r"size along x must be finite and > 0, got 0.0"),
    ({"size": (1, -1, 1)}, r"size along y must be finite and > 0, got -1.0"),
    ({"size": (1, 1)}, r"size must be 3 finite numbers"),
    ({"size": 1, "origin": (0, 0, np.nan)}, r"origin must be 3 finite numbers"),
    ({"size": 1, "degrees": (1, 0, 1)}, r"degrees must be three integers >= 1, got \(1, 0, 1\)"),
])
def test_block_refuses_bad_input(kwargs, message):
    with pytest.raises(InvalidGeometryError, match=message):
        block(**kwargs)


# ------------------------------------------------------------------ extrude
def test_extrude_sweeps_the_surface_along_the_vector():
    # a rational quarter annulus in z = 0, and a curved bicubic-ish patch
    arc = np.array([[1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    quarter = NurbsSurface(np.stack([arc, 2 * arc]), [0, 0, 1, 1], [0, 0, 0, 1, 1, 1], 1, 2,
                           np.array([[1, R2, 1], [1, R2, 1]]))
    d = np.array([0.3, -0.2, 2.0])
    solid = extrude(quarter, d)
    faces = solid.boundary()
    np.testing.assert_allclose(face_grid(faces["w0"]), face_grid(quarter), rtol=0, atol=1e-15)
    np.testing.assert_allclose(face_grid(faces["w1"]), face_grid(quarter) + d, rtol=0, atol=1e-14)
    # the faces along the sweep are ruled: x(u, v, w) = S(u, v) + w d
    x = volume_samples(solid)
    np.testing.assert_allclose(solid.evaluate(*x.T), quarter.evaluate(x[:, 0], x[:, 1]) + x[:, 2:] * d,
                               rtol=0, atol=1e-14)
    radius = np.hypot(*(face_grid(faces["u1"]) - face_grid(faces["u1"])[..., 2:] / 2.0 * d)[..., :2]
                      .transpose(2, 0, 1))
    np.testing.assert_allclose(radius, 2.0, rtol=0, atol=1e-14)      # the outer cylinder wall
    assert solid.weights is not None and right_handed(solid)
    assert solid.volume() == pytest.approx(2.0 * 3 * np.pi / 4, rel=1e-12)
    with pytest.raises(InvalidGeometryError, match="vector must be non-zero"):
        extrude(quarter, (0, 0, 0))
    with pytest.raises(InvalidGeometryError, match="surface must be a NurbsSurface, got list"):
        extrude([], d)


# ------------------------------------------------------------------ revolve
def _distance_to_axis(points, a, d):
    rel = points - a
    return np.linalg.norm(rel - (rel @ d)[..., None] * d, axis=-1)


@pytest.mark.parametrize("degrees, n_arcs", [(135, 2), (250, 3), (90, 1), (360, 4)])
def test_revolve_makes_exact_circles(degrees, n_arcs):
    angle = np.radians(degrees)
    a = np.array([0.5, -1.0, 2.0])
    d = np.array([1.0, 2.0, 2.0]) / 3.0
    # a planar profile not touching the axis: the rectangle in the plane of the axis and e
    e = np.cross(d, [1.0, 0, 0])
    e /= np.linalg.norm(e)
    cp = np.array([[a + r * e + h * d for h in (-0.5, 1.0)] for r in (1.0, 2.5)])
    profile = NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    solid = revolve(profile, a, 3 * d, angle)
    assert solid.degree_w == 2 and solid.n_control[2] == 2 * n_arcs + 1
    assert solid.domain[4:] == (0.0, angle)
    x = volume_samples(solid)
    points = solid.evaluate(*x.T)
    base = profile.evaluate(x[:, 0], x[:, 1])
    # every point stays at its profile point's distance from the axis and height along it
    np.testing.assert_allclose(_distance_to_axis(points, a, d), _distance_to_axis(base, a, d),
                               rtol=0, atol=1e-14)
    np.testing.assert_allclose((points - a) @ d, (base - a) @ d, rtol=0, atol=1e-14)
    # at the knots of w the turn is the knot value
    faces = solid.boundary()
    e2 = np.cross(d, e)
    for knot in np.unique(solid.knots_w):
        ring = solid.isosurface(knot, "w")
        rel = face_grid(profile) - a
        direction = np.cos(knot) * e + np.sin(knot) * e2
        turned = a + (rel @ d)[..., None] * d + (rel @ e)[..., None] * direction
        np.testing.assert_allclose(face_grid(ring), turned, rtol=0, atol=1e-14)
    np.testing.assert_allclose(face_grid(faces["w0"]), face_grid(profile), rtol=0, atol=0)
    # volume: angle / 2 (r2^2 - r1^2) h
    assert solid.volume() == pytest.approx(angle / 2 * (2.5 ** 2 - 1.0) * 1.5, rel=1e-12)
    # S_u x S_v = e x d points against the motion d x e: left-handed; about -d right-handed
    assert not right_handed(solid) and right_handed(revolve(profile, a, -d, angle))
    exterior = tuple(solid.exterior_faces())
    if degrees == 360:
        np.testing.assert_array_equal(solid.control_points[:, :, -1], solid.control_points[:, :, 0])
        assert exterior == ("u0", "u1", "v0", "v1")
    else:
        assert exterior == FACES
    assert collapsed_names(solid) == []


def test_revolve_a_profile_touching_the_axis_collapses_the_face_on_it():
    cone = NurbsSurface(np.array([[[0, 0, 0], [0, 0, 1]], [[1, 0, 0], [0, 0, 1.0]]]),
                        [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)        # triangle, u0 on the axis
    solid = revolve(cone, (0, 0, 0), (0, 0, 1))
    assert collapsed_names(solid) == ["u0", "v1"]          # the axis segment and the apex
    assert list(solid.exterior_faces()) == ["u1", "v0"]    # the cone and its base disk
    assert solid.volume() == pytest.approx(np.pi / 3, rel=1e-12)


@pytest.mark.parametrize("kwargs, message", [
    ({"angle": 0.0}, "angle must be finite and > 0, got 0.0"),
    ({"angle": 7.0}, r"angle must be <= 2 pi, got 7.0"),
    ({"axis_direction": (0, 0, 0)}, "axis_direction must be non-zero"),
    ({"axis_point": (0, 0)}, "axis_point must be 3 finite numbers"),
])
def test_revolve_refuses_bad_input(kwargs, message):
    args = {"surface": rectangle(1, 2, 0, 1), "axis_point": (0, 0, 0), "axis_direction": (0, 0, 1),
            "angle": 1.0, **kwargs}
    with pytest.raises(InvalidGeometryError, match=message):
        revolve(**args)


# -------------------------------------------------------------------- ruled
def test_ruled_joins_two_incompatible_surfaces_by_straight_lines():
    rng = np.random.default_rng(4)
    # a: bilinear over [0, 1]^2 in y = 0 (normal -y); b: rational biquadratic with an interior
    # knot over [2, 5] x [-1, 1], near y = -2
    a = rectangle(0, 1, 0, 1)
    cp = np.stack(np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 3), indexing="ij"), -1)
    cp = np.concatenate([cp[..., :1], -2 + rng.uniform(-0.2, 0.2, cp.shape[:2] + (1,)), cp[..., 1:]], -1)
    b = NurbsSurface(cp, [2, 2, 2, 3.5, 5, 5, 5], [-1, -1, -1, 1, 1, 1], 2, 2,
                     rng.uniform(0.5, 2.0, (4, 3)))
    solid = ruled(a, b)
    assert solid.degrees == (2, 2, 1) and solid.domain == (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)
    s = np.linspace(0, 1, 31)
    S, T = np.meshgrid(s, s, indexing="ij")
    faces = solid.boundary()
    np.testing.assert_allclose(faces["w0"].evaluate(S, T), a.evaluate(S, T), rtol=0, atol=1e-14)
    # b's parameters mapped affinely onto a's domain
    np.testing.assert_allclose(faces["w1"].evaluate(S, T), b.evaluate(2 + 3 * S, -1 + 2 * T), rtol=0,
                               atol=1e-14)
    # the w lines are straight: x(u, v, w) on the segment from A(u, v) to B(u, v)
    x = volume_samples(solid)
    pa, pb = a.evaluate(x[:, 0], x[:, 1]), b.evaluate(2 + 3 * x[:, 0], -1 + 2 * x[:, 1])
    p = solid.evaluate(*x.T)
    t = np.einsum("ij,ij->i", p - pa, pb - pa) / np.einsum("ij,ij->i", pb - pa, pb - pa)
    np.testing.assert_allclose(p, pa + t[:, None] * (pb - pa), rtol=0, atol=1e-13)
    assert np.all((t > -1e-12) & (t < 1 + 1e-12)) and right_handed(solid)


def test_ruled_between_a_face_and_its_copy_is_an_extrusion():
    flat = NurbsSurface(np.array([[[0, 0, 0], [0, 1, 0]], [[1, 0, 0], [1, 1, 0.]]]),
                        [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    slab = ruled(flat, flat.translated([0.5, 0, 3]).elevate_degree(1, 0))
    reference = extrude(flat, (0.5, 0, 3))
    x = volume_samples(slab)
    np.testing.assert_allclose(slab.evaluate(*x.T), reference.evaluate(*x.T), rtol=0, atol=1e-14)
    assert slab.volume() == pytest.approx(3.0, rel=1e-14)
    with pytest.raises(InvalidGeometryError, match="surface_b must lie in 3D, got dimension 2"):
        ruled(flat, NurbsSurface(np.zeros((2, 2, 2)), [0, 0, 1, 1], [0, 0, 1, 1], 1, 1))


# ------------------------------------------------------------ sphere (Fig. 3)
def test_solid_sphere_boundary_is_the_exact_sphere():
    centre, r = np.array([1.0, -2.0, 0.5]), 2.5
    ball = solid_sphere(r, centre)
    assert ball.degrees == (2, 2, 2) and ball.n_control == (3, 5, 9)
    assert ball.domain == (0.0, 1.0, 0.0, np.pi, 0.0, 2 * np.pi)
    faces = ball.boundary()
    sphere = face_grid(faces["u1"], 101)
    assert np.abs(np.linalg.norm(sphere - centre, axis=-1) - r).max() <= 1e-12 * r
    # at the knots the parameters are the spherical coordinates
    for t in (0.0, np.pi / 2, np.pi):
        for phi in np.arange(5) * np.pi / 2:
            expected = centre + 0.5 * r * np.array([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi),
                                                    np.cos(t)])
            np.testing.assert_allclose(ball.evaluate(0.5, t, phi), expected, rtol=0, atol=1e-14)
    # every point inside at a distance proportional to s
    x = volume_samples(ball)
    np.testing.assert_allclose(np.linalg.norm(ball.evaluate(*x.T) - centre, axis=1), r * x[:, 0],
                               rtol=0, atol=1e-13)
    assert right_handed(ball)


def test_solid_sphere_reports_its_collapsed_faces():
    ball = solid_sphere(1.5, (0, 0, 3))
    assert collapsed_names(ball) == ["u0", "v0", "v1"]
    faces = ball.boundary()
    np.testing.assert_allclose(face_grid(faces["u0"]), np.broadcast_to([0, 0, 3.0], (41, 41, 3)), atol=0)
    for name, pole in (("v0", 1.0), ("v1", -1.0)):
        segment = face_grid(faces[name])
        np.testing.assert_allclose(segment[..., :2], 0.0, atol=0)
        heights = 3.0 + pole * 1.5 * np.linspace(0, 1, 41)[:, None]        # along s, the radius
        np.testing.assert_allclose(segment[..., 2], np.broadcast_to(heights, (41, 41)), rtol=0,
                                   atol=1e-14)
    np.testing.assert_array_equal(face_grid(faces["w0"]), face_grid(faces["w1"]))   # the seam
    assert list(ball.exterior_faces()) == ["u1"]
    assert ball.volume() == pytest.approx(4 / 3 * np.pi * 1.5 ** 3, rel=1e-12)


# ------------------------------------------------------------- torus (Fig. 8)
@pytest.mark.parametrize("centre, axis", [((0, 0, 0), (0, 0, 1)), ((1, 2, -3), (1, -2, 0.5))])
def test_solid_torus_boundary_satisfies_the_implicit_equation(centre, axis):
    big, small = 3.0, 1.2
    ring = solid_torus(big, small, centre, axis)
    assert ring.degrees == (2, 2, 2) and ring.n_control == (3, 9, 9)
    c, d = np.array(centre, float), np.array(axis, float) / np.linalg.norm(axis)
    faces = ring.boundary()
    points = face_grid(faces["u1"], 101) - c
    z = points @ d
    rho = np.linalg.norm(points - z[..., None] * d, axis=-1)
    assert np.abs((rho - big) ** 2 + z ** 2 - small ** 2).max() <= 1e-12 * big ** 2
    # the collapsed face u0 is the centre circle of the tube
    core = face_grid(faces["u0"]) - c
    np.testing.assert_allclose(core @ d, 0.0, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(core, axis=-1), big, rtol=0, atol=1e-13)
    assert collapsed_names(ring) == ["u0"]
    assert list(ring.exterior_faces()) == ["u1"]                       # v and w are seams
    np.testing.assert_allclose(face_grid(faces["v0"]), face_grid(faces["v1"]), rtol=0, atol=1e-14)
    np.testing.assert_allclose(face_grid(faces["w0"]), face_grid(faces["w1"]), rtol=0, atol=1e-14)
    assert right_handed(ring)
    assert ring.volume() == pytest.approx(2 * np.pi ** 2 * big * small ** 2, rel=1e-12)


def test_solid_torus_refuses_a_self_intersecting_torus():
    with pytest.raises(InvalidGeometryError, match=r"major must be > minor \(a ring torus\), "
                                                   r"got major = 1.0, minor = 1.0"):
        solid_torus(1.0, 1.0)
    with pytest.raises(InvalidGeometryError, match="minor must be finite and > 0"):
        solid_torus(1.0, -0.5)
    with pytest.raises(InvalidGeometryError, match="axis must be non-zero"):
        solid_torus(2.0, 1.0, axis=(0, 0, 0))
