"""A pole cap gridded in its disc chart: the O-type grid remapped to an H-type one (003 Fig. 5)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.grid_cases import pole_patch
from helpers.occ_shapes import sphere, torus

import surfprep
from surfprep.algorithms.grid.faces import pole_halves, rectangle_regions
from surfprep.algorithms.grid.io.blocks import side_nodes
from surfprep.algorithms.grid.polar import PoleChart, cap_regions, pole_cap
from surfprep.errors import InvalidGeometryError

R = 5.0


@pytest.fixture(scope="module")
def cap() -> PoleChart:
    chart = pole_cap(pole_halves(sphere(R))[0])
    assert chart is not None
    return chart


def _differences(chart: PoleChart, x: np.ndarray, y: np.ndarray, h: float = 1e-6):
    fx = (chart.evaluate(x + h, y) - chart.evaluate(x - h, y)) / (2 * h)
    fy = (chart.evaluate(x, y + h) - chart.evaluate(x, y - h)) / (2 * h)
    return fx, fy


def test_the_chart_derivatives_are_the_surface_s_by_the_chain_rule(cap):
    x, y = np.array([0.3, -0.2, 0.01, -0.7, 0.05]), np.array([0.1, 0.5, -0.02, -0.6, 0.9])
    d = cap.derivatives(x, y)
    fx, fy = _differences(cap, x, y)
    scale = np.linalg.norm(fx, axis=-1).max()
    assert np.abs(d[..., 1, 0, :] - fx).max() < 1e-6 * scale
    assert np.abs(d[..., 0, 1, :] - fy).max() < 1e-6 * scale
    assert np.allclose(d[..., 0, 0, :], cap.evaluate(x, y))
    # the pole is an ordinary point of the chart: radius by meridian length, angle by the
    # length round the parallel, so the hemisphere's chart is its azimuthal equidistant map
    d0 = cap.derivatives(np.array([0.0]), np.array([0.0]))
    fx, fy = _differences(cap, np.array([0.0]), np.array([0.0]))
    assert np.abs(d0[0, 1, 0] - fx[0]).max() < 1e-2 * scale and np.abs(d0[0, 0, 1] - fy[0]).max() < 1e-2 * scale
    quarter = R * np.pi / 2                                   # pole to equator
    assert np.linalg.norm(fx[0]) == pytest.approx(quarter, rel=1e-3)
    assert np.linalg.norm(fy[0]) == pytest.approx(quarter, rel=1e-3)


def test_the_chart_normals_follow_its_own_orientation(cap):
    x, y = np.array([0.2, -0.5, 0.0]), np.array([0.3, 0.1, 0.0])
    n = cap.normals(x, y)
    d = cap.derivatives(x[:2], y[:2])
    cross = np.cross(d[..., 1, 0, :], d[..., 0, 1, :])
    assert np.allclose(n[:2], cross / np.linalg.norm(cross, axis=-1, keepdims=True), atol=1e-9)
    assert np.allclose(np.abs(n[2]), [0, 0, 1], atol=1e-9)          # at the pole, on the axis


def test_only_caps_closed_round_one_pole_get_a_chart():
    assert pole_cap(pole_patch()) is None                   # a pole, not closed round it
    assert pole_cap(torus(10.0, 3.0)) is None               # closed, no pole
    assert pole_cap(sphere(R)) is None                      # two poles: halves first


def test_cap_regions_are_a_square_over_the_pole_and_four_round_it(cap):
    regions = cap_regions(cap)
    assert len(regions) == 5
    # the rim is split at the four diagonals, an eighth of a turn past the seam
    rims = [r.sides[name] for r in regions[1:] for name in r.sides
            if np.allclose(np.hypot(*r.sides[name].uv(np.linspace(0, 1, 5)).T), 1.0)]
    assert len(rims) == 4
    assert sum(s.length for s in rims) == pytest.approx(2 * np.pi * R, rel=1e-6)
    with pytest.raises(ValueError, match="corner_radius"):
        cap_regions(cap, corner_radius=1.0)


def test_a_sphere_with_h_type_caps_has_no_cell_at_a_pole():
    """Both hemispheres as butterflies: ten blocks point-matched on twenty shared edges,
    no collapsed side, every node on the sphere, the cells adding up to its area; three
    blocks meet at 120 degrees at the square's corners (a straight square: 90 + 135 +
    135, skewness 0.5)."""
    result = surfprep.grid(sphere(R), size=0.5, pole_caps="h")
    net = result.network
    assert len(net.blocks) == 10 and len(net.interfaces) == 20 and not result.skipped
    for f in net.interfaces:
        a = side_nodes(net.blocks[f.block].points, f.side)
        b = side_nodes(net.blocks[f.other].points, f.other_side)
        assert np.array_equal(a[::-1] if f.reversed else a, b)
    assert all(not b.collapsed_sides for b in net.blocks)
    nodes = np.concatenate([b.reshape(-1, 3) for b in result.blocks])
    assert np.abs(np.linalg.norm(nodes, axis=1) - R).max() < 1e-9
    worst = result.report()["worst"]
    assert worst["folded_cells"] == 0 and worst["max_skewness"] < 0.4 and worst["min_angle"] > 55.0
    assert worst["max_growth_ratio"] < 1.3
    d1 = [b[1:, 1:] - b[:-1, :-1] for b in result.blocks]
    d2 = [b[:-1, 1:] - b[1:, :-1] for b in result.blocks]
    area = sum(0.5 * np.linalg.norm(np.cross(a, b), axis=-1).sum() for a, b in zip(d1, d2, strict=True))
    assert area == pytest.approx(4 * np.pi * R ** 2, rel=5e-3)
    # the parameters returned are the sphere halves' own (u, v), not the chart's
    halves = pole_halves(sphere(R))
    for block, k in zip(net.blocks, range(10), strict=True):
        half = halves[k // 5]
        p = block.parameters
        assert np.abs(half.evaluate(p[..., 0], p[..., 1]) - block.points).max() < 1e-9


def test_the_default_keeps_o_type_caps_and_a_bad_choice_is_refused():
    assert len(rectangle_regions(sphere(R))) == 2
    assert len(rectangle_regions(sphere(R), pole_caps="h")) == 10
    with pytest.raises(InvalidGeometryError, match="pole_caps"):
        rectangle_regions(sphere(R), pole_caps="x")
    with pytest.raises(InvalidGeometryError, match="pole_caps"):
        surfprep.grid(sphere(R), pole_caps="butterfly")


def test_a_sphere_read_from_step_with_h_type_caps(tmp_path):
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeSphere
    path = tmp_path / "ball.step"
    surfprep.write(BRepPrimAPI_MakeSphere(2.0).Shape(), path)
    result = surfprep.grid(path, size=0.25, pole_caps="h")
    assert len(result.blocks) == 10 and result.faces == (0,) * 10
    assert result.report()["worst"]["folded_cells"] == 0
    nodes = np.concatenate([b.reshape(-1, 3) for b in result.blocks])
    assert np.abs(np.linalg.norm(nodes, axis=1) - 2.0).max() < 1e-7
