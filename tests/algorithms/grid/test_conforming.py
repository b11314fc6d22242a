"""Block layouts made conforming: T-junctions cut through, so shared edges are whole sides."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms import NurbsSurface
from surfprep.algorithms.grid.conforming import SNAP, conforming, t_junctions
from surfprep.algorithms.grid.io.blocks import side_nodes
from surfprep.algorithms.grid.network import grid_network
from surfprep.algorithms.grid.region import Region

GAP = 1e-9


def rectangle(x0: float, x1: float, y0: float, y1: float) -> NurbsSurface:
    """The rectangle ``[x0, x1] x [y0, y1]`` of the plane z = 0, u along x."""
    cp = np.array([[[x0, y0, 0.0], [x0, y1, 0.0]], [[x1, y0, 0.0], [x1, y1, 0.0]]])
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def _area(block: np.ndarray) -> float:
    d1, d2 = block[1:, 1:] - block[:-1, :-1], block[:-1, 1:] - block[1:, :-1]
    return 0.5 * float(np.linalg.norm(np.cross(d1, d2), axis=-1).sum())


def _assert_matched(net) -> None:
    for f in net.interfaces:
        a = side_nodes(net.blocks[f.block].points, f.side)
        b = side_nodes(net.blocks[f.other].points, f.other_side)
        assert np.array_equal(a[::-1] if f.reversed else a, b)


def test_a_corner_inside_a_side_is_found_at_its_arc_length_fraction():
    tall = rectangle(0, 1, 0, 2)
    low, high = rectangle(1, 2, 0, 1.5), rectangle(1, 2, 1.5, 2)
    found = t_junctions([tall, low, high], gap=GAP)
    assert set(found) == {(0, "i1")}
    assert found[0, "i1"] == pytest.approx([0.75])


def test_a_tall_block_beside_two_is_cut_where_they_meet():
    """Without the cut the tall block's side matches neither neighbour (one shared edge,
    theirs); cut at y = 1.5 both halves match: four shared edges, node for node."""
    layout = [rectangle(0, 1, 0, 2), rectangle(1, 2, 0, 1.5), rectangle(1, 2, 1.5, 2)]
    made = conforming(layout, gap=GAP)
    assert made.cuts == 1 and made.left == 0 and made.origin == (0, 0, 1, 2)
    assert all(isinstance(s, NurbsSurface) for s in made.surfaces)     # iso-cut: rectangles
    u0, _, _, v1 = made.surfaces[0].domain
    assert made.surfaces[0].evaluate(u0, v1) == pytest.approx([0.0, 1.5, 0.0])
    assert not t_junctions(list(made.surfaces), gap=GAP)

    plain = grid_network(layout, gap=GAP, size=0.1, conform=False)
    assert len(plain.interfaces) == 1
    net = grid_network(layout, gap=GAP, size=0.1)
    assert len(net.blocks) == 4 and len(net.interfaces) == 4
    assert net.cuts == 1 and net.t_junctions_left == 0 and net.indices == (0, 0, 1, 2)
    _assert_matched(net)
    assert sum(_area(b.points) for b in net.blocks) == pytest.approx(4.0, rel=1e-9)
    assert net.report()["cuts"] == 1


def test_cuts_propagate_through_a_row_until_they_reach_the_boundary():
    """Two tall blocks and two stacked ones: the cut of the middle block ends on the first
    block's side, which is then cut too."""
    layout = [rectangle(0, 1, 0, 2), rectangle(1, 2, 0, 2), rectangle(2, 3, 0, 0.8), rectangle(2, 3, 0.8, 2)]
    made = conforming(layout, gap=GAP)
    assert made.cuts == 2 and made.left == 0 and len(made.surfaces) == 6
    net = grid_network(layout, gap=GAP, size=0.1)
    assert len(net.interfaces) == 7
    _assert_matched(net)
    assert all(b.quality.folded_cells == 0 for b in net.blocks)


def test_a_cut_ends_on_a_corner_nearly_across():
    """Corners at y = 1.0 on the right side and 1.2 on the left (within SNAP): one slanted
    cut joins them instead of two cuts and a sliver between."""
    layout = [rectangle(-1, 0, 0, 1.2), rectangle(-1, 0, 1.2, 2), rectangle(0, 1, 0, 2),
              rectangle(1, 2, 0, 1.0), rectangle(1, 2, 1.0, 2)]
    assert 0.1 < SNAP
    made = conforming(layout, gap=GAP)
    assert made.cuts == 1 and made.left == 0
    pieces = [s for s, k in zip(made.surfaces, made.origin, strict=True) if k == 2]
    assert len(pieces) == 2 and all(isinstance(p, Region) and not p.is_rectangle for p in pieces)
    wanted = {(1.0, 1.0, 0.0), (0.0, 1.2, 0.0)}
    cuts = [side for side in pieces[0].sides.values()
            if {tuple(np.round(e, 12) + 0.0) for e in side.points(np.array([0.0, 1.0]))} == wanted]
    assert len(cuts) == 1
    cut = cuts[0]
    # on the plane's straight cut: the line between them
    mid = cut.points(np.linspace(0, 1, 9))
    assert np.abs(mid[:, 1] - (1.2 - 0.2 * mid[:, 0])).max() < 1e-9
    net = grid_network(layout, gap=GAP, size=0.1)
    _assert_matched(net)
    assert len(net.interfaces) == 7 and all(b.quality.folded_cells == 0 for b in net.blocks)
    assert sum(_area(b.points) for b in net.blocks) == pytest.approx(6.0, rel=1e-9)


def test_fixed_blocks_are_not_cut_and_what_is_left_is_counted():
    layout = [rectangle(0, 1, 0, 2), rectangle(1, 2, 0, 1.5), rectangle(1, 2, 1.5, 2)]
    made = conforming(layout, gap=GAP, fixed=frozenset({0}))
    assert made.cuts == 0 and made.left == 1 and len(made.surfaces) == 3
