"""The compiled nearest-candidate-triangle kernel against its numpy form."""

from __future__ import annotations

import numpy as np

from surfprep.algorithms.healing import error_kernels
from surfprep.algorithms.healing.error import _nearest_numpy


def test_numba_is_available():
    assert error_kernels.AVAILABLE


def test_compiled_equals_numpy_on_random_and_degenerate_triangles():
    rng = np.random.default_rng(7)
    tri = rng.normal(size=(60, 3, 3))
    tri[5] = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]                 # collinear: a sliver
    tri[6] = [[1, 1, 1], [1, 1, 1], [1, 1, 1]]                 # a point
    points = rng.normal(scale=1.5, size=(500, 3))
    cand = rng.integers(0, 60, size=(500, 12))
    cand[:, 0] = 5
    cand[:, 1] = 6
    d, pick, bary = error_kernels.nearest_on_candidates(points, tri, cand)
    d_ref, pick_ref, bary_ref = _nearest_numpy(points, tri, cand)
    np.testing.assert_allclose(d, d_ref, rtol=1e-12, atol=1e-14)
    np.testing.assert_array_equal(pick, pick_ref)
    np.testing.assert_allclose(bary, bary_ref, atol=1e-12)
    foot = np.einsum("nc,ncd->nd", bary, tri[cand[np.arange(500), pick]])
    np.testing.assert_allclose(np.linalg.norm(points - foot, axis=1), d, rtol=1e-12)
