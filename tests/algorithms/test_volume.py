"""The trivariate NURBS solid (004 §3): evaluation, derivatives, knot operations, Bézier
decomposition, isosurfaces and boundary, volume, point inversion, validation."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.strategies import random_knots

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.basis import collocation_matrix, greville_abscissae
from surfprep.algorithms.volume import FACES, NurbsVolume, as_axis
from surfprep.algorithms.volume_builders import block, extrude, solid_sphere, solid_torus
from surfprep.errors import InvalidGeometryError

R2 = np.sqrt(0.5)


# ------------------------------------------------------------------ builders
def random_volume(seed: int, degrees=(2, 3, 1), breaks=(2, 1, 2), rational=True,
                  clamped=True) -> NurbsVolume:
    """Random net over random (non-[0, 1]) domains with multiple interior knots."""
    rng = np.random.default_rng(seed)
    knots = [random_knots(rng, p, b, p, clamped) for p, b in zip(degrees, breaks)]
    shape = tuple(k.size - p - 1 for k, p in zip(knots, degrees))
    points = rng.uniform(-10, 10, shape + (3,))
    weights = rng.uniform(0.3, 3.0, shape) if rational else None
    return NurbsVolume(points, *knots, *degrees, weights)


def samples(volume: NurbsVolume, n: int = 400, seed: int = 0) -> np.ndarray:
    """Random parameters ``(n, 3)`` in the domain, the corners included."""
    lo, hi = np.array(volume.domain[0::2]), np.array(volume.domain[1::2])
    rng = np.random.default_rng(seed)
    corners = np.stack(np.meshgrid(*zip(lo, hi), indexing="ij"), -1).reshape(-1, 3)
    return np.concatenate([corners, lo + (hi - lo) * rng.random((n, 3))])


def scale_of(volume: NurbsVolume) -> float:
    box = volume.bounding_box()
    return float(np.linalg.norm(box[1] - box[0]))


def f_poly(u, v, w):
    """A polynomial map of degrees (2, 3, 2) and its partial derivatives, exactly."""
    return np.stack([u * u * v - w, v ** 3 + u * w * w, u * v * w + 1.0], axis=-1)


def f_poly_derivative(u, v, w, a, b, c):
    """``d^{a+b+c} f / du^a dv^b dw^c`` of :func:`f_poly`, by hand."""
    zero, one = np.zeros_like(u), np.ones_like(u)
    x = {(0, 0, 0): u * u * v - w, (1, 0, 0): 2 * u * v, (0, 1, 0): u * u, (0, 0, 1): -one,
         (2, 0, 0): 2 * v, (1, 1, 0): 2 * u, (2, 1, 0): 2 * one}
    y = {(0, 0, 0): v ** 3 + u * w * w, (0, 1, 0): 3 * v * v, (0, 2, 0): 6 * v, (0, 3, 0): 6 * one,
         (1, 0, 0): w * w, (0, 0, 1): 2 * u * w, (1, 0, 1): 2 * w, (0, 0, 2): 2 * u,
         (1, 0, 2): 2 * one}
    z = {(0, 0, 0): u * v * w + 1.0, (1, 0, 0): v * w, (0, 1, 0): u * w, (0, 0, 1): u * v,
         (1, 1, 0): w, (1, 0, 1): v, (0, 1, 1): u, (1, 1, 1): one}
    return np.stack([d.get((a, b, c), zero) for d in (x, y, z)], axis=-1)


#: knots of degrees (2, 3, 2) over [-1, 2] x [0.5, 3] x [1, 4] with interior knots
POLY_KNOTS = [np.array([-1, -1, -1, 0.2, 0.2, 1.1, 2, 2, 2.0]),
              np.array([0.5, 0.5, 0.5, 0.5, 1.7, 3, 3, 3, 3]),
              np.array([1, 1, 1, 2.5, 4, 4, 4.0])]


def polynomial_volume(f=f_poly, degrees=(2, 3, 2), knots=POLY_KNOTS) -> NurbsVolume:
    """``f`` (:func:`f_poly` by default) represented exactly: interpolated at the Greville
    points of a spline space that contains it."""
    grev = [greville_abscissae(k, p) for k, p in zip(knots, degrees)]
    values = f(*np.meshgrid(*grev, indexing="ij"))
    for axis, (k, p, g) in enumerate(zip(knots, degrees, grev)):
        matrix = collocation_matrix(k, p, g)
        moved = np.moveaxis(values, axis, 0)
        values = np.moveaxis(np.linalg.solve(matrix, moved.reshape(moved.shape[0], -1))
                             .reshape(moved.shape), 0, axis)
    return NurbsVolume(values, *knots, *degrees)


def trilinear(corners, u, v, w):
    """The trilinear interpolant of the 8 ``corners[i, j, k]`` on [0, 1]^3, by its formula."""
    out = 0.0
    for i in (0, 1):
        for j in (0, 1):
            for k in (0, 1):
                share = (u if i else 1 - u) * (v if j else 1 - v) * (w if k else 1 - w)
                out = out + np.asarray(share)[..., None] * corners[i, j, k]
    return out


# ------------------------------------------------------------- evaluation
def test_trilinear_hexahedron_matches_the_trilinear_formula():
    rng = np.random.default_rng(3)
    corners = np.stack(np.meshgrid([0, 1.0], [0, 1.0], [0, 1.0], indexing="ij"), -1) \
        + 0.2 * rng.standard_normal((2, 2, 2, 3))
    hexa = NurbsVolume(corners, [0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1], 1, 1, 1)
    u, v, w = rng.random((3, 500))
    np.testing.assert_allclose(hexa.evaluate(u, v, w), trilinear(corners, u, v, w), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(hexa.evaluate(1, 0, 1), corners[1, 0, 1])
    grid = hexa.evaluate_grid([0, 0.3], [0.5], [0.1, 0.7, 1])
    assert grid.shape == (2, 1, 3, 3)
    np.testing.assert_allclose(grid[1, 0, 2], trilinear(corners, 0.3, 0.5, 1.0), atol=1e-15)
    assert hexa(0.1, 0.2, 0.3).shape == (3,)
    assert hexa.evaluate(np.zeros((4, 5)), 0.5, np.ones(5)).shape == (4, 5, 3)


def test_polynomial_volume_values_and_derivatives_are_exact():
    solid = polynomial_volume()
    x = samples(solid, 300, seed=1)
    u, v, w = x.T
    np.testing.assert_allclose(solid.evaluate(u, v, w), f_poly(u, v, w), rtol=0, atol=1e-11)
    d = solid.derivatives(u, v, w, 3)
    assert d.shape == (x.shape[0], 4, 4, 4, 3)
    for a in range(4):
        for b in range(4):
            for c in range(4):
                np.testing.assert_allclose(d[:, a, b, c], f_poly_derivative(u, v, w, a, b, c),
                                           rtol=0, atol=1e-9, err_msg=f"derivative {(a, b, c)}")


def _richardson(f, x, h):
    """Central difference of ``f`` at ``x`` along the step vector ``h (3,)``, Richardson
    extrapolated (error O(|h|^4))."""
    size = float(np.linalg.norm(h))
    d_h = (f(x + h) - f(x - h)) / (2 * size)
    d_h2 = (f(x + h / 2) - f(x - h / 2)) / size
    return (4 * d_h2 - d_h) / 3


def _interior(volume: NurbsVolume, x: np.ndarray, gap: float) -> np.ndarray:
    """Parameters at least ``gap`` (share of the range) from every knot: the derivatives
    are smooth there."""
    keep = np.ones(x.shape[0], dtype=bool)
    for axis, knots in enumerate(volume.knots):
        span = volume.domain[2 * axis + 1] - volume.domain[2 * axis]
        keep &= np.abs(x[:, axis, None] - knots[None, :]).min(axis=1) > gap * span
    return x[keep]


def _step(solid: NurbsVolume, axis: int) -> np.ndarray:
    h = np.zeros(3)
    h[axis] = 1e-4 * (solid.domain[2 * axis + 1] - solid.domain[2 * axis])
    return h


def _unit(*axes: int) -> tuple[int, int, int]:
    index = [0, 0, 0]
    for axis in axes:
        index[axis] += 1
    return tuple(index)


def test_rational_derivatives_match_finite_differences():
    solid = random_volume(5, degrees=(3, 2, 2))
    x = _interior(solid, samples(solid, 300, seed=2), 0.01)
    assert x.shape[0] > 100
    d = solid.derivatives(*x.T, 2)
    for axis in range(3):
        fd = _richardson(lambda y: solid.evaluate(*y.T), x, _step(solid, axis))
        exact = d[(slice(None),) + _unit(axis)]
        np.testing.assert_allclose(exact, fd, rtol=0, atol=1e-7 * np.abs(exact).max())
        # second and mixed derivatives: differences of the first ones
        for other in range(3):
            first = _unit(axis)
            fd = _richardson(lambda y, k=first: solid.derivatives(*y.T, 1)[(slice(None),) + k], x,
                             _step(solid, other))
            exact = d[(slice(None),) + _unit(axis, other)]
            np.testing.assert_allclose(exact, fd, rtol=0, atol=1e-6 * np.abs(exact).max())


def test_jacobian_columns():
    solid = random_volume(6)
    x = samples(solid, 50)
    jac = solid.jacobian(*x.T)
    d = solid.derivatives(*x.T, 1)
    assert jac.shape == (x.shape[0], 3, 3)
    np.testing.assert_array_equal(jac[..., 0], d[:, 1, 0, 0])
    np.testing.assert_array_equal(jac[..., 1], d[:, 0, 1, 0])
    np.testing.assert_array_equal(jac[..., 2], d[:, 0, 0, 1])
    cube = block((2.0, 3.0, 0.5), origin=(1, -1, 4), degrees=(3, 1, 2))
    np.testing.assert_allclose(cube.jacobian([0.1, 0.9], 0.5, [0.3, 1.0]),
                               np.broadcast_to(np.diag([2.0, 3.0, 0.5]), (2, 3, 3)), atol=1e-14)
    solid = polynomial_volume()
    u, v, w = samples(solid, 40).T
    exact = np.stack([f_poly_derivative(u, v, w, *e) for e in np.eye(3, dtype=int)], axis=-1)
    np.testing.assert_allclose(solid.jacobian(u, v, w), exact, rtol=0, atol=1e-9)


@pytest.mark.parametrize("rational", [False, True])
def test_grid_evaluation_equals_scattered(rational):
    solid = random_volume(7, rational=rational, clamped=False)
    lo, hi = np.array(solid.domain[0::2]), np.array(solid.domain[1::2])
    u, v, w = (np.linspace(a, b, n) for a, b, n in zip(lo, hi, (7, 5, 6)))
    grid = solid.derivatives_grid(u, v, w, 2)
    U, V, W = np.meshgrid(u, v, w, indexing="ij")
    scattered = solid.derivatives(U, V, W, 2)
    assert grid.shape == (7, 5, 6, 3, 3, 3, 3)
    np.testing.assert_allclose(grid, scattered, rtol=1e-12, atol=1e-12 * np.abs(scattered).max())
    np.testing.assert_allclose(solid.evaluate_grid(u, v, w), scattered[..., 0, 0, 0, :], rtol=0,
                               atol=1e-12 * scale_of(solid))


def test_the_solid_lies_in_its_control_net_box():
    solid = random_volume(8)
    points = solid.evaluate(*samples(solid, 2000).T)
    box = solid.bounding_box()
    assert np.all(points >= box[0] - 1e-12) and np.all(points <= box[1] + 1e-12)


# ---------------------------------------------------------- knot operations
def _same_geometry(a: NurbsVolume, b: NurbsVolume, x: np.ndarray) -> float:
    return float(np.abs(a.evaluate(*x.T) - b.evaluate(*x.T)).max())


@pytest.mark.parametrize("direction", ["u", "v", "w"])
def test_knot_insertion_and_refinement_keep_the_geometry(direction):
    solid = random_volume(9, clamped=False)
    axis = as_axis(direction)
    lo, hi = solid.domain[2 * axis:2 * axis + 2]
    x = samples(solid, 1500, seed=3)
    once = solid.insert_knot(lo + 0.37 * (hi - lo), direction, 1)
    assert once.n_control[axis] == solid.n_control[axis] + 1
    assert once.knots[axis].size == solid.knots[axis].size + 1
    assert _same_geometry(solid, once, x) <= 1e-12 * scale_of(solid)
    fractions = [0.1, 0.5, 0.5, 0.77] if solid.degrees[axis] > 1 else [0.1, 0.5, 0.77]
    refined = solid.refine(lo + (hi - lo) * np.array(fractions), direction)
    assert refined.n_control[axis] == solid.n_control[axis] + len(fractions)
    assert _same_geometry(solid, refined, x) <= 1e-12 * scale_of(solid)
    for other in range(3):
        if other != axis:
            np.testing.assert_array_equal(refined.knots[other], solid.knots[other])


@pytest.mark.parametrize("direction", ["u", "v", "w"])
def test_split_and_restrict_keep_the_geometry(direction):
    solid = random_volume(10, clamped=False)
    axis = as_axis(direction)
    lo, hi = solid.domain[2 * axis:2 * axis + 2]
    cut = lo + 0.41 * (hi - lo)
    left, right = solid.split(cut, direction)
    x = samples(solid, 1500, seed=4)
    for piece in (left, right):
        a, b = piece.domain[2 * axis:2 * axis + 2]
        inside = x[(x[:, axis] >= a) & (x[:, axis] <= b)]
        assert inside.shape[0] > 100
        assert _same_geometry(solid, piece, inside) <= 1e-12 * scale_of(solid)
    assert left.domain[2 * axis + 1] == right.domain[2 * axis] == cut
    box = solid.domain
    bounds = [box[0] + 0.2 * (box[1] - box[0]), box[0] + 0.9 * (box[1] - box[0]),
              None, box[2] + 0.5 * (box[3] - box[2]), box[4] + 0.1 * (box[5] - box[4]), None]
    sub = solid.restrict(*bounds)
    expected = [b if b is not None else d for b, d in zip(bounds, box)]
    assert sub.domain == tuple(expected)
    y = samples(sub, 1500, seed=5)
    assert _same_geometry(solid, sub, y) <= 1e-12 * scale_of(solid)
    clamped = solid.clamp()
    assert _same_geometry(solid, clamped, x) <= 1e-12 * scale_of(solid)
    for k, p in zip(clamped.knots, clamped.degrees):
        assert np.all(k[:p + 1] == k[0]) and np.all(k[-p - 1:] == k[-1])


def test_degree_elevation_and_translation_keep_the_geometry():
    solid = random_volume(11, degrees=(1, 2, 2))
    x = samples(solid, 800)
    higher = solid.elevate_degree(2, 0, 1)
    assert higher.degrees == (3, 2, 3)
    assert _same_geometry(solid, higher, x) <= 1e-11 * scale_of(solid)
    moved = solid.translated([1.0, -2.0, 0.5])
    np.testing.assert_allclose(moved.evaluate(*x.T), solid.evaluate(*x.T) + [1.0, -2.0, 0.5],
                               rtol=0, atol=1e-12 * scale_of(solid))


def test_bezier_decomposition_reproduces_the_volume():
    solid = random_volume(12, degrees=(2, 1, 3), breaks=(2, 1, 1), clamped=False)
    bez = solid.bezier_volumes()
    ku, kv, kw = bez.shape
    assert (ku, kv, kw) == (3, 2, 2)
    assert bez.pieces.shape == (3, 2, 2, 3, 2, 4, 4) and bez.boxes.shape == (3, 2, 2, 2, 3)
    rng = np.random.default_rng(6)
    for i in range(ku):
        for j in range(kv):
            for k in range(kw):
                piece = bez.piece(i, j, k)
                lo = np.array([bez.intervals_u[i, 0], bez.intervals_v[j, 0], bez.intervals_w[k, 0]])
                hi = np.array([bez.intervals_u[i, 1], bez.intervals_v[j, 1], bez.intervals_w[k, 1]])
                x = lo + (hi - lo) * rng.random((200, 3))
                points = solid.evaluate(*x.T)
                np.testing.assert_allclose(piece.evaluate(*x.T), points, rtol=0,
                                           atol=1e-12 * scale_of(solid))
                assert np.all(points >= bez.boxes[i, j, k, 0] - 1e-12)
                assert np.all(points <= bez.boxes[i, j, k, 1] + 1e-12)
    # the spans tile the domain
    assert bez.intervals_u[0, 0] == solid.domain[0] and bez.intervals_w[-1, 1] == solid.domain[5]


# ------------------------------------------------------ isosurfaces, boundary
@pytest.mark.parametrize("direction", ["u", "v", "w"])
@pytest.mark.parametrize("fraction", [0.0, 0.3, 1.0])
def test_isosurfaces_hold_the_parameter(direction, fraction):
    solid = random_volume(13, clamped=False)
    axis = as_axis(direction)
    lo, hi = solid.domain[2 * axis:2 * axis + 2]
    value = lo + fraction * (hi - lo)
    surface = solid.isosurface(value, direction)
    a, b = (k for k in range(3) if k != axis)
    assert surface.domain == solid.domain[2 * a:2 * a + 2] + solid.domain[2 * b:2 * b + 2]
    assert (surface.degree_u, surface.degree_v) == (solid.degrees[a], solid.degrees[b])
    s = np.linspace(*surface.domain[:2], 23)
    t = np.linspace(*surface.domain[2:], 19)
    S, T = np.meshgrid(s, t, indexing="ij")
    x = [None, None, None]
    x[axis], x[a], x[b] = np.full_like(S, value), S, T
    np.testing.assert_allclose(surface.evaluate_grid(s, t), solid.evaluate(*x), rtol=0,
                               atol=1e-12 * scale_of(solid))


def test_boundary_faces_and_their_orientation():
    cube = block((2.0, 3.0, 4.0), origin=(1.0, 1.0, 1.0), degrees=(2, 1, 3))
    faces = cube.boundary()
    assert tuple(faces) == FACES
    centre = np.array([2.0, 2.5, 3.0])
    outward = {"u0": [-1, 0, 0], "u1": [1, 0, 0], "v0": [0, -1, 0], "v1": [0, 1, 0],
               "w0": [0, 0, -1], "w1": [0, 0, 1]}
    # the notes of NurbsVolume.boundary: S_a x S_b points out on u1, v0, w1
    sign = {"u0": -1, "u1": 1, "v0": 1, "v1": -1, "w0": -1, "w1": 1}
    for name, face in faces.items():
        assert isinstance(face, NurbsSurface)
        point = face.evaluate(0.5, 0.5)
        np.testing.assert_allclose((point - centre) / np.abs(point - centre).max(),
                                   np.sign(outward[name]) * 1.0, atol=1e-14)
        np.testing.assert_allclose(face.normals(0.3, 0.6), sign[name] * np.array(outward[name]),
                                   atol=1e-14)
    assert not any(cube.collapsed_faces().values())
    assert tuple(cube.exterior_faces()) == FACES


# -------------------------------------------------------------------- volume
def test_volume_of_blocks_and_polynomial_solids():
    assert block((2.0, 3.0, 0.5), degrees=(3, 2, 4)).volume() == pytest.approx(3.0, rel=1e-14)
    # x = (u, v, w (1 + u v)) on [0, 1]^3: volume = integral (1 + u v) = 5/4, det J of degree 2
    corners = np.stack(np.meshgrid([0, 1.0], [0, 1.0], [0, 1.0], indexing="ij"), -1)
    corners[1, 1, 1, 2] = 2.0
    hexa = NurbsVolume(corners, [0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1], 1, 1, 1)
    np.testing.assert_allclose(hexa.evaluate(0.5, 0.5, 1.0)[2], 1.25, rtol=1e-15)
    assert hexa.volume() == pytest.approx(1.25, rel=1e-14)
    # x = (u, v + u^3, w (1 + u^2 v^2)): det J = 1 + u^2 v^2, over [-1, 2] x [0.5, 3] x [1, 4]
    solid = polynomial_volume(lambda u, v, w: np.stack([u, v + u ** 3, w * (1 + u * u * v * v)], -1),
                              (3, 2, 1), [np.repeat([-1.0, 0.5, 2.0], [4, 1, 4]),
                                          np.repeat([0.5, 3.0], 3), np.repeat([1.0, 2.0, 4.0], [2, 1, 2])])
    exact = 3 * 2.5 * 3 + (8 + 1) / 3 * (27 - 0.125) / 3 * 3
    assert solid.volume() == pytest.approx(exact, rel=1e-13)


def test_default_quadrature_is_exact_for_polynomial_solids():
    """det J has degree 3p - 1 in a direction of degree p: ceil(3p / 2) Gauss points per
    span integrate it exactly, one fewer does not."""
    rng = np.random.default_rng(20)
    degrees = (3, 2, 4)
    knots = [np.repeat([0.0, 0.4, 1.0], [p + 1, 1, p + 1]) for p in degrees]
    grev = [greville_abscissae(k, p) for k, p in zip(knots, degrees)]
    net = np.stack(np.meshgrid(*grev, indexing="ij"), -1)
    net += 0.04 * rng.standard_normal(net.shape)                   # det J stays > 0
    solid = NurbsVolume(net, *knots, *degrees)
    assert np.linalg.det(solid.jacobian(*samples(solid, 2000).T)).min() > 0
    reference = solid.volume(n_points=20)
    assert solid.volume() == pytest.approx(reference, rel=1e-14)
    assert abs(solid.volume(n_points=5) - reference) > 1e-12        # 5 < ceil(3 * 4 / 2)


def test_volume_of_an_extruded_rational_surface():
    # quarter annulus 1 <= r <= 2 in the plane z = 0 (rational in v), area 3 pi / 4
    arc = np.array([[1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    net = np.stack([arc, 2 * arc])
    quarter = NurbsSurface(net, [0, 0, 1, 1], [0, 0, 0, 1, 1, 1], 1, 2,
                           np.array([[1, R2, 1], [1, R2, 1]]))
    solid = extrude(quarter, (0.3, -0.2, 2.0))
    assert solid.volume() == pytest.approx(2.0 * 3 * np.pi / 4, rel=1e-12)


def test_volume_of_the_solid_sphere_and_torus():
    r = 1.7
    ball = solid_sphere(r, (3.0, -1.0, 2.0))
    assert abs(ball.volume() - 4 / 3 * np.pi * r ** 3) <= 1e-10 * 4 / 3 * np.pi * r ** 3
    big, small = 2.5, 0.75
    ring = solid_torus(big, small, (1, 2, 3), (1, -2, 0.5))
    exact = 2 * np.pi ** 2 * big * small ** 2
    assert abs(ring.volume() - exact) <= 1e-10 * exact


def test_volume_needs_a_solid_in_space():
    flat = NurbsVolume(np.zeros((2, 2, 2, 2)), [0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1], 1, 1, 1)
    with pytest.raises(InvalidGeometryError, match="needs a solid in 3D, got dimension 2"):
        flat.volume()
    with pytest.raises(InvalidGeometryError, match="n_points must be an integer >= 1"):
        block(1.0).volume(n_points=0)


# ----------------------------------------------------------------- inversion
@pytest.mark.parametrize("kind", ["sphere", "torus"])
def test_invert_round_trip_on_rational_solids(kind):
    rng = np.random.default_rng(14)
    if kind == "sphere":
        solid = solid_sphere(2.0, (1.0, 0.5, -0.3))
        lo, hi = [0.05, 0.05, 0.0], [1.0, np.pi - 0.05, 2 * np.pi]      # away from the axis
    else:
        solid = solid_torus(3.0, 1.0, (1, 2, 3), (1, 1, 0))
        lo, hi = [0.05, 0.0, 0.0], [1.0, 2 * np.pi, 2 * np.pi]
    uvw = rng.uniform(lo, hi, (800, 3))
    points = solid.evaluate(*uvw.T)
    result = solid.invert(points)
    assert result.inside.all()
    assert np.abs(solid.evaluate(*result.uvw.T) - points).max() <= 1e-12
    assert np.abs(result.points - points).max() <= 1e-12 and result.distance.max() <= 1e-12
    gap = np.abs(result.uvw - uvw)
    gap[:, 1:] = np.minimum(gap[:, 1:], 2 * np.pi - gap[:, 1:])        # the seams
    if kind == "sphere":
        gap[:, 1] = np.abs(result.uvw[:, 1] - uvw[:, 1])
    assert gap.max() <= 1e-10


def test_invert_reports_points_outside_the_sphere():
    centre, r = np.array([1.0, 0.5, -0.3]), 2.0
    ball = solid_sphere(r, centre)
    rng = np.random.default_rng(15)
    d = rng.standard_normal((300, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    far = centre + d * rng.uniform(2.01, 6.0, (300, 1))
    near = centre + d * rng.uniform(0.0, 1.99, (300, 1))
    result = ball.invert(np.concatenate([far, near]))
    assert not result.inside[:300].any() and result.inside[300:].all()
    np.testing.assert_allclose(result.distance[:300], np.linalg.norm(far - centre, axis=1) - r,
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(result.uvw[:300, 0], 1.0, rtol=0, atol=0)   # on the face u1
    np.testing.assert_allclose(result.points[:300], centre + r * d, rtol=0, atol=1e-12)
    assert result.distance[300:].max() <= 1e-12


def test_invert_classifies_points_against_the_implicit_torus():
    ring = solid_torus(3.0, 1.0)
    rng = np.random.default_rng(16)
    points = rng.uniform(-4.5, 4.5, (1500, 3)) * [1, 1, 0.4]
    signed = np.hypot(np.hypot(points[:, 0], points[:, 1]) - 3.0, points[:, 2]) - 1.0
    points = points[np.abs(signed) > 1e-6]
    signed = signed[np.abs(signed) > 1e-6]
    result = ring.invert(points)
    np.testing.assert_array_equal(result.inside, signed < 0)
    np.testing.assert_allclose(result.distance[signed > 0], signed[signed > 0], rtol=0, atol=1e-12)
    assert result.distance[signed < 0].max() <= 1e-12
    # the centre of the hole: the nearest points are the inner equator, 2 away
    hole = ring.invert([[0.0, 0.0, 0.0]])
    assert not hole.inside[0] and hole.distance[0] == pytest.approx(2.0, abs=1e-12)


def test_invert_retries_points_whose_first_newton_run_fails():
    """Points just before the seam w = 2 pi with one seed: about half start from the
    samples at w = 0 (the same points in space) and stall on the box face; the inward
    foot on the torus tells they are inside, and the second run from more seeds finds them."""
    ring = solid_torus(3.0, 1.0)
    rng = np.random.default_rng(18)
    uvw = np.c_[rng.uniform(0.3, 1, 200), rng.uniform(0, 2 * np.pi, 200),
                rng.uniform(2 * np.pi - 0.05, 2 * np.pi, 200)]
    points = ring.evaluate(*uvw.T)
    result = ring.invert(points, n_seeds=1)
    assert result.inside.all() and result.distance.max() <= 1e-12
    np.testing.assert_allclose(result.uvw, uvw, rtol=0, atol=1e-10)


def test_invert_near_the_collapsed_faces_of_the_sphere():
    ball = solid_sphere(1.0)
    rng = np.random.default_rng(17)
    centre = rng.uniform(-1e-6, 1e-6, (100, 3))
    axis = np.c_[rng.uniform(-1e-9, 1e-9, (100, 2)), rng.uniform(-0.99, 0.99, 100)]
    result = ball.invert(np.concatenate([centre, axis, [[0, 0, 0.0], [0, 0, 0.5]]]))
    assert result.inside.all()
    assert result.distance.max() <= 1e-10 * np.sqrt(12)


def test_invert_a_block_and_its_shapes():
    cube = block((2.0, 1.0, 1.0))
    result = cube.invert(np.array([[[1.0, 0.5, 0.5], [3.0, 0.5, 0.5]], [[3.0, 2.0, 2.0], [0, 0, 0]]]))
    assert result.uvw.shape == (2, 2, 3) and result.inside.shape == (2, 2)
    np.testing.assert_array_equal(result.inside, [[True, False], [False, True]])
    np.testing.assert_allclose(result.distance, [[0, 1.0], [np.sqrt(3.0), 0]], atol=1e-12)
    np.testing.assert_allclose(result.uvw[1, 0], [1, 1, 1], atol=1e-12)
    with pytest.raises(InvalidGeometryError, match=r"points must have shape \(\.\.\., 3\)"):
        cube.invert([[1.0, 2.0]])


# ---------------------------------------------------------------- validation
def _valid():
    return {"control_points": np.zeros((3, 2, 2, 3)), "knots_u": [0, 0, 0, 1, 1, 1],
                "knots_v": [0, 0, 1, 1], "knots_w": [0, 0, 1, 1], "degree_u": 2, "degree_v": 1, "degree_w": 1}


@pytest.mark.parametrize("change, message", [
    ({"control_points": np.zeros((3, 2, 3))}, r"control_points must have shape \(n_u, n_v, n_w, d\)"),
    ({"control_points": np.full((3, 2, 2, 3), np.nan)}, "control_points contain NaN"),
    ({"knots_u": [0, 0, 1, 1, 1]}, r"knots_u: expected n_control \+ degree \+ 1 = 6 knots"),
    ({"knots_v": [0, 1, 0.5, 1]}, "knots_v must be non-decreasing"),
    ({"knots_w": [0, 0, np.inf, 1]}, "knots_w contain NaN or infinite values"),
    ({"degree_w": 0}, "knots_w: degree must be an integer >= 1, got 0"),
    ({"degree_u": 3}, "knots_u: need at least degree \\+ 1 = 4 control points, got 3"),
    ({"weights": np.ones((3, 2))}, r"weights must have shape \(3, 2, 2\), got \(3, 2\)"),
    ({"weights": np.r_[np.ones(11), 0.0].reshape(3, 2, 2)}, "weights must be finite and > 0"),
])
def test_validation_errors(change, message):
    NurbsVolume(**_valid())
    with pytest.raises(InvalidGeometryError, match=message):
        NurbsVolume(**{**_valid(), **change})


def test_operation_errors():
    solid = random_volume(18)
    with pytest.raises(InvalidGeometryError, match="direction must be 'u', 'v' or 'w', got 'x'"):
        solid.isosurface(0.0, "x")
    with pytest.raises(InvalidGeometryError, match=r"isosurface parameter = .* is outside the domain .*"
                                                   r"\(direction w\)"):
        solid.isosurface(solid.domain[5] + 1.0, "w")
    with pytest.raises(InvalidGeometryError, match="isosurface parameter must be finite"):
        solid.isosurface(np.nan, 1)
    with pytest.raises(InvalidGeometryError, match="split parameter = .* interior of the domain"):
        solid.split(solid.domain[0], "u")
    with pytest.raises(InvalidGeometryError, match="multiplicity"):
        solid.insert_knot(solid.domain[2] + 0.5 * (solid.domain[3] - solid.domain[2]), "v", 4)
    with pytest.raises(InvalidGeometryError, match="degree elevation in w must be an integer >= 0"):
        solid.elevate_degree(0, 0, -1)
    with pytest.raises(ValueError, match="order must be >= 0"):
        solid.derivatives(0, 0, 0, -1)
    assert as_axis("W") == 2 and as_axis(1) == 1
    assert "NurbsVolume(degree=(2, 3, 1)" in repr(solid)


def test_construct_fast_and_from_homogeneous():
    solid = random_volume(19)
    again = NurbsVolume.from_homogeneous(solid.homogeneous_points(), *solid.knots, *solid.degrees)
    x = samples(solid, 200)
    assert _same_geometry(solid, again, x) <= 1e-12 * scale_of(solid)
    fast = NurbsVolume.construct_fast(solid.control_points, *solid.knots, *solid.degrees,
                                      solid.weights)
    assert not fast.control_points.flags.writeable and fast.is_rational
    assert _same_geometry(solid, fast, x) == 0.0
    with pytest.raises(InvalidGeometryError, match="homogeneous weights must be > 0"):
        NurbsVolume.from_homogeneous(-solid.homogeneous_points(), *solid.knots, *solid.degrees)
