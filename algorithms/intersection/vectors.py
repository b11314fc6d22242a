"""Small vector helpers on ``(..., 3)`` arrays, without the per-call overhead of
``np.cross`` (which moves axes and checks shapes on every call; the refinement and
sampling loops call it thousands of times on a few hundred vectors)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["cross", "dot", "norm"]


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
