"""Points inside a closed shell of trimmed faces by ray parity on the exact surfaces."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep import TrimmedFace
from surfprep.algorithms.containment import INSIDE, ON, OUTSIDE, classify_points, interior_point
from surfprep.algorithms.face_split import Cut, split_face
from surfprep.algorithms.volume_builders import block, solid_sphere, solid_torus
from surfprep.errors import InvalidGeometryError


def shell(solid):
    return [TrimmedFace(s, name=name) for name, s in solid.exterior_faces().items()]


@pytest.mark.parametrize(("solid", "inside"), [
    (block((2.0, 3.0, 4.0), origin=(-1, -1, -1)),
     lambda p: np.all((p > [-1, -1, -1]) & (p < [1, 2, 3]), axis=1)),
    (solid_sphere(2.0, (0.5, 0, 0)), lambda p: np.linalg.norm(p - [0.5, 0, 0], axis=1) < 2.0),
    (solid_torus(3.0, 1.0), lambda p: np.hypot(np.hypot(p[:, 0], p[:, 1]) - 3, p[:, 2]) < 1.0),
])
def test_random_points_against_the_implicit_answer(solid, inside):
    box = solid.bounding_box()
    points = np.random.default_rng(4).uniform(box[0] - 0.5, box[1] + 0.5, (400, 3))
    labels = classify_points(shell(solid), points, tol=1e-9)
    assert set(labels.tolist()) <= {INSIDE, OUTSIDE}
    np.testing.assert_array_equal(labels == INSIDE, inside(points))


def test_points_on_the_shell_and_on_its_edges_are_on():
    faces = shell(block(2.0, origin=(-1, -1, -1)))
    on = [[1.0, 0.2, 0.3], [0.0, -1.0, 0.0], [1.0, 1.0, 0.5], [1.0, 1.0, 1.0]]   # faces, an edge, a corner
    assert classify_points(faces, on, tol=1e-9).tolist() == [ON] * 4
    # along a ray that passes through an edge for the first direction, the next decides
    assert classify_points(faces, [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0]], tol=1e-9).tolist() == [INSIDE, OUTSIDE]


def test_trimmed_faces_count_only_inside_their_loops():
    """A ball's sphere cut along a circle into a cap and the rest: the two trimmed pieces
    close the same ball."""
    sphere = solid_sphere(1.0).exterior_faces()["u1"]
    u0, u1, v0, v1 = sphere.domain
    from surfprep import NurbsCurve
    # a circle of latitude: u fixed, v around (a closed cut in (u, v) across the seam
    # is a straight line from v0 to v1 with its ends on the seam)
    u = 0.3 * (u1 - u0) + u0
    pcurve = NurbsCurve(np.array([[u, v0], [u, v1]]), [v0, v0, v1, v1], 1)
    pieces = split_face(TrimmedFace(sphere), [Cut(pcurve, sphere.isocurve(u, "u"))])
    assert len(pieces) == 2
    points = np.random.default_rng(2).uniform(-1.3, 1.3, (300, 3))
    labels = classify_points(pieces, points, tol=1e-9)
    np.testing.assert_array_equal(labels == INSIDE, np.linalg.norm(points, axis=1) < 1.0)


def test_an_interior_point_lies_inside_the_face_away_from_its_edges():
    sphere = solid_sphere(1.0).exterior_faces()["u1"]
    u0, u1, v0, v1 = sphere.domain
    from surfprep import NurbsCurve
    u = 0.3 * (u1 - u0) + u0
    pcurve = NurbsCurve(np.array([[u, v0], [u, v1]]), [v0, v0, v1, v1], 1)
    for piece in split_face(TrimmedFace(sphere), [Cut(pcurve, sphere.isocurve(u, "u"))]):
        uv, xyz = interior_point(piece)
        np.testing.assert_allclose(np.linalg.norm(xyz), 1.0, atol=1e-12)
        # the cap's middle is its pole, the rest's is around the equator
        assert abs(uv[0] - u) > 0.1


def test_bad_input_is_refused():
    faces = shell(block(1.0))
    with pytest.raises(InvalidGeometryError, match="faces"):
        classify_points([], [[0, 0, 0]], tol=1e-9)
    with pytest.raises(InvalidGeometryError, match="tol"):
        classify_points(faces, [[0, 0, 0]], tol=-1.0)
    with pytest.raises(InvalidGeometryError, match="NaN"):
        classify_points(faces, [[np.nan, 0, 0]], tol=1e-9)


def test_the_side_of_an_open_sheet_by_its_normal():
    from surfprep import NurbsSurface
    from surfprep.algorithms.containment import sheet_side
    # a bent sheet z = 0.3 x^2 over [-1, 1]^2 (Bezier, degree 2 in x), normal +z-ish
    cp = np.zeros((3, 2, 3))
    for i, x in enumerate((-1.0, 0.0, 1.0)):
        for j, y in enumerate((-1.0, 1.0)):
            cp[i, j] = (x, y, 0.3 if i != 1 else -0.3)
    sheet = NurbsSurface(cp, [0, 0, 0, 1, 1, 1], [0, 0, 1, 1], 2, 1)
    rng = np.random.default_rng(1)
    xy = rng.uniform(-0.6, 0.6, (200, 2))
    u = (xy[:, 0] + 1) / 2
    z_on = sheet.evaluate(u, (xy[:, 1] + 1) / 2)[:, 2]
    dz = rng.choice([-1.0, 1.0], 200) * rng.uniform(0.01, 0.2, 200)
    points = np.column_stack([sheet.evaluate(u, (xy[:, 1] + 1) / 2)[:, :2], z_on + dz])
    up = np.sign(np.cross(*sheet.derivatives(np.array([0.5]), np.array([0.5]), 1)[0, [1, 0], [0, 1]])[2])
    side = sheet_side([TrimmedFace(sheet)], points, tol=1e-9)
    np.testing.assert_array_equal(side, np.sign(dz) * up)
    flipped = sheet_side([TrimmedFace(sheet, reversed=True)], points, tol=1e-9)
    np.testing.assert_array_equal(flipped, -side)
    assert sheet_side([TrimmedFace(sheet)], sheet.evaluate(np.array([0.3]), np.array([0.6])), tol=1e-9).tolist() == [0]
    with pytest.raises(InvalidGeometryError, match="does not reach"):
        sheet_side([TrimmedFace(sheet)], [[5.0, 0.0, 0.0]], tol=1e-9)
