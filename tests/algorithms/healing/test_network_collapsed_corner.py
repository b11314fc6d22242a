"""A three-sided patch (one side collapsed to a point, as napa's heal produced) joins its
neighbour: the collapsed side shares nothing (it touched both other sides of its own patch,
which then counted as bifurcations), the default gap_tol is not shrunk to zero by its zero
length, and the join is measured (normals where they exist)."""

from __future__ import annotations

import numpy as np

from surfprep.algorithms.fitting import interpolate_surface
from surfprep.algorithms.healing import connect


def test_join_with_a_collapsed_corner_is_measured():
    s = np.linspace(0, 1, 6)
    gu, gv = np.meshgrid(s, s, indexing="ij")
    # patch a: a triangle (0,0), (1,0), (0,1): its side v = 1 collapses to the point (0, 1),
    # so Su x Sv vanishes at the end of the shared side u = 0
    a = np.stack([gu * (1 - gv), gv, 0.1 * gu * gv * (1 - gv)], axis=-1)
    b = np.stack([-gu[::-1], gv, 0 * gu], axis=-1)          # x in [-1, 0], shares u = 0 of a
    net = connect([interpolate_surface(a), interpolate_surface(b)], continuity="G0", strict=False)
    assert len(net.joins) == 1
    join = net.joins[0]
    assert join.max_gap < 1e-12 and np.isfinite(join.max_angle)
