"""Sides of approximants snapped onto a kept face's edge follow it to its end: a corner
shared by two approximants is moved onto the edge's end in both (their shared side stays
one curve), so the snapped side closes in the geometry, not only up to the input gap."""

from __future__ import annotations

import numpy as np

from surfprep.algorithms.fitting import interpolate_curve, interpolate_surface
from surfprep.algorithms.healing import connect
from surfprep.algorithms.healing.adjacency import FaceEdge
from surfprep.algorithms.healing.connectivity import Side, side_points
from surfprep.algorithms.healing.snap import snap_to_originals as _snap_to_originals
from surfprep.algorithms.projection import project_to_curve


def _flat(x0, x1):
    x, y = np.linspace(x0, x1, 5), np.linspace(0.0, 1.0, 5)
    gx, gy = np.meshgrid(x, y, indexing="ij")
    return interpolate_surface(np.stack([gx, gy, 0.1 * gx * gy], axis=-1))


def test_shared_corner_pinned_to_the_kept_edge_end():
    net = connect([_flat(0.0, 1.0), _flat(1.0, 2.0)], continuity="G0", gap_tol=1e-2)
    assert len(net.edges) == 1
    # the kept face below the left patch ends 3e-3 off the shared corner (1, 0, 0)
    s = np.linspace(0.0, 1.0, 9)
    pts = np.stack([s, 3e-3 * s ** 2, np.zeros_like(s)], axis=1)
    edge = interpolate_curve(pts)
    samples = edge.evaluate(np.linspace(*edge.domain, 65))
    snapped, count = _snap_to_originals(net, [FaceEdge(7, 0, edge, samples)], 1e-2, 1e-9)
    assert count == 1
    left, right = snapped.patches
    side = side_points(left, Side.V0, 201)
    assert project_to_curve(edge, side).distance.max() < 1e-8
    assert np.linalg.norm(right.control_points[0, 0] - [1.0, 3e-3, 0.0]) < 1e-12
    (join,) = snapped.joins
    assert join.max_gap < 1e-12


def test_side_meeting_two_edges_of_a_kept_face_follows_both():
    # a T-junction: the kept face below the left patch has two edges along its bottom side
    # (one smooth curve 2e-3 off the side, split at x = 0.4)
    net = connect([_flat(0.0, 1.0), _flat(1.0, 2.0)], continuity="G0", gap_tol=1e-2)
    whole = interpolate_curve(np.stack([np.linspace(0, 1, 17), 2e-3 * np.sin(
        np.pi * np.linspace(0, 1, 17)), np.zeros(17)], axis=1))
    split = float(project_to_curve(whole, np.array([[0.4, 0.0, 0.0]])).t[0])
    t0, t1 = whole.domain
    first, second = whole.restrict(t0, split), whole.restrict(split, t1)
    edges = [FaceEdge(7, k, c, c.evaluate(np.linspace(*c.domain, 65)))
             for k, c in enumerate((first, second))]
    snapped, count = _snap_to_originals(net, edges, 1e-2, 1e-9)
    assert count == 1
    side = side_points(snapped.patches[0], Side.V0, 401)
    gap = np.min([project_to_curve(c, side).distance for c in (first, second)], axis=0)
    assert gap.max() < 1e-6                           # was 2e-3 (not snapped at all)
    assert snapped.joins[0].max_gap < 1e-12
