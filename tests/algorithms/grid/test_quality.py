"""Grid quality measured on the surface, against figures known by construction."""

from __future__ import annotations

import json

import numpy as np
import pytest

from surfprep.algorithms.grid import grid_quality


def _plane_grid(ni, nj, shear=0.0, dx=1.0, dy=1.0):
    i, j = np.meshgrid(np.arange(ni) * dx, np.arange(nj) * dy, indexing="ij")
    points = np.stack([i + shear * j, j, np.zeros_like(i)], -1)
    normals = np.broadcast_to([0.0, 0.0, 1.0], points.shape)
    return points, normals


def test_a_rectangular_grid_is_perfect():
    q = grid_quality(*_plane_grid(6, 4, dx=2.0, dy=0.5))
    assert q.min_angle == pytest.approx(90.0) and q.max_angle == pytest.approx(90.0)
    assert q.max_skewness == pytest.approx(0.0, abs=1e-12)
    assert q.max_aspect_ratio == pytest.approx(4.0)
    assert q.max_growth_ratio == pytest.approx(1.0)
    assert q.min_scaled_jacobian == pytest.approx(1.0)
    assert q.folded_cells == 0 and q.max_area_ratio == pytest.approx(1.0)
    assert q.skewness_bands == {"good": 15, "acceptable": 0, "poor": 0}
    json.dumps(q.report())


def test_a_sheared_grid_has_its_known_angle_and_skewness():
    q = grid_quality(*_plane_grid(5, 5, shear=1.0))          # 45 degree parallelograms
    assert q.min_angle == pytest.approx(45.0) and q.max_angle == pytest.approx(45.0)
    assert q.max_skewness == pytest.approx(0.5)
    assert q.min_scaled_jacobian == pytest.approx(np.sqrt(0.5))


def test_a_fold_is_counted():
    points, normals = _plane_grid(5, 5)
    points = points.copy()
    points[2, 2] = [3.4, 3.4, 0.0]                            # pulled across its neighbours
    q = grid_quality(points, normals)
    assert q.folded_cells > 0 and q.min_scaled_jacobian < 0


def test_growth_ratio_of_a_geometric_line():
    i = 1.3 ** np.arange(6)
    x = np.concatenate([[0.0], np.cumsum(i)])
    X, Y = np.meshgrid(x, np.arange(3.0), indexing="ij")
    points = np.stack([X, Y, np.zeros_like(X)], -1)
    q = grid_quality(points, np.broadcast_to([0.0, 0.0, 1.0], points.shape))
    assert q.max_growth_ratio == pytest.approx(1.3)


def test_collapsed_side_corners_are_left_out():
    # a triangle: side i = 0 collapsed to the origin
    u, v = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 1, 5), indexing="ij")
    points = np.stack([u, u * v, np.zeros_like(u)], -1)
    q = grid_quality(points, np.broadcast_to([0.0, 0.0, 1.0], points.shape))
    assert q.collapsed_corners == 2 * 4                       # two corners of each of the 4 pole cells
    assert q.folded_cells == 0 and q.min_scaled_jacobian > 0
    assert np.isfinite(q.max_growth_ratio) and np.isfinite(q.max_skewness)
