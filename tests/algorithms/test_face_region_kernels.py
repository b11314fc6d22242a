"""The compiled even-odd ray test against its numpy form and a brute-force count."""

from __future__ import annotations

import numpy as np
import pytest

from surfprep.algorithms import face_region_kernels
from surfprep.algorithms.face_region import LoopIndex
from surfprep.algorithms.face_region_kernels import ray_crossings, ray_crossings_numpy


def test_numba_is_available():
    """numba is a declared dependency: the compiled form must be the one that runs."""
    assert face_region_kernels.AVAILABLE


def _star_with_hole(n: int = 200) -> np.ndarray:
    """Segments (m, 2, 2) of a wavy star (outer loop) and a circular hole."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    outer = np.column_stack([(1 + 0.3 * np.sin(7 * t)) * np.cos(t),
                             (1 + 0.3 * np.sin(7 * t)) * np.sin(t)])
    hole = 0.25 * np.column_stack([np.cos(-t), np.sin(-t)]) + [0.1, -0.05]
    loops = [outer, hole]
    return np.concatenate([np.stack([q, np.roll(q, -1, axis=0)], axis=1) for q in loops])


def _brute_force(uv: np.ndarray, seg: np.ndarray) -> np.ndarray:
    a, b = seg[:, 0], seg[:, 1]
    count = np.zeros(uv.shape[0], dtype=np.int64)
    for (pu, pv), k in zip(uv, range(uv.shape[0])):
        for (au, av), (bu, bv) in zip(a, b):
            if (av > pv) != (bv > pv):
                if au + (pv - av) * (bu - au) / (bv - av) > pu:
                    count[k] += 1
    return count


@pytest.mark.parametrize("n_points", [1, 7, 500])
def test_compiled_equals_numpy_and_brute_force(n_points):
    seg = _star_with_hole()
    index = LoopIndex.build(seg)
    rng = np.random.default_rng(n_points)
    uv = rng.uniform(-1.5, 1.5, (n_points, 2))
    uv[0] = [0.1, -0.05]                                   # the hole's centre: outside
    args = (index.a, index.b, index.lo, index.hi, index.width, index.bins, index.seg_sorted,
            index.indptr)
    compiled, reference = ray_crossings(uv, *args), ray_crossings_numpy(uv, *args)
    np.testing.assert_array_equal(compiled, reference)
    np.testing.assert_array_equal(compiled, _brute_force(uv, seg))
    assert compiled[0] % 2 == 0
    # the points the loop encloses: inside the star, outside the hole
    inside = compiled % 2 == 1
    r = np.hypot(uv[:, 0], uv[:, 1])
    assert not np.any(inside & (r > 1.3)) and not np.any(
        inside & (np.hypot(uv[:, 0] - 0.1, uv[:, 1] + 0.05) < 0.24))


def test_points_beyond_the_buckets_cross_nothing():
    index = LoopIndex.build(_star_with_hole())
    uv = np.array([[0.0, 5.0], [0.0, -5.0], [-5.0, 0.0]])
    got = ray_crossings(uv, index.a, index.b, index.lo, index.hi, index.width, index.bins,
                        index.seg_sorted, index.indptr)
    np.testing.assert_array_equal(got, [0, 0, 4])
