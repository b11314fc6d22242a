"""Curves held as grid lines: the held nodes lie on the curve, the rest of the grid follows."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.grid_cases import warped_cylinder, warped_plane

from surfprep import NurbsCurve
from surfprep.algorithms.grid import grid_surface
from surfprep.algorithms.projection import distance_to_curve
from surfprep.errors import InvalidGeometryError

BEZIER = [0, 0, 0, 0, 1, 1, 1, 1]


def _across_x(x0, x1, bend=0.15) -> NurbsCurve:
    """A cubic in z = 0 from (x0, 0) to (x1, 1), bending sideways."""
    return NurbsCurve(np.array([[x0, 0, 0], [x0 + bend, 1 / 3, 0], [x1 - bend, 2 / 3, 0], [x1, 1, 0.0]]),
                      BEZIER, 3)


def _lines_on(curve: NurbsCurve, points: np.ndarray, axis: int, tol: float) -> list[int]:
    """Indices of the grid lines (i-lines for axis 0) whose nodes all lie on ``curve``."""
    lines = points if axis == 0 else np.transpose(points, (1, 0, 2))
    return [k for k, line in enumerate(lines) if distance_to_curve(curve, line).max() < tol]


def test_a_curve_across_the_face_becomes_an_i_line():
    curve = _across_x(0.4, 0.5)
    grid = grid_surface(warped_plane(), dims=(21, 17), hold=[curve])
    (column,) = _lines_on(curve, grid.points, 0, 1e-7)
    assert 5 <= column <= 13
    line = grid.points[column]
    np.testing.assert_allclose(line[[0, -1]], curve.evaluate([0.0, 1.0]), atol=1e-9)
    assert grid.quality.folded_cells == 0 and grid.elliptic.converged
    # the side nodes run in order and the held line splits them
    assert np.all(np.diff(grid.points[:, 0, 0]) > 0)


def test_two_curves_the_other_way_become_j_lines():
    low = NurbsCurve(np.array([[0, 0.3, 0], [1 / 3, 0.2, 0], [2 / 3, 0.45, 0], [1, 0.35, 0.0]]), BEZIER, 3)
    high = NurbsCurve(np.array([[1, 0.75, 0], [2 / 3, 0.8, 0], [1 / 3, 0.6, 0], [0, 0.7, 0.0]]), BEZIER, 3)
    grid = grid_surface(warped_plane(), dims=(15, 21), hold=[high, low])     # high runs backwards
    rows_low = _lines_on(low, grid.points, 1, 1e-7)
    rows_high = _lines_on(high, grid.points, 1, 1e-7)
    assert len(rows_low) == 1 and len(rows_high) == 1 and rows_low[0] < rows_high[0]
    assert grid.quality.folded_cells == 0


def test_a_helix_on_the_warped_cylinder_is_held():
    t = np.linspace(0.0, 1.0, 600)
    theta, z = -0.6 + 1.0 * t, -2.0 + 4.0 * t                 # from the bottom rim to the top rim
    helix = np.stack([np.cos(theta), np.sin(theta), z], axis=1)
    grid = grid_surface(warped_cylinder(), dims=(21, 17), hold=[helix])   # given as points
    radius = np.linalg.norm(grid.points[..., :2], axis=-1)
    np.testing.assert_allclose(radius, 1.0, atol=1e-9)        # on the cylinder
    angles = np.arctan2(grid.points[..., 1], grid.points[..., 0])
    # exactly one i-line is the helix (to the chord error of 600 points)
    on_helix = np.abs(angles - (-0.6 + (grid.points[..., 2] + 2.0) / 4.0)) < 1e-5
    assert on_helix.all(axis=1).sum() == 1
    assert grid.quality.folded_cells == 0


@pytest.mark.parametrize("curve, match", [
    (_across_x(0.4, 0.5) .translated([0, 0, 0.5]), "from the face"),
    (NurbsCurve(np.array([[0.4, 0, 0], [0.5, 0.3, 0], [0.5, 0.5, 0.0]]), [0, 0, 0, 1, 1, 1], 2),
     "opposite side"),
    (np.array([[0.2, 0.0, 0.0], [0.2, 0.0, 0.0]]), "zero length"),
])
def test_curves_that_cannot_be_held_are_refused(curve, match):
    with pytest.raises(InvalidGeometryError, match=match):
        grid_surface(warped_plane(), dims=(11, 11), hold=[curve])


def test_crossing_and_crowded_held_curves_are_refused():
    across_y = NurbsCurve(np.array([[0, 0.5, 0], [1, 0.5, 0.0]]), [0, 0, 1, 1], 1)
    with pytest.raises(InvalidGeometryError, match="same way"):
        grid_surface(warped_plane(), dims=(11, 11), hold=[_across_x(0.4, 0.5), across_y])
    with pytest.raises(InvalidGeometryError, match="too close"):
        grid_surface(warped_plane(), dims=(5, 11), hold=[_across_x(0.40, 0.40, 0.0),
                                                        _across_x(0.41, 0.41, 0.0)])
