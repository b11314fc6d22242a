"""Where two faces coincide: the faces, not their surfaces. Faces on one plane that
overlap, meet along an edge, or lie apart."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms import NurbsSurface, TrimmedFace
from surfprep.algorithms.characteristic import face_coincidence
from surfprep.algorithms.face_region import FaceRegion


def square(x0: float, x1: float, z: float = 0.0) -> FaceRegion:
    """The face [x0, x1] x [0, 1] of the plane z (a bilinear patch)."""
    cp = np.array([[[x0, 0, z], [x0, 1, z]], [[x1, 0, z], [x1, 1, z]]], float)
    return FaceRegion(TrimmedFace(NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)))


def test_a_face_coincides_with_itself_everywhere():
    region = face_coincidence(square(0, 1), square(0, 1), 1e-9)
    assert region.share == 1.0 and region.max_distance <= 1e-15
    np.testing.assert_allclose(region.box_a, [[0, 0], [1, 1]], atol=0.02)


def test_overlapping_faces_coincide_over_the_overlap():
    region = face_coincidence(square(0, 1), square(0.5, 1.5), 1e-9)
    assert region.share == pytest.approx(0.5, abs=0.02)
    assert region.box_a[0, 0] == pytest.approx(0.5, abs=0.02)   # a's right half ...
    assert region.box_b[1, 0] == pytest.approx(0.5, abs=0.02)   # ... is b's left half


@pytest.mark.parametrize("b", [square(1, 2), square(1.5, 2.5), square(0, 1, z=1e-3)])
def test_faces_that_meet_along_an_edge_or_lie_apart_do_not(b):
    assert face_coincidence(square(0, 1), b, 1e-9) is None
