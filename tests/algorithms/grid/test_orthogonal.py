"""Boundary orthogonality (Steger--Sorenson sources), measured on the grids' own nodes."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.grid_cases import pole_patch, side_angles, warped_cylinder
from helpers.paths import SAMPLES

from surfprep.algorithms.grid import Spacing, grid_network, grid_surface
from surfprep.algorithms.grid.orthogonal import BoundaryControl, source_steps
from surfprep.algorithms.surface import NurbsSurface

LINEAR = [0.0, 0.0, 1.0, 1.0]


def _trapezoid() -> NurbsSurface:
    """The plane trapezoid (0,0) (4,0) (3,2) (1,2): its Winslow lines leave the slanted
    sides and the top at angles up to ~10 degrees off 90."""
    net = np.array([[[0, 0, 0], [1, 2, 0]], [[4, 0, 0], [3, 2, 0]]], float)
    return NurbsSurface(net, LINEAR, LINEAR, 1, 1)


def _bent() -> NurbsSurface:
    """A plane sheet whose bottom side bends by 53 degrees in its middle (a roof line)."""
    net = np.array([[[0, 0, 0], [0, 2, 0]], [[1, 0.5, 0], [1, 2, 0]], [[2, 0, 0], [2, 2, 0]]], float)
    return NurbsSurface(net, [0, 0, 0.5, 1, 1], LINEAR, 1, 1)


def test_an_orthogonal_grid_asks_for_nothing():
    x, y = np.meshgrid(np.linspace(0, 2, 9), np.linspace(0, 1, 7), indexing="ij")
    points = np.stack([x, y, np.zeros_like(x)], axis=-1)
    control = BoundaryControl.start(points, heights={"i0": 0.25, "j1": 1 / 6})
    assert control.sides == ("j0", "j1", "i0", "i1")
    _, dP, dQ, misfit = control.update(points)
    assert misfit < 1e-9 and np.abs(dP).max() < 1e-9 and np.abs(dQ).max() < 1e-9
    sheared = points.copy()
    sheared[:, 1:-1, 0] += 0.05                          # the first rows lean
    steps_p, _, miss, _ = source_steps(sheared, *control.targets["j0"])
    assert miss > 1.0 and np.all(steps_p[2:-2] < 0.0)    # P pulls the lines back


def test_lines_leave_the_sides_of_a_trapezoid_at_right_angles():
    plain = grid_surface(_trapezoid(), dims=(41, 31), orthogonal=False)
    square = grid_surface(_trapezoid(), dims=(41, 31))
    before = max(np.abs(a - 90).max() for a in side_angles(plain.points))
    after = max(np.abs(a - 90).max() for a in side_angles(square.points))
    assert before > 5.0
    assert after < 0.5
    assert square.elliptic.converged and square.quality.folded_cells == 0 and square.orthogonal_dropped is None
    assert np.abs(square.points[..., 2]).max() == 0.0
    # the sides' nodes are where the arc-length law put them
    np.testing.assert_array_equal(square.points[:, 0], plain.points[:, 0])
    np.testing.assert_array_equal(square.points[0, :], plain.points[0, :])


@pytest.mark.parametrize("first", [0.01, 0.002])
def test_a_first_spacing_asked_for_is_held_off_the_side(first):
    """The tanh law puts the first node of the slanted sides ``first`` from the bottom; the
    algebraic grid's first cells between them are lower (the trapezoid is 2 high, its slanted
    sides 2.24 long): the controlled grid holds ``first`` across the whole side."""
    spacing = (Spacing(), Spacing(first=first))
    plain = grid_surface(_trapezoid(), dims=(41, 31), spacing=spacing, orthogonal=False)
    grid = grid_surface(_trapezoid(), dims=(41, 31), spacing=spacing)
    assert grid.orthogonal_dropped is None and grid.elliptic.converged and grid.quality.folded_cells == 0

    def heights(points):
        return np.linalg.norm(points[:, 1] - points[:, 0], axis=-1)[4:-4] / first - 1.0

    assert np.abs(heights(plain.points)).max() > 0.05
    assert np.abs(heights(grid.points)).max() < 0.015
    assert max(np.abs(a - 90).max() for a in side_angles(grid.points)) < 0.5


def test_an_orthogonal_grid_on_a_developable_surface_is_left_as_it_is():
    surface = warped_cylinder()
    plain = grid_surface(surface, dims=(25, 21), orthogonal=False, tol=1e-7)
    square = grid_surface(surface, dims=(25, 21), tol=1e-7)
    assert np.abs(square.points - plain.points).max() < 1e-4 * np.ptp(plain.points[..., 0])
    assert square.quality.max_skewness < 1e-3


def test_a_bend_of_a_side_is_left_free_and_nothing_folds():
    grid = grid_surface(_bent(), dims=(41, 31))
    assert grid.elliptic.converged and grid.quality.folded_cells == 0
    angles = side_angles(grid.points)
    assert np.abs(angles[1] - 90).max() < 0.5 and np.abs(angles[3] - 90).max() < 0.5   # the straight sides
    bottom = angles[2]
    m = 4
    assert np.abs(bottom[:len(bottom) // 2 - m] - 90).max() < 0.5   # away from the bend


def test_no_fold_next_to_a_pole():
    grid = grid_surface(pole_patch(), dims=(21, 21))
    assert grid.quality.folded_cells == 0 and grid.elliptic.converged


def test_a_badly_parametrized_real_face_gets_right_angles_at_its_sides():
    import surfprep
    face = surfprep.to_nurbs(surfprep.read(SAMPLES / "occt_catia4_face_L1.igs").faces[0])
    plain = grid_surface(face.surface, dims=(41, 41), orthogonal=False)
    square = grid_surface(face.surface, dims=(41, 41))
    assert max(np.abs(a - 90).max() for a in side_angles(plain.points)) > 8.0
    assert max(np.abs(a - 90).max() for a in side_angles(square.points)) < 0.5
    assert square.quality.folded_cells == 0
    assert square.quality.max_skewness <= plain.quality.max_skewness


@pytest.mark.parametrize("orthogonal", [False, True])
def test_refine_keeps_the_boundary(orthogonal):
    grid = grid_surface(_trapezoid(), dims=(21, 15), orthogonal=orthogonal)
    start = grid.start_parameters
    for side in (np.s_[:, 0], np.s_[:, -1], np.s_[0, :], np.s_[-1, :]):
        np.testing.assert_array_equal(grid.parameters[side], start[side])


def test_a_run_that_does_not_reach_the_sides_keeps_the_plain_grid_and_says_so():
    """100 sweeps converge the plain grid of the trapezoid but not its sides' sources: the
    plain grid is returned, the block's report says why."""
    square = grid_surface(_trapezoid(), dims=(41, 31), max_sweeps=100)
    plain = grid_surface(_trapezoid(), dims=(41, 31), max_sweeps=100, orthogonal=False)
    assert square.orthogonal_dropped is not None and "not reached" in square.orthogonal_dropped
    np.testing.assert_array_equal(square.points, plain.points)
    assert square.report()["elliptic"]["orthogonal_dropped"] == square.orthogonal_dropped
    full = grid_surface(_trapezoid(), dims=(41, 31))
    assert full.orthogonal_dropped is None and full.report()["elliptic"]["sides_misfit"] <= 1.0


def test_a_network_squares_its_open_sides_and_lets_its_interfaces_run_on():
    """Two trapezoids sharing the edge x = 2: the lines leave the six open sides at right
    angles (14 degrees off without), the shared edge's nodes stay matched bit for bit."""
    left = NurbsSurface(np.array([[[0, 0, 0], [0.5, 2, 0]], [[2, 0, 0], [2, 2, 0]]], float), LINEAR, LINEAR, 1, 1)
    right = NurbsSurface(np.array([[[2, 0, 0], [2, 2, 0]], [[4, 0, 0], [3.5, 2, 0]]], float), LINEAR, LINEAR, 1, 1)
    worst = {}
    for orthogonal in (False, True):
        net = grid_network([left, right], gap=1e-9, dims=(31, 31), orthogonal=orthogonal)
        a, b = (block.points for block in net.blocks)
        np.testing.assert_array_equal(a[-1], b[0])                      # the shared edge
        assert all(block.quality.folded_cells == 0 for block in net.blocks)
        i0, _, j0, j1 = side_angles(a)
        _, i1, k0, k1 = side_angles(b)
        worst[orthogonal] = max(np.abs(np.concatenate([i0, j0, j1, i1, k0, k1]) - 90))
    assert worst[False] > 10.0
    assert worst[True] < 0.5


def test_a_sharp_corner_is_not_squeezed_further_by_the_squared_sides():
    """A quadrilateral with a 15 degree corner (and a 165 degree one): squaring its sides
    would skew the cells beside the sharp corner beyond the corner's own 0.833; the grid
    without it is kept, and the block says why."""
    tip = 1 / np.tan(np.radians(15.0))
    sliver = NurbsSurface(np.array([[[0, 0, 0], [tip, 1, 0]], [[4, 0, 0], [4, 1, 0]]], float), LINEAR, LINEAR, 1, 1)
    grid = grid_surface(sliver, dims=(41, 21))
    plain = grid_surface(sliver, dims=(41, 21), orthogonal=False)
    assert grid.orthogonal_dropped is not None and "more skewed" in grid.orthogonal_dropped
    np.testing.assert_array_equal(grid.points, plain.points)
    assert grid.quality.max_skewness < 75 / 90 + 0.005 and grid.quality.folded_cells == 0   # the corner's own


def test_a_refinement_resumed_from_its_sources_needs_fewer_sweeps_for_the_same_grid():
    """The trapezoid's squared grid, its bottom's nodes then slid along it (as a network's
    shared edge slides): refined again from the sources it had reached, it meets its sides
    in fewer sweeps than from none, and both runs find the same grid."""
    from surfprep.algorithms.grid.elliptic import refine
    surface = _trapezoid()
    first = refine(surface, grid_surface(surface, dims=(41, 31), smooth="none").parameters,
                   orthogonal=True)
    assert first.converged and first.control is not None
    slid = first.parameters.copy()
    slid[1:-1, 0, 0] += 0.004 * np.sin(np.pi * np.linspace(0, 1, 41)[1:-1])
    fresh = refine(surface, slid, orthogonal=True, warm=True)
    resumed = refine(surface, slid, orthogonal=True, warm=True, resume=first.control)
    assert fresh.converged and resumed.converged
    assert resumed.sweeps < 0.7 * fresh.sweeps
    cell = 4.0 / 40
    a, b = surface.evaluate(*fresh.parameters.transpose(2, 0, 1)), surface.evaluate(
        *resumed.parameters.transpose(2, 0, 1))
    assert np.abs(a - b).max() < 0.02 * cell
    assert max(np.abs(x - 90).max() for x in side_angles(b)) < 0.5


def test_sources_resumed_on_a_finer_grid_are_interpolated_and_scaled():
    x, y = np.meshgrid(np.linspace(0, 2, 9), np.linspace(0, 1, 7), indexing="ij")
    coarse = BoundaryControl.start(np.stack([x, y, np.zeros_like(x)], axis=-1), sides=("j0",))
    along = np.linspace(1.0, 2.0, 7)
    coarse = BoundaryControl(coarse.sides, coarse.targets,
                             {"j0": (along, -along, *coarse.corrections["j0"][2:])})
    x, y = np.meshgrid(np.linspace(0, 2, 17), np.linspace(0, 1, 13), indexing="ij")
    fine = BoundaryControl.start(np.stack([x, y, np.zeros_like(x)], axis=-1), sides=("j0", "i0"))
    resumed = fine.resumed(coarse, 0.5)
    a, b = resumed.corrections["j0"][:2]
    assert a.shape == (15,)
    np.testing.assert_allclose(a, 0.5 * np.interp(np.arange(1, 16) / 16, np.arange(1, 8) / 8, along))
    np.testing.assert_allclose(b, -a)
    np.testing.assert_array_equal(resumed.corrections["i0"][0], 0.0)      # not in the coarse one
