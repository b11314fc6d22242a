"""The arc-length distribution mesh and weighted transfinite interpolation."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms.grid import distribution_mesh, stretched, transfinite, uniform
from surfprep.errors import InvalidGeometryError


def test_distribution_mesh_of_uniform_sides_is_the_uniform_mesh():
    s, t = distribution_mesh(uniform(5), uniform(5), uniform(4), uniform(4))
    S, T = np.meshgrid(uniform(5), uniform(4), indexing="ij")
    np.testing.assert_allclose(s, S, atol=1e-15)
    np.testing.assert_allclose(t, T, atol=1e-15)


def test_distribution_mesh_keeps_the_sides_and_crosses_the_lines():
    a, b = stretched(9, first=0.02), uniform(9)
    c, d = uniform(7), stretched(7, last=0.05)
    s, t = distribution_mesh(a, b, c, d)
    np.testing.assert_array_equal(s[:, 0], a)
    np.testing.assert_array_equal(s[:, -1], b)
    np.testing.assert_array_equal(t[0], c)
    np.testing.assert_array_equal(t[-1], d)
    # node (i, j) lies on the line (a_i, 0)-(b_i, 1) and on (0, c_j)-(1, d_j)
    np.testing.assert_allclose(s, a[:, None] + t * (b - a)[:, None], atol=1e-14)
    np.testing.assert_allclose(t, c[None, :] + s * (d - c)[None, :], atol=1e-14)


def test_tfi_reproduces_a_bilinear_map_exactly():
    corners = np.array([[0.0, 0.0, 0.0], [3.0, 0.5, 1.0], [-0.5, 2.0, 0.3], [2.0, 3.0, -1.0]])
    p00, p10, p01, p11 = corners
    u, v = np.meshgrid(np.linspace(0, 1, 7), np.linspace(0, 1, 5), indexing="ij")
    exact = ((1 - u) * (1 - v))[..., None] * p00 + (u * (1 - v))[..., None] * p10 \
        + ((1 - u) * v)[..., None] * p01 + (u * v)[..., None] * p11
    grid = transfinite(exact[:, 0], exact[:, -1], exact[0], exact[-1])
    np.testing.assert_allclose(grid, exact, atol=1e-14)


def test_tfi_carries_the_sides_distributions_inside():
    # a unit square whose bottom and top sides are clustered toward x = 0
    x = stretched(11, first=0.01)
    bottom = np.stack([x, np.zeros(11)], 1)
    top = np.stack([x, np.ones(11)], 1)
    y = uniform(6)
    left, right = np.stack([np.zeros(6), y], 1), np.stack([np.ones(6), y], 1)
    grid = transfinite(bottom, top, left, right)
    np.testing.assert_allclose(grid[..., 0], np.repeat(x[:, None], 6, 1), atol=1e-15)
    np.testing.assert_allclose(grid[..., 1], np.repeat(y[None, :], 11, 0), atol=1e-15)


def test_tfi_refuses_sides_that_do_not_meet():
    side = np.stack([uniform(4), np.zeros(4)], 1)
    with pytest.raises(InvalidGeometryError, match="corner is not shared"):
        transfinite(side, side + [0, 1], np.stack([np.zeros(3), uniform(3)], 1),
                    np.stack([np.ones(3) * 2, uniform(3)], 1))
    with pytest.raises(InvalidGeometryError, match="same node count"):
        distribution_mesh(uniform(4), uniform(5), uniform(3), uniform(3))
    with pytest.raises(InvalidGeometryError, match="from 0 to 1"):
        distribution_mesh(uniform(4)[::-1], uniform(4), uniform(3), uniform(3))


def test_sides_slid_on_a_bilinear_grid_are_carried_in_as_the_interpolation_of_the_new_sides():
    """``carried_inward`` adds the transfinite interpolation of the sides' moves; on a grid
    that is itself the interpolation of its sides (a uniform one) the result is the
    interpolation of the moved sides, exactly."""
    from surfprep.algorithms.grid.tfi import carried_inward
    ni, nj = 9, 7
    x, y = np.meshgrid(np.linspace(0, 2, ni), np.linspace(0, 1, nj), indexing="ij")
    before = np.stack([x, y], axis=-1)
    after = before.copy()
    wave_i, wave_j = np.sin(np.pi * uniform(ni)), np.sin(np.pi * uniform(nj))
    after[:, 0, 0] += 0.05 * wave_i                   # the bottom's nodes slide along it
    after[:, -1, 0] -= 0.03 * wave_i
    after[0, :, 1] += 0.04 * wave_j
    after[-1, :, 1] += 0.02 * wave_j ** 2
    moved = carried_inward(before, after)
    S, T = np.meshgrid(uniform(ni), uniform(nj), indexing="ij")
    expected = transfinite(after[:, 0], after[:, -1], after[0], after[-1], weights=(S, T))
    np.testing.assert_allclose(moved, expected, atol=1e-14)
    assert np.abs(moved[1:-1, 1:-1] - before[1:-1, 1:-1]).max() > 0.01    # the interior moved
    with pytest.raises(InvalidGeometryError, match="one shape"):
        carried_inward(before, after[:-1])
