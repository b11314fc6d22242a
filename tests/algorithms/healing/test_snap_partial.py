"""Sides of approximants meeting only PART of a kept face's edge are fitted to that part:
the edge is restricted between the projections of the side's ends (a sub-patch side of a
split face beside a neighbour whose edge is twice as long; a quarter of a closed circular
edge across its seam). Gaps measured on the geometry: the side sampled densely, closest
points on the kept edge."""

from __future__ import annotations

import numpy as np

from surfprep.algorithms.fitting import interpolate_curve, interpolate_surface
from surfprep.algorithms.healing import connect
from surfprep.algorithms.healing.adjacency import FaceEdge
from surfprep.algorithms.healing.connectivity import Side, side_points
from surfprep.algorithms.healing.snap import snap_to_originals
from surfprep.algorithms.projection import project_to_curve


def _edge(curve, face=7, k=0):
    return FaceEdge(face, k, curve, curve.evaluate(np.linspace(*curve.domain, 17)))


def _flat(x0, x1):
    x, y = np.linspace(x0, x1, 5), np.linspace(0.0, 1.0, 5)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return interpolate_surface(np.stack([gx, gy, 0.1 * gy * np.sin(gx)], axis=-1))


def test_two_sub_patch_sides_each_fitted_to_half_of_a_kept_edge():
    # two sub-patches (of a split face) side by side over x in [0, 2]; the kept face
    # below has ONE edge along both bottom sides, 2e-3 off them
    net = connect([_flat(0.0, 1.0), _flat(1.0, 2.0)], continuity="G0", gap_tol=1e-2)
    assert len(net.edges) == 1
    x = np.linspace(0.0, 2.0, 33)
    edge = interpolate_curve(np.stack([x, 2e-3 * np.sin(np.pi * x / 2) - 1e-3 * x,
                                       np.zeros_like(x)], axis=1))
    before = [project_to_curve(edge, side_points(p, Side.V0, 401)).distance.max()
              for p in net.patches]
    assert min(before) > 1e-3
    snapped, count = snap_to_originals(net, [_edge(edge)], 1e-2, 1e-9)
    assert count == 2
    for p in snapped.patches:
        gap = project_to_curve(edge, side_points(p, Side.V0, 401)).distance
        assert gap.max() < 1e-7
    # the split point moved onto the edge in both sub-patches: their join stays closed
    assert snapped.joins[0].max_gap < 1e-12


def test_quarter_of_a_closed_circle_across_its_seam():
    # a kept disc's boundary: a closed circle starting at angle 0; the patch's side is
    # the quarter from -45 to 45 degrees, 1e-3 inside
    angle = np.linspace(0.0, 2 * np.pi, 65)
    circle = interpolate_curve(np.stack([np.cos(angle), np.sin(angle), 0 * angle], axis=1))
    a = np.linspace(-np.pi / 4, np.pi / 4, 9)
    r = np.linspace(0.999, 1.5, 5)
    grid = np.stack([np.outer(np.cos(a), r), np.outer(np.sin(a), r),
                     np.outer(0 * a, r)], axis=-1)                     # (9, 5, 3) u along arc
    patch = interpolate_surface(grid)
    net = connect([patch], continuity="G0", gap_tol=1e-2)
    before = project_to_curve(circle, side_points(patch, Side.V0, 401)).distance.max()
    assert before > 5e-4
    snapped, count = snap_to_originals(net, [_edge(circle)], 1e-2, 1e-9)
    assert count == 1
    side = side_points(snapped.patches[0], Side.V0, 401)
    gap = project_to_curve(circle, side).distance
    # the interpolated circle is not periodic: it has a slight kink at its seam (angle 0,
    # the middle of the side), which the fitted cubic row rounds off by < 1e-6
    assert gap.max() < 1e-6 and abs(int(np.argmax(gap)) - 200) < 20
    # the side covers the quarter, not more: its ends stay at -45 / 45 degrees
    ends = np.degrees(np.arctan2(side[[0, -1], 1], side[[0, -1], 0]))
    assert np.allclose(sorted(ends), [-45.0, 45.0], atol=0.1)


def test_edge_touching_only_a_corner_is_no_target():
    net = connect([_flat(0.0, 1.0)], continuity="G0", gap_tol=1e-2)
    # an edge leaving the corner (1, 0) downwards meets the bottom side at one point only
    y = np.linspace(0.0, -1.0, 9)
    edge = interpolate_curve(np.stack([np.ones_like(y), y, 0 * y], axis=1))
    _, count = snap_to_originals(net, [_edge(edge)], 1e-2, 1e-9)
    assert count == 0


def _sheet(x0, x1, y0, y1, bump=0.0):
    x, y = np.linspace(x0, x1, 5), np.linspace(y0, y1, 5)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return interpolate_surface(np.stack([gx, gy, 0.1 * gy * np.sin(gx) + bump * np.sin(
        np.pi * gx / 2)], axis=-1))


def test_t_junction_between_approximants_closed_on_the_longer_side():
    # two sub-patches (x in [0, 1] and [1, 2]) above ONE approximant whose top side runs
    # along both bottom sides, 2e-3 off them: connect joins whole sides only
    below = _sheet(0.0, 2.0, -1.0, 0.0, bump=2e-3)
    net = connect([_sheet(0.0, 1.0, 0.0, 1.0), _sheet(1.0, 2.0, 0.0, 1.0), below],
                  continuity="G0", gap_tol=1e-2, strict=False)    # as heal calls it
    assert len(net.edges) == 1                     # only the two sub-patches' shared side
    below = net.patches[2]
    top = below.isocurve(below.domain[3], Side.V1.fixed)
    before = [project_to_curve(top, side_points(p, Side.V0, 401)).distance.max()
              for p in net.patches[:2]]
    assert min(before) > 1e-3
    snapped, count = snap_to_originals(net, [], 1e-2, 1e-9)
    assert count == 2
    for p in snapped.patches[:2]:
        assert project_to_curve(top, side_points(p, Side.V0, 401)).distance.max() < 1e-7
    assert np.array_equal(snapped.patches[2].control_points, below.control_points)
    assert snapped.joins[0].max_gap < 1e-12


def test_side_partly_along_a_kept_edge_fitted_there_only():
    # the kept edge meets the right half (x in [1, 2]) of the patch's bottom side, 2e-3
    # off it; the left half meets nothing and stays where it was
    net = connect([_sheet(0.0, 2.0, 0.0, 1.0)], continuity="G0", gap_tol=1e-2)
    x = np.linspace(1.0, 2.0, 17)
    edge = interpolate_curve(np.stack([x, 2e-3 * np.sin(np.pi * (x - 1)) - 1e-3 * (x - 1),
                                       np.zeros_like(x)], axis=1))
    snapped, count = snap_to_originals(net, [_edge(edge)], 1e-2, 1e-9)
    assert count == 1
    old, new = side_points(net.patches[0], Side.V0, 801), side_points(snapped.patches[0],
                                                                       Side.V0, 801)
    right = old[:, 0] >= 1.0 + 1e-3
    assert project_to_curve(edge, new[right]).distance.max() < 1e-7
    # the free half moves only next to the junction (the edge leaves at a slight angle)
    near, far = (old[:, 0] < 1.0) & (old[:, 0] > 0.8), old[:, 0] <= 0.8
    assert np.abs(new[far] - old[far]).max() < 1e-5
    assert np.abs(new[near] - old[near]).max() < 1e-4
    assert np.allclose(new[0], old[0], atol=1e-12)      # the free far corner stays
