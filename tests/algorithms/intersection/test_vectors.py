"""vectors.py: the elementwise forms equal numpy's reductions and products exactly."""

import numpy as np
import pytest

from surfprep.algorithms.intersection import vectors


@pytest.mark.parametrize("shape", [(7, 3, 3), (5, 4, 4, 3), (1, 1, 2), (0, 3, 3)])
def test_corner_reductions_equal_numpy(shape):
    a = np.random.default_rng(0).normal(size=shape)
    axes = tuple(range(1, len(shape) - 1))
    np.testing.assert_array_equal(vectors.corner_min(a), a.min(axis=axes, initial=np.inf))
    np.testing.assert_array_equal(vectors.corner_max(a), a.max(axis=axes, initial=-np.inf))
    rows = a.reshape(shape[0], int(np.prod(shape[1:])))
    np.testing.assert_array_equal(vectors.entry_max(a), rows.max(axis=1, initial=-np.inf))


def test_nan_propagates_like_numpy():
    a = np.random.default_rng(1).normal(size=(4, 3, 3))
    a[2, 1, 0] = np.nan
    np.testing.assert_array_equal(vectors.corner_min(a), a.min(axis=1))
    np.testing.assert_array_equal(vectors.entry_max(a), a.reshape(4, -1).max(axis=1))


def test_cross_equals_numpy():
    rng = np.random.default_rng(2)
    a, b = rng.normal(size=(6, 3)), rng.normal(size=(6, 3))
    np.testing.assert_allclose(vectors.cross(a, b), np.cross(a, b), rtol=0, atol=1e-15)
    np.testing.assert_allclose(vectors.cross(a, b[:1]), np.cross(a, b[:1]), rtol=0, atol=1e-15)
