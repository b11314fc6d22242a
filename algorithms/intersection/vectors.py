"""Small vector helpers on ``(..., 3)`` arrays, without the per-call overhead of
``np.cross`` (which moves axes and checks shapes on every call; the refinement and
sampling loops call it thousands of times on a few hundred vectors), and reductions
over a short middle axis (numpy's ``min(axis=1)`` on ``(m, 3, 3)`` triangles runs
about four times slower than two elementwise minimums)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["corner_max", "corner_min", "cross", "dot", "entry_max", "norm"]


def cross(a: NDArray, b: NDArray) -> NDArray:
    """``a x b`` for ``(..., 3)`` arrays (broadcast), as ``np.cross`` gives it."""
    if a.shape != b.shape:
        a, b = np.broadcast_arrays(a, b)
    out = np.empty(a.shape)
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def dot(a: NDArray, b: NDArray) -> NDArray:
    """Row-wise dot products ``(...)`` of ``(..., k)`` arrays."""
    return np.einsum("...i,...i->...", a, b)


def norm(a: NDArray) -> NDArray:
    """Row-wise Euclidean norms ``(...)`` of ``(..., k)`` arrays."""
    return np.sqrt(np.einsum("...i,...i->...", a, a))


def _fold(ufunc, flat: NDArray) -> NDArray:
    """``ufunc`` folded over axis 1 of ``flat (m, k, ...)``: k - 1 elementwise calls."""
    out = flat[:, 0].copy()
    for k in range(1, flat.shape[1]):
        ufunc(out, flat[:, k], out=out)
    return out


def _middle(a: NDArray) -> NDArray:
    return a.reshape(a.shape[0], int(np.prod(a.shape[1:-1])), a.shape[-1])


def corner_min(a: NDArray) -> NDArray:
    """``(m, d)``: the minimum over all middle axes of ``a (m, ..., d)`` (at least one
    entry), e.g. the lower corner of the box of every triangle ``(m, 3, 3)``."""
    return _fold(np.minimum, _middle(a))


def corner_max(a: NDArray) -> NDArray:
    """``(m, d)``: the maximum over all middle axes of ``a (m, ..., d)``."""
    return _fold(np.maximum, _middle(a))


def entry_max(a: NDArray) -> NDArray:
    """``(m,)``: the largest entry of every row of ``a (m, ...)``."""
    return _fold(np.maximum, a.reshape(a.shape[0], -1) if a.shape[0] else a.reshape(0, 1))
