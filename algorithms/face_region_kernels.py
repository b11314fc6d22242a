"""Compiled even-odd ray test of parameter points against bucketed loop segments.

Trimming loops of a face, sampled into polygon segments in ``(u, v)``, are
bucketed by their v-range (``indptr``/``seg_sorted``: the segments of bucket
``k`` are ``seg_sorted[indptr[k]:indptr[k + 1]]``). A point is inside the
loops when a ray from it in +u crosses an odd number of segments (outer loop
and holes at once); only the segments of the point's bucket can cross its ray.

:func:`ray_crossings_numpy` is the reference form (gathers every candidate
pair into arrays); :func:`ray_crossings` runs the same test point by point in
one compiled call, so a classification of a few points costs microseconds
instead of the hundreds that the numpy form's temporaries cost (the clipping
of intersection curves to trimmed faces classifies a few points per crossing
many times over).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .jit import AVAILABLE, jit

__all__ = ["ray_crossings", "ray_crossings_numpy"]


@jit
def _ray_crossings_kernel(uv, a, b, lo, hi, width, bins, seg_sorted,  # pragma: no cover - compiled
                          indptr, out):
    for i in range(uv.shape[0]):
        pu, pv = uv[i, 0], uv[i, 1]
        count = 0
        if pv >= lo and pv <= hi:
            k = int((pv - lo) / width)
            k = min(max(k, 0), bins - 1)
            for j in range(indptr[k], indptr[k + 1]):
                s = seg_sorted[j]
                av, bv = a[s, 1], b[s, 1]
                if (av > pv) != (bv > pv):
                    dv = bv - av if bv != av else 1.0
                    u_cross = a[s, 0] + (pv - av) * (b[s, 0] - a[s, 0]) / dv
                    if u_cross > pu:
                        count += 1
        out[i] = count


def ray_crossings_numpy(uv: NDArray, a: NDArray, b: NDArray, lo: float, hi: float, width: float,
                        bins: int, seg_sorted: NDArray, indptr: NDArray) -> NDArray:
    """Crossings ``(n,) int`` of a ray in +u from each ``uv (n, 2)`` with the segments
    ``a -> b`` (``(m, 2)`` each) of its v-bucket (module docstring)."""
    pbin = np.clip(((uv[:, 1] - lo) / width).astype(np.int64), 0, bins - 1)
    inside_range = (uv[:, 1] >= lo) & (uv[:, 1] <= hi)
    per_point = np.where(inside_range, indptr[pbin + 1] - indptr[pbin], 0)
    point_of = np.repeat(np.arange(uv.shape[0]), per_point)
    offs = np.arange(per_point.sum()) - np.repeat(np.cumsum(per_point) - per_point, per_point)
    cand = seg_sorted[indptr[pbin[point_of]] + offs]
    pa, pb, p = a[cand], b[cand], uv[point_of]
    straddle = (pa[:, 1] > p[:, 1]) != (pb[:, 1] > p[:, 1])
    dv = np.where(pb[:, 1] != pa[:, 1], pb[:, 1] - pa[:, 1], 1.0)
    u_cross = pa[:, 0] + (p[:, 1] - pa[:, 1]) * (pb[:, 0] - pa[:, 0]) / dv
    hit = straddle & (u_cross > p[:, 0])
    return np.bincount(point_of[hit], minlength=uv.shape[0])


def ray_crossings(uv: NDArray, a: NDArray, b: NDArray, lo: float, hi: float, width: float,
                  bins: int, seg_sorted: NDArray, indptr: NDArray) -> NDArray:
    """:func:`ray_crossings_numpy`, compiled (the numpy form without numba)."""
    if not AVAILABLE:                   # pragma: no cover - numba is installed in CI
        return ray_crossings_numpy(uv, a, b, lo, hi, width, bins, seg_sorted, indptr)
    out = np.zeros(uv.shape[0], dtype=np.int64)
    _ray_crossings_kernel(np.ascontiguousarray(uv, dtype=float), a, b, float(lo), float(hi),
                          float(width), int(bins), seg_sorted, indptr, out)
    return out
