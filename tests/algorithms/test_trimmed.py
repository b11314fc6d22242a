"""TrimmedFace.parameter_box / bounding_box: boxes that hold the face, tighter than the surface's."""

from __future__ import annotations

import numpy as np
from helpers.surfaces import bumpy, straight_loop

from surfprep import NurbsCurve, TrimmedFace
from surfprep.algorithms.face_region import FaceRegion
from surfprep.algorithms.face_split import Cut, split_face
from surfprep.algorithms.volume_builders import solid_sphere


def face_points(face: TrimmedFace, n: int = 201) -> np.ndarray:
    """3D points of a dense grid of the face's domain that lie inside the face."""
    u0, u1, v0, v1 = face.surface.domain
    u, v = np.meshgrid(np.linspace(u0, u1, n), np.linspace(v0, v1, n), indexing="ij")
    uv = np.stack([u.ravel(), v.ravel()], axis=1)
    inside = FaceRegion(face).contains(uv)
    assert inside.any()
    return face.surface.evaluate(uv[inside, 0], uv[inside, 1])


def test_a_small_face_on_a_large_surface_gets_a_small_box_that_holds_it():
    surface = bumpy()
    # a pentagon in (u, v) over one of the bumps
    face = TrimmedFace(surface, (straight_loop([[0.2, 0.5], [0.4, 0.52], [0.42, 0.66],
                                               [0.3, 0.7], [0.21, 0.64]]),))
    assert face.parameter_box() == (0.2, 0.42, 0.5, 0.7)
    box = face.bounding_box()
    points = face_points(face)
    assert np.all(points >= box[0] - 1e-12) and np.all(points <= box[1] + 1e-12)
    whole = surface.bounding_box()
    assert np.all(box[1, :2] - box[0, :2] < 0.4 * (whole[1, :2] - whole[0, :2]))


def test_pieces_of_a_split_sphere_lie_in_their_boxes():
    sphere = solid_sphere(1.0).exterior_faces()["u1"]
    u0, u1, v0, v1 = sphere.domain
    u = 0.3 * (u1 - u0) + u0
    pcurve = NurbsCurve(np.array([[u, v0], [u, v1]]), [v0, v0, v1, v1], 1)
    pieces = split_face(TrimmedFace(sphere), [Cut(pcurve, sphere.isocurve(u, "u"))])
    boxes = [piece.bounding_box() for piece in pieces]
    for piece, box in zip(pieces, boxes):
        points = face_points(piece)
        assert np.all(points >= box[0] - 1e-12) and np.all(points <= box[1] + 1e-12)
    # the cap's box is smaller than the sphere's in the cut direction
    assert min(np.prod(b[1] - b[0]) for b in boxes) < 0.8 * np.prod(np.diff(sphere.bounding_box(), axis=0))


def test_faces_that_span_the_domain_keep_the_surface_box():
    surface = bumpy()
    np.testing.assert_array_equal(TrimmedFace(surface).bounding_box(), surface.bounding_box())
    # a pcurve outside the domain (as a periodic surface's, shifted by a period): the
    # loops are not trusted for a box
    shifted = TrimmedFace(surface, (straight_loop([[1.2, 0.5], [1.4, 0.5], [1.4, 0.7]]),))
    assert shifted.parameter_box() == surface.domain
    np.testing.assert_array_equal(shifted.bounding_box(), surface.bounding_box())
