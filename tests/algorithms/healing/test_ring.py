"""The ring of projections beyond a Coons grid's boundary (healing.ring)."""

from __future__ import annotations

import numpy as np
from helpers.heal_cases import iso_boundary, smooth_surface

from surfprep.algorithms.healing.boundary import as_boundary
from surfprep.algorithms.healing.coons import discrete_coons
from surfprep.algorithms.healing.ring import extend_grid, ring_segments
from surfprep.algorithms.projection import distance_to_surface


def test_extension_continues_quadratics_exactly():
    s = np.linspace(0.0, 1.0, 9)
    x, y = np.meshgrid(s, np.linspace(0.0, 2.0, 7), indexing="ij")
    ext_x, ext_y = extend_grid(x, 3), extend_grid(y, 3)
    assert ext_x.shape == (15, 13)
    np.testing.assert_allclose(ext_x[:, 0], np.linspace(-0.375, 1.375, 15), atol=1e-14)
    q = 1 + x - 2 * y + x * x - 0.5 * x * y + 3 * y * y
    eq = 1 + ext_x - 2 * ext_y + ext_x ** 2 - 0.5 * ext_x * ext_y + 3 * ext_y ** 2
    np.testing.assert_allclose(extend_grid(q, 3), eq, atol=1e-12)
    np.testing.assert_array_equal(extend_grid(q, 3)[3:-3, 3:-3], q)


def test_ring_segments_straddle_the_continued_surface():
    smooth = smooth_surface()
    coons = discrete_coons(as_boundary(iso_boundary(smooth, 0.3, 0.6, 0.3, 0.6)), 8, 8)
    ring = ring_segments(coons, 0.05, 2)
    assert ring.outer.shape == (13, 13) and ring.outer.sum() == 13 * 13 - 81
    mid = 0.5 * (ring.upper + ring.lower)
    np.testing.assert_allclose(np.linalg.norm(ring.upper - ring.lower, axis=1), 0.1)
    # the ring's midpoints lie outside the hole's square, near the surface around it
    uv = mid[:, :2]
    assert np.all((uv < 0.3 - 1e-9).any(axis=1) | (uv > 0.6 + 1e-9).any(axis=1))
    assert distance_to_surface(smooth, mid).max() < 2e-3
