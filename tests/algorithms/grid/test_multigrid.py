"""FAS coarse-grid corrections of the elliptic grid system, against grids known exactly."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.grid_cases import crowded_plane, unrolled_cylinder_grid, warped_cylinder, warped_plane

from surfprep.algorithms.grid import grid_surface, multigrid, refine
from surfprep.algorithms.grid.elliptic import MULTIGRID_ABOVE


def _cartesian(ni: int, nj: int) -> np.ndarray:
    x, y = np.meshgrid(np.linspace(0, 1, ni), np.linspace(0, 1, nj), indexing="ij")
    return np.stack([x, y, np.zeros_like(x)], axis=-1)


@pytest.mark.parametrize("surface", [warped_plane, crowded_plane], ids=["warped", "crowded"])
def test_a_large_plane_grid_reaches_the_cartesian_grid_in_few_sweeps(surface):
    """Winslow's grid of the unit square with uniform sides is the Cartesian grid, whatever
    the parametrization: at 129 x 97 the corrected iteration finds it to 1e-8 in a few dozen
    fine sweeps (SOR alone: hundreds)."""
    dims = (129, 97)
    assert max(dims) > MULTIGRID_ABOVE
    grid = grid_surface(surface(), dims=dims, tol=1e-8, orthogonal=False)
    assert grid.elliptic.converged and grid.elliptic.refused == 0
    np.testing.assert_allclose(grid.points, _cartesian(*dims), atol=1e-8)
    assert grid.elliptic.sweeps < 150


def test_a_developable_surface_at_131_by_97_gets_the_unrolled_grid():
    grid = grid_surface(warped_cylinder(), dims=(131, 97), tol=1e-8)
    np.testing.assert_allclose(grid.points, unrolled_cylinder_grid(131, 97), atol=1e-7)


def test_a_solution_is_a_fixed_point_of_the_correction():
    """At the converged grid R = 0 (tangentially): tau = R_c(I u) and the coarse solution
    is I u, so the correction moves nothing (to the coarse solve's own convergence)."""
    surface = warped_plane()
    grid = grid_surface(surface, dims=(97, 81), tol=1e-10, orthogonal=False)
    st = grid.parameters
    s, t = st[..., 0].copy(), st[..., 1].copy()
    d = surface.derivatives(s, t, 1)
    x = d[..., 0, 0, :].copy()
    zero = np.zeros_like(s)
    assert multigrid.correct(surface, s, t, x, d[..., 1, 0, :], d[..., 0, 1, :], zero, zero,
                             surface.domain, 1.0)
    cell = 1.0 / 96
    moved = np.linalg.norm(surface.evaluate(s, t) - grid.points, axis=-1).max()
    assert moved < 1e-6 * cell


def test_the_same_grid_with_and_without_corrections():
    """SOR alone and V-cycles find the same surface grid, the V-cycles in far fewer sweeps."""
    surface = crowded_plane()
    start = grid_surface(surface, dims=(97, 81), smooth="none").parameters
    corrected = refine(surface, start, tol=1e-7)
    plain = refine(surface, start, tol=1e-7, multigrid=False)
    assert corrected.converged and plain.converged
    assert corrected.sweeps < 0.3 * plain.sweeps
    a = surface.evaluate(*corrected.parameters.transpose(2, 0, 1))
    b = surface.evaluate(*plain.parameters.transpose(2, 0, 1))
    assert np.abs(a - b).max() < 1e-5 / 96


def test_a_start_nearer_a_solution_than_the_coarse_one_is_kept():
    """The fuselage's nose face at 201 x 201: its algebraic start is nearly a solution (a
    residual of 5e-4 cells) and the coarse grid's solution interpolated next to its pole is
    not (0.27 cells): from the coarse start the V-cycles crept for 193 sweeps, from the
    algebraic one they converge in about 60."""
    from helpers.paths import SAMPLES

    import surfprep
    face = surfprep.to_nurbs(surfprep.read(SAMPLES / "occt_fuselage.stp").faces[0])
    grid = grid_surface(face.surface, dims=(201, 201), orthogonal=False)
    assert grid.elliptic.converged and grid.quality.folded_cells == 0
    assert grid.elliptic.sweeps < 100
    assert grid.elliptic.residuals[0] < 1e-2
