"""The compiled Möller-Trumbore of the projection (healing/piercing_kernels.py) against
its numpy form and against exact hits."""

from __future__ import annotations

import numpy as np

from surfprep.algorithms.healing import piercing_kernels
from surfprep.algorithms.healing.piercing import intersect_segments, moller_trumbore


def test_compiled_kernel_is_available():
    assert piercing_kernels.AVAILABLE


def test_compiled_pairs_agree_with_numpy_form():
    rng = np.random.default_rng(7)
    a, b = rng.normal(size=(300, 3)), rng.normal(size=(300, 3))
    tri = rng.normal(size=(200, 3, 3))
    tri[0, 2] = tri[0, 0] + 2.0 * (tri[0, 1] - tri[0, 0])              # a sliver: no hit
    b[0] = a[0] + (tri[1, 1] - tri[1, 0])                              # parallel to triangle 1
    seg = rng.integers(0, 300, 5000)
    which = rng.integers(0, 200, 5000)
    seg[:2], which[:2] = 0, [0, 1]
    t, w1, w2, ok = piercing_kernels.hits_on_pairs(a, b, tri, seg, which, 1e-9)
    t_np, w1_np, w2_np, ok_np = moller_trumbore(a[seg], b[seg] - a[seg], tri[which])
    np.testing.assert_array_equal(ok, ok_np)
    assert ok.sum() > 50                                               # the test sees hits
    for got, want in ((t, t_np), (w1, w1_np), (w2, w2_np)):
        np.testing.assert_allclose(got[ok], want[ok], rtol=1e-12, atol=1e-12)
    assert not ok[0] and not ok[1]


def test_segments_through_a_triangle_hit_where_they_should():
    """Vertical segments through the triangle (0,0,0), (1,0,0), (0,1,0): the hit is at
    the segment's crossing of z = 0, the weights are the point's (x, y); segments
    outside miss; a segment along an edge is kept (edge slack)."""
    tri = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    xy = np.array([[0.2, 0.3], [0.5, 0.5], [0.0, 0.4], [0.7, 0.6], [-0.1, 0.2]])
    a = np.column_stack([xy, np.full(5, -0.25)])
    b = np.column_stack([xy, np.full(5, 0.75)])
    hits = intersect_segments(a, b, tri)
    np.testing.assert_array_equal(hits.found, [True, True, True, False, False])
    np.testing.assert_allclose(hits.t[:3], 0.25, atol=1e-15)
    np.testing.assert_allclose(hits.barycentric[:3, 1:], xy[:3], atol=1e-15)
