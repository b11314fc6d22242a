"""curve_gap (trace.py): the distance from points to intersection curves, measured on
their 3D interpolants, against the exact circle of a sphere cut by a plane; the
Newton shortcut (``within``) never measures more than the dense sampling, nor less
than the true gap (up to the interpolant's own error, about tol)."""

from __future__ import annotations

import numpy as np
from helpers.surfaces import DIAGONAL, sphere_and_plane

from surfprep.algorithms.characteristic import characteristic_intersection
from surfprep.algorithms.characteristic.trace import curve_gap


def test_gap_to_a_traced_circle_is_exact_and_the_newton_shortcut_agrees():
    a, b, centre, radius = sphere_and_plane(0.2)
    record = characteristic_intersection(a, b, tol=1e-9)
    assert len(record.curves) == 1
    # the circle: centre + radius (cos x e1 + sin x e2) in the plane normal to DIAGONAL
    n = DIAGONAL / np.linalg.norm(DIAGONAL)
    e1 = np.array([0.0, 0.0, 1.0])
    e2 = np.cross(n, e1)
    rng = np.random.default_rng(3)
    angle = rng.uniform(0, 2 * np.pi, 60)
    offset = np.concatenate([np.zeros(20), 10.0 ** rng.uniform(-8, -3, 40)])
    radial = np.cos(angle)[:, None] * e1 + np.sin(angle)[:, None] * e2
    pts = centre + (radius + offset)[:, None] * radial               # in the plane: gap = offset
    exact = offset
    dense = curve_gap(pts, list(record.curves))
    slack = 1e-8                                      # the interpolant is within tol, chords sag
    assert np.abs(dense - exact).max() <= slack
    for within in (1e-8, 1e-6, 1e-4):
        quick = curve_gap(pts, list(record.curves), within=within)
        assert np.all(quick <= dense + 1e-15)         # a covered start stays covered
        assert np.all(quick >= exact - slack)         # never below the true gap
        np.testing.assert_array_equal(quick[exact > within + slack] <= within, False)
        np.testing.assert_array_equal(quick[exact < within - slack] <= within, True)
