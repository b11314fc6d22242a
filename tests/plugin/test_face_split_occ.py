"""Split regions become valid OpenCascade faces whose areas add up to the face's."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.paths import SAMPLES

import surfprep
from surfprep.algorithms.face_split import Cut, split_face
from surfprep.plugin.occ.shapes import face_area, is_valid

FUSELAGE = SAMPLES / "occt_fuselage.stp"


@pytest.mark.parametrize("how", ["iso-line", "closed loop"])
def test_a_fuselage_face_split_gives_valid_faces_of_the_same_total_area(how):
    model = surfprep.read(FUSELAGE)
    face = surfprep.to_nurbs(model.faces[1])
    surface = face.surface
    v0, v1 = surface.domain[2:]
    if how == "iso-line":                                    # across the face at u = 1.3
        pcurve = surfprep.NurbsCurve(np.array([[1.3, v0], [1.3, v1]]), [v0, v0, v1, v1], 1)
        cut = Cut(pcurve, surface.isocurve(1.3, "u"))
        expected = 2
    else:                                                    # an ellipse in the parameters
        s = np.sqrt(0.5)
        unit = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]])
        pole = np.array([1.5, 0.5]) + unit * [0.4, 0.2]
        pcurve = surfprep.NurbsCurve(pole, [0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1], 2,
                                     np.array([1, s, 1, s, 1, s, 1, s, 1]))
        cut = Cut(pcurve)
        expected = 2
    parts = split_face(face, [cut])
    assert len(parts) == expected
    occ_faces = [surfprep.to_occ(p) for p in parts]
    assert all(is_valid(f) for f in occ_faces)
    # GProp at a tight tolerance (its default is off by 0.35 % on this face)
    whole = face_area(model.faces[1], 1e-9)
    np.testing.assert_allclose(sum(face_area(f, 1e-9) for f in occ_faces), whole, rtol=1e-6)
