"""Exact test surfaces for the SSI tests, written with numpy only (no OCP)."""

from __future__ import annotations

import numpy as np

from surfprep.algorithms import NurbsSurface

R2 = np.sqrt(0.5)


def sphere_band(r: float = 1.0, centre=(0, 0, 0)) -> NurbsSurface:
    """Rational biquadratic sphere zone between latitudes -45 and 45 degrees, 4 x 1
    patches, radius ``r`` around ``centre`` (exact: every point is at distance r)."""
    circ = np.array([[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1],
                     [1, 0]], float)
    wc = np.array([1, R2, 1, R2, 1, R2, 1, R2, 1])
    mer = np.array([[R2, -R2], [2 * R2, 0.0], [R2, R2]])
    cp = np.empty((9, 3, 3))
    cp[..., 0] = circ[:, None, 0] * mer[None, :, 0]
    cp[..., 1] = circ[:, None, 1] * mer[None, :, 0]
    cp[..., 2] = mer[None, :, 1]
    ku = [0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1]
    return NurbsSurface(cp * r + np.asarray(centre, float), ku, [0, 0, 0, 1, 1, 1], 2, 2,
                        wc[:, None] * np.array([1, R2, 1])[None, :])
