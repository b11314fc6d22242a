"""Faces cut into parts the block layouts take (holes apart, reflex corners), then gridded."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep import NurbsCurve, NurbsSurface, TrimEdge, TrimLoop, TrimmedFace
from surfprep.algorithms.grid.faces import face_regions
from surfprep.algorithms.grid.network import grid_network
from surfprep.algorithms.grid.parts import separate_holes, split_at_reflex
from surfprep.algorithms.healing.loop_sides import NotDecomposableError

SIDE = 4.0                                      # the plane (u, v) -> (4u, 4v, 0)


def _plane() -> NurbsSurface:
    g = np.array([0.0, SIDE])
    cp = np.zeros((2, 2, 3))
    cp[..., 0], cp[..., 1] = np.meshgrid(g, g, indexing="ij")
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def _edge(a, b) -> TrimEdge:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return TrimEdge(NurbsCurve(np.array([[*(SIDE * a), 0], [*(SIDE * b), 0]]), [0, 0, 1, 1], 1),
                    NurbsCurve(np.array([a, b]), [0, 0, 1, 1], 1), 0.0, 1.0)


def _hole(centre, radius) -> TrimLoop:
    """A circle run clockwise (a hole), rational quadratic."""
    s = np.sqrt(0.5)
    unit = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]], float)
    weights = np.array([1, s, 1, s, 1, s, 1, s, 1])
    knots = [0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1]
    uv = np.asarray(centre) + radius * unit
    return TrimLoop((TrimEdge(NurbsCurve(np.column_stack([SIDE * uv, np.zeros(9)]), knots, 2, weights),
                              NurbsCurve(uv, knots, 2, weights), 0.0, 1.0, reversed=True),))


def _plate(*centres, radius=0.1) -> TrimmedFace:
    outer = TrimLoop((_edge((0, 0), (1, 0)), _edge((1, 0), (1, 1)), _edge((1, 1), (0, 1)),
                      _edge((0, 1), (0, 0))))
    return TrimmedFace(_plane(), (outer, *[_hole(c, radius) for c in centres]))


def _cells_area(points) -> float:
    d1, d2 = points[1:, :-1] - points[:-1, :-1], points[:-1, 1:] - points[:-1, :-1]
    d3, d4 = points[1:, 1:] - points[1:, :-1], points[1:, 1:] - points[:-1, 1:]
    return float(0.5 * np.abs(np.cross(d1, d2)[..., 2]).sum() + 0.5 * np.abs(np.cross(d3, d4)[..., 2]).sum())


@pytest.mark.parametrize("centres", [[(0.3, 0.5), (0.7, 0.5)], [(0.25, 0.3), (0.75, 0.3), (0.5, 0.75)],
                                     [(0.2, 0.2), (0.5, 0.2), (0.8, 0.2), (0.2, 0.7), (0.5, 0.7), (0.8, 0.7)]])
def test_a_plate_with_holes_is_cut_into_parts_of_one_hole_and_gridded(centres):
    """Each part holds one hole and keeps its area; the blocks (four round each hole:
    the parts' outlines have four corners) tile the plate less its holes, point-matched,
    with no fold."""
    face = _plate(*centres)
    parts = separate_holes(face)
    assert len(parts) == len(centres) and all(len(p.loops) == 2 for p in parts)
    regions = face_regions(face, gap_tol=1e-6)
    assert not isinstance(regions, str) and len(regions) == 4 * len(centres)
    net = grid_network(regions, gap=1e-6, size=0.05)
    assert sum(b.quality.folded_cells for b in net.blocks) == 0 and net.snap < 1e-9
    area = sum(_cells_area(b.points) for b in net.blocks)
    exact = SIDE ** 2 - len(centres) * np.pi * (SIDE * 0.1) ** 2
    assert area == pytest.approx(exact, rel=1e-3)          # the cells' chords inside the circles
    # every shared edge is one: the cuts between the parts are matched sides
    assert len(net.interfaces) >= 4 * len(centres)


def test_a_face_with_at_most_one_hole_is_not_cut():
    face = _plate((0.5, 0.5))
    assert separate_holes(face) == [face]


def _polygon_hole(*corners) -> TrimLoop:
    """A hole bounded by straight edges through ``corners`` (given counter-clockwise,
    run clockwise)."""
    corners = corners[::-1]
    return TrimLoop(tuple(_edge(corners[k], corners[(k + 1) % len(corners)]) for k in range(len(corners))))


def test_holes_no_straight_cut_separates_are_refused_with_the_reason():
    """A small square hole in the inner corner of an L-shaped hole: the square lies in
    the hull of the L, so no straight line has them on two sides."""
    outer = TrimLoop((_edge((0, 0), (1, 0)), _edge((1, 0), (1, 1)), _edge((1, 1), (0, 1)),
                      _edge((0, 1), (0, 0))))
    ell = _polygon_hole((0.4, 0.4), (0.9, 0.4), (0.9, 0.45), (0.45, 0.45), (0.45, 0.9), (0.4, 0.9))
    square = _polygon_hole((0.5, 0.5), (0.6, 0.5), (0.6, 0.6), (0.5, 0.6))
    face = TrimmedFace(_plane(), (outer, ell, square))
    with pytest.raises(NotDecomposableError, match="no straight cut"):
        separate_holes(face)
    assert "not cut into parts of one hole" in face_regions(face, gap_tol=1e-6)


def _outline(*corners) -> TrimLoop:
    """A loop of straight edges through ``corners`` (counter-clockwise)."""
    return TrimLoop(tuple(_edge(corners[k], corners[(k + 1) % len(corners)]) for k in range(len(corners))))


def test_an_l_is_cut_at_its_reflex_corner_into_two_rectangles():
    face = TrimmedFace(_plane(), (_outline((0, 0), (1, 0), (1, 0.4), (0.4, 0.4), (0.4, 1), (0, 1)),))
    parts = split_at_reflex(face)
    assert parts is not None and len(parts) == 2
    areas = sorted(abs(_loop_area(p)) for p in parts)
    # the bisector of the corner's inner angle (45 degrees) runs to the corner (0, 0)
    assert sum(areas) == pytest.approx(0.64, abs=1e-9) and areas[0] == pytest.approx(0.32, abs=1e-9)
    assert split_at_reflex(_plate()) is None                   # a square: no reflex corner


@pytest.mark.parametrize(("corners", "blocks"), [
    ([(0, 0), (1, 0), (1, 1), (0.7, 1), (0.7, 0.3), (0.3, 0.3), (0.3, 1), (0, 1)], 3),          # a U
    ([(0, 0), (1, 0), (1, 1), (0.8, 1), (0.8, 0.3), (0.6, 0.3), (0.6, 1), (0.4, 1), (0.4, 0.3),
      (0.2, 0.3), (0.2, 1), (0, 1)], 18),                                                       # a comb
])
def test_very_non_convex_outlines_are_gridded_after_reflex_cuts(corners, blocks):
    """The star round a centre leaves these outlines (refused before); cut at reflex
    corners they are tiled exactly, no fold."""
    face = TrimmedFace(_plane(), (_outline(*corners),))
    regions = face_regions(face, gap_tol=1e-6)
    assert not isinstance(regions, str) and len(regions) == blocks
    net = grid_network(regions, gap=1e-6, size=0.1)
    assert sum(b.quality.folded_cells for b in net.blocks) == 0
    x, y = (SIDE * np.array(corners, float)).T
    exact = 0.5 * abs(float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)))
    assert sum(_cells_area(b.points) for b in net.blocks) == pytest.approx(exact, rel=1e-9)


def _loop_area(face: TrimmedFace) -> float:
    from surfprep.algorithms.trimmed import loop_uv
    uv = loop_uv(face.loops[0])
    return 0.5 * float(np.sum(uv[:, 0] * np.roll(uv[:, 1], -1) - np.roll(uv[:, 0], -1) * uv[:, 1]))
