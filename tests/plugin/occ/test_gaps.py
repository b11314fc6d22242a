"""Gaps in the geometry of a sewn shape, measured on the faces (plugin/occ/gaps.py)."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.projection import distance_to_surface
from surfprep.plugin.convert import to_nurbs
from surfprep.plugin.occ.faces import make_face
from surfprep.plugin.occ.gaps import gaps_in_geometry
from surfprep.plugin.occ.shapes import all_faces, sew


def plane_patch(x0: float, x1: float, z: float):
    x, y = np.meshgrid(np.linspace(x0, x1, 4), np.linspace(0.0, 1.0, 4), indexing="ij")
    return interpolate_surface(np.stack([x, y, np.full_like(x, z)], axis=-1))


@pytest.fixture(scope="module")
def sewn_over_a_step():
    # two unit squares side by side, the second 1e-3 higher: sewing at 1e-2 shares
    # their edge by tolerance, the faces stay 1e-3 apart along it
    shape, _ = sew([make_face(plane_patch(0.0, 1.0, 0.0)),
                    make_face(plane_patch(1.0, 2.0, 1e-3))], 1e-2)
    return shape


def test_an_edge_shared_by_tolerance_is_open_in_the_geometry(sewn_over_a_step):
    gaps = gaps_in_geometry(sewn_over_a_step, 1e-7)
    assert gaps.free == 6
    (_edge, faces, largest) = gaps.open_edges[0]
    assert len(gaps.open_edges) == 1 and faces == 2
    assert largest == pytest.approx(1e-3, rel=1e-9)
    assert gaps.free_in_geometry == 8 and len(gaps.polylines) == 8
    # closed at a tolerance above the step
    assert gaps_in_geometry(sewn_over_a_step, 2e-3).free_in_geometry == 6


def test_each_polyline_lies_on_the_face_it_is_said_to_belong_to(sewn_over_a_step):
    gaps = gaps_in_geometry(sewn_over_a_step, 1e-7)
    faces = [to_nurbs(f).surface for f in all_faces(sewn_over_a_step)]
    assert len(gaps.owners) == len(gaps.polylines)
    assert sorted(gaps.owners) == [0, 0, 0, 0, 1, 1, 1, 1]
    # the two sides of the open edge are flagged, the six free edges not
    assert sorted(gaps.sewn) == [False] * 6 + [True] * 2
    sides = [line for line, flag in zip(gaps.polylines, gaps.sewn) if flag]
    assert np.allclose(sides[0][:, 0], 1.0) and np.allclose(sides[1][:, 0], 1.0)
    for line, owner in zip(gaps.polylines, gaps.owners):
        assert distance_to_surface(faces[owner], line).max() < 1e-12
        assert distance_to_surface(faces[1 - owner], line).max() > 1e-4
