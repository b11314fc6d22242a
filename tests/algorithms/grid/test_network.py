"""Point-matched grids over a network of four-sided surfaces."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.grid_cases import warped_plane

from surfprep import NurbsSurface
from surfprep.algorithms.grid.io import side_nodes
from surfprep.algorithms.grid.network import grid_network, match_sides
from surfprep.errors import InvalidGeometryError


def _flip_u(s: NurbsSurface) -> NurbsSurface:
    ku = (s.knots_u[0] + s.knots_u[-1]) - s.knots_u[::-1]
    return NurbsSurface(s.control_points[::-1], ku, s.knots_v, s.degree_u, s.degree_v,
                        None if s.weights is None else s.weights[::-1])


def _quarters(flip_last: bool = False) -> list[NurbsSurface]:
    """The warped plane cut into four by its iso-lines u = 0.5 and v = 0.4."""
    a, b = warped_plane().split(0.5, "u")
    a1, a2 = a.split(0.4, "v")
    b1, b2 = b.split(0.4, "v")
    return [a1, a2, b1, _flip_u(b2) if flip_last else b2]


def _plane_strip(y0: float, y1: float, middle_x: float) -> NurbsSurface:
    """The rectangle [0, 1] x [y0, y1] of the plane z = 0, quadratic in u with its middle
    control column at x = ``middle_x``: the same sides as a bilinear patch, another speed
    along them (0.5 in u is x = 0.5 only for middle_x = 0.5)."""
    x = np.array([0.0, middle_x, 1.0])
    pts = np.zeros((3, 2, 3))
    pts[:, :, 0] = x[:, None]
    pts[:, :, 1] = [y0, y1]
    return NurbsSurface(pts, [0, 0, 0, 1, 1, 1], [0, 0, 1, 1], 2, 1)


def test_a_side_parametrized_otherwise_still_matches():
    """A shared edge runs at another speed on each face (one face reparametrized, its
    neighbour not): the sides are one edge, matched at equal fractions of arc length."""
    a, b = _plane_strip(0.0, 1.0, 0.5), _plane_strip(1.0, 2.0, 0.1)
    mid_a, mid_b = a.evaluate(0.5, 1.0), b.evaluate(0.5, 1.0)
    assert np.linalg.norm(mid_a - mid_b) > 0.1              # equal parameters, other places
    interfaces = match_sides([a, b], gap=1e-9)
    assert [(f.block, f.side, f.other, f.other_side, f.reversed) for f in interfaces] == [
        (0, "j1", 1, "j0", False)]


@pytest.mark.parametrize("flip_last", [False, True])
def test_shared_sides_are_found_in_either_direction(flip_last):
    interfaces = match_sides(_quarters(flip_last), gap=1e-9)
    pairs = {frozenset([(f.block, f.side), (f.other, f.other_side)]): f.reversed for f in interfaces}
    assert len(pairs) == 4
    assert pairs[frozenset([(0, "j1"), (1, "j0")])] is False
    assert pairs[frozenset([(0, "i1"), (2, "i0")])] is False
    # block 3 runs against u when flipped: its side i1 (not i0) meets block 1, and the
    # side it shares with block 2 runs the other way
    assert pairs[frozenset([(1, "i1"), (3, "i1" if flip_last else "i0")])] is False
    assert pairs[frozenset([(2, "j1"), (3, "j0")])] is flip_last


@pytest.mark.parametrize("flip_last", [False, True])
def test_shared_nodes_are_identical_and_lines_cross_smoothly(flip_last):
    net = grid_network(_quarters(flip_last), gap=1e-9, size=0.05)
    assert len(net.interfaces) == 4
    for f in net.interfaces:
        a = side_nodes(net.blocks[f.block].points, f.side)
        b = side_nodes(net.blocks[f.other].points, f.other_side)
        assert np.array_equal(a[::-1] if f.reversed else a, b)            # bit for bit
    assert net.snap < 1e-12                   # the quarters are cut from one surface
    # the whole plane: every block flat and unfolded, the lines crossing each cut
    # without a kink beyond a few degrees away from the corner where four blocks meet
    for block in net.blocks:
        assert block.quality.folded_cells == 0
        assert np.abs(block.points[..., 2]).max() < 1e-12
    assert all(crease < 1e-6 for _, crease in net.interface_angles)
    assert net.interface_rounds >= 1


def test_node_counts_follow_the_shared_edges():
    net = grid_network(_quarters(), gap=1e-9, size=0.1)
    dims = [b.dims for b in net.blocks]
    assert dims[0][0] == dims[1][0] and dims[2][0] == dims[3][0]        # i counts across the v cut
    assert dims[0][1] == dims[2][1] and dims[1][1] == dims[3][1]        # j counts across the u cut


def test_dims_linking_i_to_j_take_the_larger_count_and_say_so():
    """Quarter 1 turned (its i along the other's j): the shared edge links block 0's i
    (asked 9) to block 1's j (asked 5): both get 9 (block 1 is 9 x 9), the edge is
    still point-matched, and the direction that got more is named."""
    quarters = _quarters()
    turned = NurbsSurface(np.transpose(quarters[1].control_points, (1, 0, 2)), quarters[1].knots_v,
                          quarters[1].knots_u, quarters[1].degree_v, quarters[1].degree_u)
    net = grid_network([quarters[0], turned], gap=1e-9, dims=(9, 5))
    assert [b.dims for b in net.blocks] == [(9, 5), (9, 9)]
    assert net.dims_changed == ((1, "j", 9),)
    assert net.report()["dims_changed"] == [{"block": 1, "direction": "j", "nodes": 9}]
    (f,) = net.interfaces
    a = side_nodes(net.blocks[f.block].points, f.side)
    b = side_nodes(net.blocks[f.other].points, f.other_side)
    assert np.array_equal(a[::-1] if f.reversed else a, b)
    same = grid_network(_quarters(), gap=1e-9, dims=(9, 5))      # consistent: as asked
    assert all(b.dims == (9, 5) for b in same.blocks) and same.dims_changed == ()
    with pytest.raises(InvalidGeometryError, match="not both"):
        grid_network(quarters, gap=1e-9, dims=(5, 5), size=0.1)


def test_a_surface_that_cannot_be_gridded_is_left_out_and_said():
    """A surface whose normal vanishes to second order at a corner (all its control
    points but one row on a point) is reported; the other blocks are gridded."""
    quarters = _quarters()
    bad = quarters[3].control_points.copy()
    bad[:, :] = bad[0, 0]
    bad[-1, -1] += [1.0, 1.0, 0.0]
    degenerate = NurbsSurface(bad, quarters[3].knots_u, quarters[3].knots_v, 3, 3)
    net = grid_network([quarters[0], quarters[1], degenerate], gap=1e-9, size=0.1)
    assert net.indices == (0, 1) and [b for b, _ in net.failed] == [2]
    assert len(net.interfaces) == 1
    with pytest.raises(InvalidGeometryError, match="no surface could be gridded"):
        grid_network([degenerate], gap=1e-9, size=0.1)


def test_a_region_whose_side_runs_far_beyond_its_surface_is_refused_with_the_reason():
    """A region's pcurve zigzagging across the domain (as a split gone astray left one on
    occt_b1_euclid.stp: a side 1.3e7 mm long on a 7.7 mm surface, whose node count then
    asked for 3.4 GB): that block is refused and named; the others are gridded."""
    from surfprep.algorithms import NurbsCurve
    from surfprep.algorithms.grid.region import Region
    plane = warped_plane()
    u0, u1, v0, v1 = plane.domain
    # from (u0, v1) down to (u0, v0), crossing the domain 60 times on the way
    zig = np.array([[u0 + (u1 - u0) * (k % 2), v1 - (v1 - v0) * k / 60] for k in range(61)])
    zig[-1, 0] = u0
    zigzag = NurbsCurve(zig, np.concatenate([[0.0], np.linspace(0, 1, 61), [1.0]]), 1)

    def seg(a, b):
        return NurbsCurve(np.array([a, b], dtype=float), [0, 0, 1, 1], 1)
    runs = [(seg((u0, v0), (u1, v0)), 0.0, 1.0), (seg((u1, v0), (u1, v1)), 0.0, 1.0),
            (seg((u1, v1), (u0, v1)), 0.0, 1.0), (zigzag, 0.0, 1.0)]
    astray = Region.from_runs(plane, runs)
    net = grid_network([warped_plane().split(0.5, "u")[0], astray], gap=1e-9, size=0.1)
    assert [b for b, _ in net.failed] == [1] and "astray" in net.failed[0][1]
    assert len(net.blocks) == 1


def test_dims_beyond_a_hundred_thousand_nodes_a_side_are_refused():
    from surfprep.algorithms.grid import grid_surface
    with pytest.raises(InvalidGeometryError, match="at most 1e5"):
        grid_surface(warped_plane(), dims=(200_000, 3))
