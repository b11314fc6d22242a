"""Compiled closest points on candidate triangles (the hot loop of the error of 001 §7).

:func:`nearest_on_candidates` gives, for every point, the nearest of its
candidate triangles and the barycentric weights of the foot: the same
arithmetic as :func:`.error.closest_on_triangles` (interior by the normal
equations when the triangle is not a sliver, else the nearest of its three
edges), point by point in one compiled call instead of over ``points x
candidates`` temporary arrays. The numpy form stays as the reference (tests
compare the two).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..jit import AVAILABLE, jit

__all__ = ["AVAILABLE", "nearest_on_candidates"]


@jit
def _edge_foot(px, py, pz, ax, ay, az, bx, by, bz):  # pragma: no cover - compiled
    abx, aby, abz = bx - ax, by - ay, bz - az
    den = abx * abx + aby * aby + abz * abz
    s = ((px - ax) * abx + (py - ay) * aby + (pz - az) * abz) / max(den, 2.2250738585072014e-308)
    s = min(max(s, 0.0), 1.0)
    dx, dy, dz = px - (ax + s * abx), py - (ay + s * aby), pz - (az + s * abz)
    return np.sqrt(dx * dx + dy * dy + dz * dz), s


@jit
def _nearest_kernel(points, tri, cand, dist_out, pick_out, bary_out):  # pragma: no cover
    for i in range(points.shape[0]):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        best = np.inf
        for c in range(cand.shape[1]):
            t = cand[i, c]
            p0x, p0y, p0z = tri[t, 0, 0], tri[t, 0, 1], tri[t, 0, 2]
            e1x, e1y, e1z = tri[t, 1, 0] - p0x, tri[t, 1, 1] - p0y, tri[t, 1, 2] - p0z
            e2x, e2y, e2z = tri[t, 2, 0] - p0x, tri[t, 2, 1] - p0y, tri[t, 2, 2] - p0z
            g11 = e1x * e1x + e1y * e1y + e1z * e1z
            g12 = e1x * e2x + e1y * e2y + e1z * e2z
            g22 = e2x * e2x + e2y * e2y + e2z * e2z
            qx, qy, qz = px - p0x, py - p0y, pz - p0z
            r1 = qx * e1x + qy * e1y + qz * e1z
            r2 = qx * e2x + qy * e2y + qz * e2z
            det = g11 * g22 - g12 * g12
            done = False
            if det > 1e-14 * g11 * g22:
                s_ = (g22 * r1 - g12 * r2) / det
                t_ = (g11 * r2 - g12 * r1) / det
                w0 = 1.0 - s_ - t_
                if w0 >= 0.0 and s_ >= 0.0 and t_ >= 0.0:
                    fx = w0 * p0x + s_ * tri[t, 1, 0] + t_ * tri[t, 2, 0]
                    fy = w0 * p0y + s_ * tri[t, 1, 1] + t_ * tri[t, 2, 1]
                    fz = w0 * p0z + s_ * tri[t, 1, 2] + t_ * tri[t, 2, 2]
                    d = np.sqrt((px - fx) ** 2 + (py - fy) ** 2 + (pz - fz) ** 2)
                    done = True
                    if d < best:
                        best = d
                        pick_out[i] = c
                        bary_out[i, 0], bary_out[i, 1], bary_out[i, 2] = w0, s_, t_
            if not done:
                for k in range(3):
                    j = (k + 1) % 3
                    d, s = _edge_foot(px, py, pz, tri[t, k, 0], tri[t, k, 1], tri[t, k, 2],
                                      tri[t, j, 0], tri[t, j, 1], tri[t, j, 2])
                    if d < best:
                        best = d
                        pick_out[i] = c
                        bary_out[i, 0] = bary_out[i, 1] = bary_out[i, 2] = 0.0
                        bary_out[i, k] = 1.0 - s
                        bary_out[i, j] = s
        dist_out[i] = best


def nearest_on_candidates(points: NDArray, tri: NDArray, cand: NDArray
                          ) -> tuple[NDArray, NDArray, NDArray]:
    """Nearest of each point's candidate triangles.

    Parameters
    ----------
    points : (n, 3) float
    tri : (t, 3, 3) float
        Triangle corners.
    cand : (n, k) int
        Candidate triangles of each point.

    Returns
    -------
    distance : (n,) float
    pick : (n,) int
        Column of ``cand`` of the nearest.
    barycentric : (n, 3) float
        Of the foot in that triangle.
    """
    n = points.shape[0]
    dist, pick, bary = np.full(n, np.inf), np.zeros(n, np.int64), np.zeros((n, 3))
    _nearest_kernel(np.ascontiguousarray(points, dtype=float),
                    np.ascontiguousarray(tri, dtype=float),
                    np.ascontiguousarray(cand, dtype=np.int64), dist, pick, bary)
    return dist, pick, bary
