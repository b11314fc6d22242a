"""Planning the approximants of heal (:mod:`surfprep.plugin.heal.jobs`)."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.surface import NurbsSurface
from surfprep.plugin.heal.jobs import plan_jobs
from surfprep.plugin.occ.faces import face_to_nurbs, make_face


def _strip(length: float, width: float):
    """A flat face ``length x width`` with four edges."""
    net = np.array([[[0, 0, 0], [0, width, 0]], [[length, 0, 0], [length, width, 0]]], float)
    surface = NurbsSurface(net, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)
    return face_to_nurbs(make_face(surface))


@pytest.mark.parametrize("gap_tol, planned", [(0.5, 1), (2.0, 0)])
def test_a_face_with_a_side_shorter_than_gap_tol_is_not_replaced(gap_tol, planned):
    """Sewing at gap_tol would collapse a side shorter than it (a 4.5 mm edge of
    occt_hammer_euclid.iges at gap_tol 17.1 mm: OpenCascade's sewing then ran for
    13 minutes); the face is kept, and said so."""
    faces = [_strip(10.0, 1.0)]
    skipped: list[str] = []
    jobs = plan_jobs(faces, [0], [], {}, {}, gap_tol=gap_tol, skipped=skipped)
    assert len(jobs) == planned
    if planned == 0:
        assert len(skipped) == 1
        assert "face 0" in skipped[0] and "side 1 long" in skipped[0]
        assert "shorter than gap_tol 2" in skipped[0]
    else:
        assert skipped == [] and jobs[0].origin.faces == (0,)
