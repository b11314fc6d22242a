"""Splitting a trimmed face along curves in its domain: regions, areas, closed loops."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep import NurbsCurve, NurbsSurface, TrimEdge, TrimLoop, TrimmedFace
from surfprep.algorithms.face_split import Cut, split_face
from surfprep.errors import InvalidGeometryError


def _plane() -> NurbsSurface:
    """z = 0 over [0, 1]^2, (u, v) = (x, y)."""
    g = np.array([0.0, 1.0])
    cp = np.zeros((2, 2, 3))
    cp[..., 0], cp[..., 1] = np.meshgrid(g, g, indexing="ij")
    return NurbsSurface(cp, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)


def _line(a, b) -> Cut:
    pcurve = NurbsCurve(np.array([a, b], float), [0, 0, 1, 1], 1)
    curve3d = NurbsCurve(np.array([[*a, 0.0], [*b, 0.0]]), [0, 0, 1, 1], 1)
    return Cut(pcurve, curve3d)


def _circle(centre, radius) -> Cut:
    """A closed rational quadratic circle, counter-clockwise."""
    s = np.sqrt(0.5)
    unit = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]], float)
    weights = np.array([1, s, 1, s, 1, s, 1, s, 1])
    knots = [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1]
    return Cut(NurbsCurve(np.asarray(centre) + radius * unit, knots, 2, weights))


def _area(face: TrimmedFace) -> float:
    """Parameter area: the outer loop's minus the holes' (shoelace on 2000 samples an edge)."""
    total = 0.0
    for loop in face.loops:
        parts = []
        for e in loop.edges:
            t = np.linspace(e.t0, e.t1, 2001)
            parts.append(e.pcurve.evaluate(t[::-1] if e.reversed else t)[:-1])
        uv = np.concatenate(parts)
        total += 0.5 * float(np.sum(uv[:, 0] * np.roll(uv[:, 1], -1) - np.roll(uv[:, 0], -1) * uv[:, 1]))
    return total


def _closed(face: TrimmedFace) -> None:
    for loop in face.loops:
        for a, b in zip(loop.edges, loop.edges[1:] + loop.edges[:1], strict=True):
            np.testing.assert_allclose(a.uv_ends()[1], b.uv_ends()[0], atol=1e-9)


def test_a_line_across_the_face_makes_two_regions():
    face = TrimmedFace(_plane())                              # the whole square, no loop
    parts = split_face(face, [_line((0.3, 0.0), (0.6, 1.0))])
    assert len(parts) == 2
    areas = sorted(_area(p) for p in parts)
    np.testing.assert_allclose(areas, [0.45, 0.55], atol=1e-12)
    for p in parts:
        _closed(p)
        assert len(p.loops) == 1 and _area(p) > 0               # counter-clockwise outer loops


def test_two_lines_make_three_regions_and_each_cut_bounds_two():
    cuts = [_line((0.2, 0.0), (0.3, 1.0)), _line((0.7, 0.0), (0.6, 1.0))]
    parts = split_face(TrimmedFace(_plane()), cuts)
    assert len(parts) == 3
    np.testing.assert_allclose(sum(_area(p) for p in parts), 1.0, atol=1e-12)
    np.testing.assert_allclose(sorted(_area(p) for p in parts), sorted([0.25, 0.4, 0.35]), atol=1e-12)
    for cut in cuts:
        uses = [e for p in parts for e in p.edges if e.pcurve is cut.pcurve]
        assert sorted(e.reversed for e in uses) == [False, True]


def test_a_closed_cut_makes_an_island_and_a_hole():
    parts = split_face(TrimmedFace(_plane()), [_circle((0.5, 0.5), 0.2)])
    assert len(parts) == 2
    island = min(parts, key=_area)
    rest = max(parts, key=_area)
    np.testing.assert_allclose(_area(island), np.pi * 0.04, rtol=1e-5)     # the samples' polygon
    np.testing.assert_allclose(_area(rest) + _area(island), 1.0, atol=1e-12)
    assert len(rest.loops) == 2 and len(island.loops) == 1


def test_cuts_through_a_hole():
    """A square plate with a square hole, cut by a line through the hole: two C shapes."""
    outer = [(0, 0), (1, 0), (1, 1), (0, 1)]
    hole = [(0.4, 0.4), (0.4, 0.6), (0.6, 0.6), (0.6, 0.4)]                 # clockwise
    loops = []
    for corners in (outer, hole):
        edges = []
        for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
            edges.append(_line(a, b))
        loops.append(TrimLoop(tuple(TrimEdge(c.curve3d, c.pcurve, 0.0, 1.0) for c in edges)))
    face = TrimmedFace(_plane(), tuple(loops))
    parts = split_face(face, [_line((0.5, 0.0), (0.5, 0.4)), _line((0.5, 0.6), (0.5, 1.0))])
    assert len(parts) == 2
    np.testing.assert_allclose([_area(p) for p in parts], [0.48, 0.48], atol=1e-12)
    for p in parts:
        _closed(p)
        assert len(p.loops) == 1


def test_crossing_cuts_make_four_regions():
    parts = split_face(TrimmedFace(_plane()), [_line((0.2, 0.0), (0.8, 1.0)), _line((0.8, 0.0), (0.2, 1.0))])
    assert len(parts) == 4
    np.testing.assert_allclose(sorted(_area(p) for p in parts), [0.15, 0.15, 0.35, 0.35], atol=1e-12)
    for p in parts:
        _closed(p)


def test_a_triangle_of_three_crossing_cuts_and_a_circle_across_one():
    """Three lines pairwise crossing inside the square (7 regions) and a circle crossing one
    line (it adds two: a lens on either side of the line)."""
    cuts = [_line((0.1, 0.0), (0.6, 1.0)), _line((0.9, 0.0), (0.4, 1.0)), _line((0.0, 0.3), (1.0, 0.35))]
    parts = split_face(TrimmedFace(_plane()), cuts)
    assert len(parts) == 7
    np.testing.assert_allclose(sum(_area(p) for p in parts), 1.0, atol=1e-12)
    more = split_face(TrimmedFace(_plane()), [_line((0.5, 0.0), (0.5, 1.0)), _circle((0.55, 0.5), 0.2)])
    assert len(more) == 4
    np.testing.assert_allclose(sum(_area(p) for p in more), 1.0, atol=1e-9)
    circle = sorted(_area(p) for p in more)[:2]
    np.testing.assert_allclose(sum(circle), np.pi * 0.04, rtol=1e-5)


def test_cuts_meeting_at_one_boundary_point_share_its_vertex():
    """Two curves from one point of the boundary (a V; the pieces of a curve touching the
    boundary, curves of three faces meeting at a corner): the loop is split there once
    and both cuts start at that vertex -- three regions."""
    parts = split_face(TrimmedFace(_plane()), [_line((0.5, 0.0), (0.2, 1.0)), _line((0.5, 0.0), (0.8, 1.0))])
    np.testing.assert_allclose(sorted(_area(p) for p in parts), [0.3, 0.35, 0.35], atol=1e-12)
    for p in parts:
        _closed(p)


def test_a_closed_cut_touching_the_boundary_is_cut_where_it_touches():
    """A circle inscribed in the square (a cylinder's section in a box's face it touches):
    it touches each side at its middle, so the face is the disc and four corners."""
    circle = _circle((0.5, 0.5), 0.5)
    curve3d = NurbsCurve(np.column_stack([circle.pcurve.control_points, np.zeros(9)]), circle.pcurve.knots, 2,
                         circle.pcurve.weights)
    parts = split_face(TrimmedFace(_plane()), [Cut(circle.pcurve, curve3d)], tol3d=1e-9)
    assert len(parts) == 5
    areas = sorted(_area(p) for p in parts)
    np.testing.assert_allclose(areas[-1], np.pi / 4, rtol=1e-6)
    np.testing.assert_allclose(areas[:4], [(1 - np.pi / 4) / 4] * 4, rtol=1e-5)
    assert all(len(p.loops) == 1 for p in parts)       # no island touching its hole


def test_a_cut_ending_on_another_cut_splits_it_there():
    """A T: one cut from the boundary ends on the inside of another running across the
    face: the other is split there and the face comes out in three."""
    across = _line((0.0, 0.5), (1.0, 0.5))
    stem = _line((0.4, 0.5), (0.4, 1.0))
    parts = split_face(TrimmedFace(_plane()), [across, stem])
    np.testing.assert_allclose(sorted(_area(p) for p in parts), [0.2, 0.3, 0.5], atol=1e-12)
    for p in parts:
        _closed(p)


def test_cuts_joined_end_to_end_inside_the_face_make_one_closed_chain():
    """Two half circles meeting inside the face (an intersection curve cut at the other
    surface's seam) bound one island, as the whole circle does."""
    circle = _circle((0.5, 0.5), 0.2).pcurve
    upper = Cut(circle.restrict(0.0, 0.5))
    lower = Cut(circle.restrict(0.5, 1.0))
    parts = split_face(TrimmedFace(_plane()), [upper, lower])
    assert len(parts) == 2
    island = min(parts, key=_area)
    assert len(island.loops) == 1 and len(island.loops[0].edges) == 2
    np.testing.assert_allclose(_area(island), np.pi * 0.04, rtol=1e-5)
    _closed(island)


def test_a_cut_that_stops_inside_the_face_becomes_an_internal_edge():
    """Where a fin stands on a sheet the curve ends inside the sheet: it divides nothing
    and is kept as an internal edge of the region it lies in."""
    inner = _line((0.3, 0.4), (0.6, 0.5))
    parts = split_face(TrimmedFace(_plane()), [inner])
    assert len(parts) == 1
    (face,) = parts
    assert len(face.internal) == 1 and face.internal[0].pcurve is inner.pcurve
    np.testing.assert_allclose(_area(face), 1.0, atol=1e-12)
    # beside a line across the face: the internal edge goes to the half it lies in
    parts = split_face(TrimmedFace(_plane()), [_line((0.8, 0.0), (0.8, 1.0)), inner])
    assert sorted(len(p.internal) for p in parts) == [0, 1]
    holder = next(p for p in parts if p.internal)
    np.testing.assert_allclose(_area(holder), 0.8, atol=1e-12)
    # a spur (one end on the boundary, one inside) divides nothing either: an internal
    # edge, and the boundary edge it starts on is split there (they share the vertex)
    (spurred,) = split_face(TrimmedFace(_plane()), [_line((0.0, 0.5), (0.5, 0.5))])
    assert len(spurred.internal) == 1 and len(spurred.loops[0].edges) == 5
    np.testing.assert_allclose(_area(spurred), 1.0, atol=1e-12)
    # a path of two cuts joined inside the face, the second stopping inside it (a fin's
    # foot of two curves): both internal edges, the boundary split where the path starts
    first, second = _line((0.0, 0.5), (0.4, 0.5)), _line((0.4, 0.5), (0.6, 0.7))
    (path,) = split_face(TrimmedFace(_plane()), [second, first])
    assert {e.pcurve for e in path.internal} == {first.pcurve, second.pcurve}
    assert len(path.loops[0].edges) == 5
    np.testing.assert_allclose(_area(path), 1.0, atol=1e-12)
    # the same path closed by a third cut back to the boundary divides the face
    parts = split_face(TrimmedFace(_plane()), [first, second, _line((0.6, 0.7), (0.6, 1.0))])
    assert len(parts) == 2 and not any(p.internal for p in parts)


def test_cuts_along_the_boundary_divide_nothing():
    """Two faces of one model meeting another along a shared edge, or touching solids:
    their curve runs along the face's edge and is left out."""
    along = _line((0.0, 0.3), (0.0, 0.9))                     # on the side u = 0
    across = _line((0.5, 0.0), (0.5, 1.0))
    parts = split_face(TrimmedFace(_plane()), [along, across])
    assert len(parts) == 2
    np.testing.assert_allclose(sorted(_area(p) for p in parts), [0.5, 0.5], atol=1e-12)
    (whole,) = split_face(TrimmedFace(_plane()), [along])     # nothing left to cut: the face
    np.testing.assert_allclose(_area(whole), 1.0, atol=1e-12)
    _closed(whole)
    # but its side u = 0 is split where the curve ends (another solid's face touching part
    # of it then shares that piece): the side in three, 4 + 2 edges, the piece [0.3, 0.9]
    assert len(whole.loops) == 1 and len(whole.loops[0].edges) == 6
    ends = [np.array(e.uv_ends()) for e in whole.loops[0].edges]
    pieces = {tuple(np.round(np.sort(uv[:, 1]), 12)) for uv in ends if np.allclose(uv[:, 0], 0.0)}
    assert pieces == {(0.0, 0.3), (0.3, 0.9), (0.9, 1.0)}
    # a curve along a whole side, corner to corner, splits nothing
    (whole,) = split_face(TrimmedFace(_plane()), [_line((0.0, 0.0), (0.0, 1.0))])
    assert len(whole.loops[0].edges) == 4


def test_a_cut_partly_along_the_boundary_keeps_its_part_across():
    """A curve running up the side u = 0 from v = 0.2 to 0.6 and then across the face
    to u = 1 (another solid's face meeting this one at a reflex corner): the part along
    divides nothing, the part across cuts the face in two; the side is split where the
    curve joins it."""
    polyline = np.array([(0.0, 0.2), (0.0, 0.6), (1.0, 0.6)])
    pcurve = NurbsCurve(polyline, [0, 0, 0.4, 1.4, 1.4], 1)
    curve3d = NurbsCurve(np.column_stack([polyline, np.zeros(3)]), [0, 0, 0.4, 1.4, 1.4], 1)
    parts = split_face(TrimmedFace(_plane()), [Cut(pcurve, curve3d)], tol3d=1e-9)
    assert len(parts) == 2
    np.testing.assert_allclose(sorted(_area(p) for p in parts), [0.4, 0.6], atol=1e-12)
    for p in parts:
        _closed(p)
    lower = max(parts, key=_area)                       # v in [0, 0.6]: its side u = 0 in two
    ends = [np.array(e.uv_ends()) for e in lower.loops[0].edges]
    on_side = sorted(tuple(np.round(np.sort(uv[:, 1]), 9)) for uv in ends if np.allclose(uv[:, 0], 0.0))
    assert on_side == [(0.0, 0.2), (0.2, 0.6)]


def test_a_cut_leaving_a_pole_along_the_pole_edge_still_divides_the_face():
    """A triangle (the side v = 1 collapsed to its apex) cut from the apex to the base by
    a curve whose pcurve leaves the pole along the pole's edge in (u, v) -- as an
    intersection curve from a pole does (occt_k1_catia_debis.stp's face 21 at mid-height):
    the tangents there coincide, the chords a little farther tell them apart, and the face
    comes out in two, not in one with the cut run both ways."""
    apex = np.array([0.5, 1.0, 0.0])
    surface = NurbsSurface(np.array([[(0, 0, 0), apex], [(1, 0, 0), apex]], float),
                           [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)

    def side(a, b, degenerated=False):
        pcurve = NurbsCurve(np.array([a, b], float), [0, 0, 1, 1], 1)
        if degenerated:
            return TrimEdge(None, pcurve, 0.0, 1.0, degenerated=True)
        points = surface.evaluate(np.array([a[0], b[0]]), np.array([a[1], b[1]]))
        return TrimEdge(NurbsCurve(points, [0, 0, 1, 1], 1), pcurve, 0.0, 1.0)
    loop = TrimLoop((side((0, 0), (1, 0)), side((1, 0), (1, 1)), side((1, 1), (0, 1), True), side((0, 1), (0, 0))))
    pcurve = NurbsCurve(np.array([(0.9, 1.0), (0.3, 1.0), (0.3, 0.0)]), [0, 0, 0, 1, 1, 1], 2)
    parts = split_face(TrimmedFace(surface, (loop,)), [Cut(pcurve)])
    assert len(parts) == 2
    areas = sorted(_area(p) for p in parts)
    assert sum(areas) == pytest.approx(1.0, abs=1e-9) and areas[0] > 0.2
    for p in parts:
        cut_uses = [e for e in p.loops[0].edges if e.pcurve is pcurve]
        assert len(cut_uses) == 1                      # the cut bounds each region once


def test_a_cut_crossing_another_and_stopping_inside_is_refused():
    """A cut that crosses another and then stops inside the face: the stub past the
    crossing bounds nothing, and it is not pruned (only cuts crossing none are): refused
    with the point named, not a wrong region."""
    across = _line((0.5, 0.0), (0.5, 1.0))
    stub = _line((0.2, 0.5), (1.0, 0.5))
    with pytest.raises(InvalidGeometryError, match=r"a cut ends at \[0.2, 0.5\], neither on the face's boundary"):
        split_face(TrimmedFace(_plane()), [across, stub])
