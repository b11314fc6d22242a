"""Elliptic refinement on the surface metric, against grids known exactly."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.grid_cases import (
    crowded_plane,
    pole_patch,
    unrolled_cylinder_grid,
    warped_cylinder,
    warped_plane,
)

from surfprep.algorithms.grid import grid_surface, refine
from surfprep.algorithms.grid.elliptic import corner_jacobians
from surfprep.algorithms.grid.elliptic_kernels import sweep, sweep_numpy
from surfprep.errors import InvalidGeometryError


def _square(ni, nj):
    x, y = np.meshgrid(np.linspace(0, 1, ni), np.linspace(0, 1, nj), indexing="ij")
    return x, y


@pytest.mark.parametrize("surface", [warped_plane, crowded_plane], ids=["warped", "crowded"])
def test_a_plane_gets_the_uniform_grid_whatever_its_parametrization(surface):
    """Winslow's grid of a square with uniform sides is the Cartesian grid: the
    algebraic start in the warped parameters is far from it, the refined grid is on it."""
    grid = grid_surface(surface(), dims=(21, 17), tol=1e-8)
    x, y = _square(21, 17)
    start = grid.start_quality
    assert start.max_skewness > 0.3                            # the start is poor
    assert np.abs(grid.points[..., 0] - x).max() < 1e-8
    assert np.abs(grid.points[..., 1] - y).max() < 1e-8
    assert grid.elliptic.converged and grid.elliptic.refused == 0
    assert grid.quality.max_skewness < 1e-6


def test_a_developable_surface_gets_the_unrolled_orthogonal_grid():
    grid = grid_surface(warped_cylinder(), dims=(21, 17), tol=1e-8)
    assert grid.start_quality.max_skewness > 0.4
    np.testing.assert_allclose(grid.points, unrolled_cylinder_grid(21, 17), atol=1e-8)
    assert grid.quality.min_angle > 89.999 and grid.quality.max_angle < 90.001


def test_residuals_fall_to_the_tolerance():
    grid = grid_surface(warped_plane(), dims=(41, 41), tol=1e-6)
    residuals = grid.elliptic.residuals
    assert residuals[-1] < 1e-6 <= residuals[0]
    assert grid.elliptic.converged


def test_compiled_and_numpy_sweeps_reach_the_same_grid():
    surface = warped_plane()
    start = grid_surface(surface, dims=(13, 11), smooth="none").parameters
    results = []
    for step in (sweep, sweep_numpy):
        s, t = start[..., 0].copy(), start[..., 1].copy()
        p = q = np.zeros_like(s)
        for _ in range(200):
            d = surface.derivatives(s, t, 1)
            x = d[..., 0, 0, :].copy()
            worst = step(s, t, x, d[..., 1, 0, :], d[..., 0, 1, :], p, q, 1.5, surface.domain)
            if worst < 1e-11:
                break
        results.append(surface.evaluate(s, t))
    np.testing.assert_allclose(results[0], results[1], atol=1e-9)
    x, y = _square(13, 11)
    assert np.abs(results[1][..., 0] - x).max() < 1e-9
    assert np.abs(results[1][..., 1] - y).max() < 1e-9


def test_no_cell_folds_next_to_a_pole():
    grid = grid_surface(pole_patch(), dims=(15, 11))
    assert grid.collapsed_sides == ("i0",)
    assert grid.quality.folded_cells == 0 and grid.quality.min_scaled_jacobian > 0
    assert grid.quality.collapsed_corners == 2 * 10
    jac = corner_jacobians(grid.parameters[..., 0], grid.parameters[..., 1])
    assert np.all(jac > 0)


def test_refine_holds_the_boundary_and_refuses_bad_starts():
    surface = warped_plane()
    start = grid_surface(surface, dims=(9, 9), smooth="none").parameters
    result = refine(surface, start)
    for side in (np.s_[0], np.s_[-1], np.s_[:, 0], np.s_[:, -1]):
        np.testing.assert_array_equal(result.parameters[side], start[side])
    folded = start.copy()
    folded[4, 4], folded[5, 5] = start[5, 5], start[4, 4]
    with pytest.raises(InvalidGeometryError, match="folded"):
        refine(surface, folded)
    with pytest.raises(InvalidGeometryError, match="outside"):
        refine(surface, start + 2.0)
    with pytest.raises(InvalidGeometryError, match="NaN"):
        refine(surface, np.where(start > 0.5, np.nan, start))
    with pytest.raises(InvalidGeometryError, match=r"\(ni, nj, 2\)"):
        refine(surface, start[..., 0])


@pytest.mark.parametrize("dims", [(81, 3), (3, 81), (81, 4)])
def test_a_long_narrow_grid_is_refined(dims):
    """Three nodes across: the coarse start's grid has two, no interior node (it crashed the
    whole model's grid once, in the sides' control of that coarse grid)."""
    grid = grid_surface(warped_plane(), dims=dims)
    assert grid.points.shape == (*dims, 3)
    assert grid.elliptic.converged and grid.quality.folded_cells == 0


def test_the_compiled_fold_test_agrees_with_the_corner_jacobians():
    from surfprep.algorithms.grid.elliptic_kernels import folds
    rng = np.random.default_rng(3)
    s, t = np.meshgrid(np.linspace(0, 1, 12), np.linspace(0, 2, 9), indexing="ij")
    assert not folds(s, t, 1.0) and folds(s, t, -1.0)
    for scale in (0.01, 0.03, 0.06, 0.1):
        for _ in range(20):
            ds = s + scale * rng.standard_normal(s.shape)
            dt = t + scale * rng.standard_normal(t.shape)
            for sign in (1.0, -1.0):
                assert folds(ds, dt, sign) == bool(np.any(sign * corner_jacobians(ds, dt) <= 0.0))
