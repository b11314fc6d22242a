"""Blocks on trimmed faces bounded by one loop of four edges (Region.from_loop)."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep import NurbsCurve, NurbsSurface, TrimEdge, TrimLoop, TrimmedFace
from surfprep.algorithms.grid.faces import face_region
from surfprep.algorithms.grid.network import grid_network
from surfprep.algorithms.grid.region import Region
from surfprep.algorithms.grid.structured import grid_region

P0, A, B = np.array([0.2, 0.1]), np.array([1.4, 0.3]), np.array([0.3, 1.4])
CORNERS = [P0, P0 + A, P0 + A + B, P0 + B]           # a parallelogram, counter-clockwise


def _plane() -> NurbsSurface:
    """z = 0 over [0, 2]^2 with (u, v) = (x, y)."""
    g = np.array([0.0, 2.0])
    cp = np.zeros((2, 2, 3))
    cp[..., 0], cp[..., 1] = np.meshgrid(g, g, indexing="ij")
    return NurbsSurface(cp, [0, 0, 2, 2], [0, 0, 2, 2], 1, 1)


def _edge(a, b) -> TrimEdge:
    line = NurbsCurve(np.array([a, b], float), [0, 0, 1, 1], 1)
    curve3d = NurbsCurve(np.array([[*a, 0.0], [*b, 0.0]]), [0, 0, 1, 1], 1)
    return TrimEdge(curve3d, line, 0.0, 1.0)


def _face(corners, *, reversed_=False, start=0) -> TrimmedFace:
    order = corners[start:] + corners[:start]
    edges = [_edge(order[k], order[(k + 1) % 4]) for k in range(4)]
    return TrimmedFace(_plane(), (TrimLoop(tuple(edges)),), 0, reversed_)


def _exact(ni, nj, corner_order):
    p0, p1, _, p3 = corner_order
    i, j = np.meshgrid(np.linspace(0, 1, ni), np.linspace(0, 1, nj), indexing="ij")
    xy = p0 + i[..., None] * (p1 - p0) + j[..., None] * (p3 - p0)
    return np.concatenate([xy, np.zeros(xy.shape[:2] + (1,))], axis=-1)


@pytest.mark.parametrize("start", [0, 1, 2, 3])
def test_a_parallelogram_face_gets_its_affine_grid_with_i_along_u(start):
    """Winslow's grid of a parallelogram with uniform sides is the affine map (without the
    sides' orthogonality, which bends its lines to meet them at right angles); the loop
    may start at any corner: j0 is the side running most nearly along +u."""
    face = _face(CORNERS, start=start)
    region = face_region(face)
    assert isinstance(region, Region) and not region.is_rectangle
    grid = grid_region(region, dims=(11, 9), orthogonal=False)
    np.testing.assert_allclose(grid.points, _exact(11, 9, CORNERS), atol=1e-9)
    assert grid.orientation == 1 and grid.quality.folded_cells == 0
    np.testing.assert_allclose(grid.report()["corner_angles"][0], np.degrees(
        np.arccos(A @ B / np.linalg.norm(A) / np.linalg.norm(B))), atol=1e-9)


def test_a_face_used_reversed_is_taken_clockwise():
    face = _face(CORNERS, reversed_=True)
    grid = grid_region(face_region(face), dims=(11, 9))
    assert grid.orientation == -1 and grid.quality.folded_cells == 0
    x = grid.points
    normal = np.cross(x[1, 0] - x[0, 0], x[0, 1] - x[0, 0])
    assert normal[2] < 0                                    # against S_u x S_v = +z


def test_two_trimmed_faces_sharing_an_edge_are_point_matched():
    left = _face([np.array([0.1, 0.1]), np.array([1.0, 0.2]), np.array([1.1, 1.8]), np.array([0.2, 1.7])])
    right = _face([np.array([1.0, 0.2]), np.array([1.9, 0.1]), np.array([1.8, 1.9]), np.array([1.1, 1.8])])
    net = grid_network([face_region(left), face_region(right)], gap=1e-9, size=0.1)
    (f,) = net.interfaces
    assert {(f.block, f.side), (f.other, f.other_side)} == {(0, "i1"), (1, "i0")}
    a = net.blocks[0].points[-1]
    b = net.blocks[1].points[0]
    assert np.array_equal(a, b)
    assert net.snap < 1e-12 and all(b.quality.folded_cells == 0 for b in net.blocks)


def test_faces_that_are_not_four_sided_say_so():
    five = [np.array([0.2, 0.1]), np.array([1.0, 0.05]), np.array([1.8, 0.3]),
            np.array([1.6, 1.9]), np.array([0.3, 1.7])]
    edges = [_edge(five[k], five[(k + 1) % 5]) for k in range(5)]
    face = TrimmedFace(_plane(), (TrimLoop(tuple(edges)),))
    assert face_region(face) == "it has 5 edges, not four: heal or split it into four-sided faces first"


def test_locate_finds_the_nearest_point_of_a_curved_side():
    """Points off a side whose pcurve is a quarter circle on a warped plane: the foot located
    is the nearest point of the side found by a dense brute-force search."""
    from helpers.grid_cases import warped_plane
    from surfprep.algorithms.grid.region import Side
    theta = np.linspace(0, np.pi / 2, 9)
    arc = np.stack([0.5 + 0.4 * np.cos(theta), 0.1 + 0.4 * np.sin(theta)], axis=1)
    surface = warped_plane()
    side = Side(surface, NurbsCurve(arc, np.r_[0, np.linspace(0, 1, 9), 1], 1), 0.0, 1.0)
    rng = np.random.default_rng(5)
    x = np.sort(rng.uniform(0, 1, 40))
    off = side.points(x) + rng.normal(scale=0.01, size=(40, 3))
    found = side.locate(off)
    dense_x = np.linspace(0, 1, 200001)
    dense = side.points(dense_x)
    truth = dense_x[np.argmin(np.linalg.norm(off[:, None] - dense[None], axis=2), axis=1)]
    np.testing.assert_allclose(found, truth, atol=2e-5)
