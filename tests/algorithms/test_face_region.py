"""Point-in-trimmed-face (algorithms.face_region) where the loops' edges meet."""

from __future__ import annotations

import numpy as np
from helpers.heal_cases import HOLE_CENTRE, HOLE_RADIUS, plane_with_hole

from surfprep.algorithms.face_region import FaceRegion


def test_a_row_through_the_vertex_where_two_arcs_meet_is_classified_right():
    """The hole is four arcs; the last ends at v = 0.5 + 1e-16 and the first starts at
    v = 0.5, so a ray along v = 0.5 passed between the two polygon ends and the
    even-odd count was one short: the hole's centre counted as inside the face."""
    region = FaceRegion(plane_with_hole())
    v = HOLE_CENTRE[1]
    u = np.linspace(0.0, 1.0, 101)
    uv = np.column_stack([u, np.full_like(u, v)])
    inside = region.contains(uv)
    in_hole = np.abs(u - HOLE_CENTRE[0]) < HOLE_RADIUS - 1e-9
    in_outer = (u > 0.1 + 1e-9) & (u < 0.9 - 1e-9)
    on_loops = (np.abs(np.abs(u - HOLE_CENTRE[0]) - HOLE_RADIUS) < 1e-9) \
        | (np.abs(u - 0.1) < 1e-9) | (np.abs(u - 0.9) < 1e-9)
    assert np.array_equal(inside[~on_loops], (in_outer & ~in_hole)[~on_loops])
