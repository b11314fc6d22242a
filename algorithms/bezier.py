"""Bézier decomposition of NURBS curves and surfaces.

The Bernstein coefficients of every polynomial piece are what inserting every
interior knot up to multiplicity ``p`` would give (A5.6 and A5.7 of [PT]); they
are computed here as blossom values by one vectorized de Boor triangle over
all spans at once, in homogeneous coordinates, so rational pieces are exact.

The decomposition gives the per-patch control-net bounding boxes used to cull
pairs of patches in surface-surface intersection: with positive weights a
rational Bézier patch lies in the convex hull of its Cartesian poles.

References
----------
.. [PT] L. Piegl, W. Tiller, *The NURBS Book*, 2nd ed., Springer 1997:
   section 5.4, A5.6 (curve), A5.7 (surface).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .curve import NurbsCurve
from .surface import NurbsSurface

__all__ = [
    "bezier_decompose_array",
    "bezier_segments",
    "bezier_patches",
    "bezier_curves",
    "bezier_surfaces",
    "patch_bounding_boxes",
]


def bezier_decompose_array(points_w: NDArray, knots: NDArray, degree: int
                           ) -> tuple[NDArray, NDArray]:
    """Bézier pieces of a homogeneous control array along axis 0.

    The Bernstein coefficients of the piece on the span ``[a, b]`` are the
    blossom values ``f(a^{p-k}, b^k)``, ``k = 0..p`` (Ramshaw; section 5.4 of
    [PT]); each is a de Boor triangle on the span's ``p + 1`` poles with ``a``
    or ``b`` as the argument of each level. All spans and all ``k`` are done
    together, so the work is ``p`` vectorized steps whatever the number of
    knots (the same result as inserting every interior knot up to
    multiplicity ``p``, A5.6). The convex weights lie in ``[0, 1]``.

    Parameters
    ----------
    points_w : (n, ...) float
        Homogeneous poles along axis 0, arbitrary trailing axes.
    knots : (n + degree + 1,) float
        Clamped or not; only the domain ``[knots[degree], knots[n]]`` is decomposed.
    degree : int

    Returns
    -------
    pieces : (k, degree + 1, ...) float
        Bernstein coefficients of the ``k`` non-empty knot spans of the domain.
    intervals : (k, 2) float
        Parameter interval of each piece, in the original parameter values.
    """
    points_w = np.asarray(points_w, dtype=float)
    knots = np.asarray(knots, dtype=float)
    p, n = int(degree), points_w.shape[0]
    spans = np.flatnonzero(knots[p:n] < knots[p + 1:n + 1]) + p        # non-empty spans
    a, b = knots[spans], knots[spans + 1]
    extra = (1,) * (points_w.ndim - 1)
    k = np.arange(p + 1)
    # level r of the triangle for coefficient k uses a while r <= p - k, else b
    current = points_w[spans[:, None] - p + k][:, None]                  # (K, 1, p+1, ...)
    for r in range(1, p + 1):
        x = np.where(r <= p - k, a[:, None], b[:, None])                 # (K, p+1)
        local = np.arange(r, p + 1)
        lo = knots[spans[:, None] - p + local]                           # (K, p+1-r)
        hi = knots[spans[:, None] + 1 - r + local]
        alpha = (x[:, :, None] - lo[:, None, :]) / (hi - lo)[:, None, :]  # (K, p+1, p+1-r)
        alpha = alpha.reshape(alpha.shape + extra)
        current = (1.0 - alpha) * current[:, :, :-1] + alpha * current[:, :, 1:]
    intervals = np.stack([a, b], axis=1)
    return current[:, :, 0], intervals


def bezier_segments(curve: NurbsCurve) -> tuple[NDArray, NDArray]:
    """Bézier segments of a curve.

    Returns
    -------
    segments : (k, p + 1, d + 1) float
        Homogeneous Bernstein coefficients ``(w x, ..., w)`` of each segment.
    intervals : (k, 2) float
        Parameter interval ``[a, b]`` of each segment.
    """
    return bezier_decompose_array(curve.homogeneous_points(), curve.knots, curve.degree)


def bezier_patches(surface: NurbsSurface) -> tuple[NDArray, NDArray, NDArray]:
    """Bézier patches of a surface.

    Returns
    -------
    patches : (ku, kv, p + 1, q + 1, d + 1) float
        Homogeneous Bernstein coefficients of patch ``(i, j)``.
    intervals_u : (ku, 2) float
    intervals_v : (kv, 2) float
        Patch ``(i, j)`` covers ``intervals_u[i] x intervals_v[j]``.
    """
    pw = surface.homogeneous_points()
    seg_u, int_u = bezier_decompose_array(pw, surface.knots_u, surface.degree_u)
    # seg_u: (ku, p+1, nv, d+1); decompose v on axis 2 moved to the front
    seg_v, int_v = bezier_decompose_array(np.moveaxis(seg_u, 2, 0), surface.knots_v,
                                          surface.degree_v)
    # seg_v: (kv, q+1, ku, p+1, d+1) -> (ku, kv, p+1, q+1, d+1)
    return np.transpose(seg_v, (2, 0, 3, 1, 4)), int_u, int_v


def _bernstein_knots(a: float, b: float, degree: int) -> NDArray:
    return np.concatenate([np.full(degree + 1, a), np.full(degree + 1, b)])


def bezier_curves(curve: NurbsCurve) -> list[NurbsCurve]:
    """The Bézier segments as clamped single-span :class:`NurbsCurve` objects."""
    segments, intervals = bezier_segments(curve)
    p, rational = curve.degree, curve.weights is not None
    return [NurbsCurve.from_homogeneous(seg, _bernstein_knots(a, b, p), p, rational)
            for seg, (a, b) in zip(segments, intervals)]


def bezier_surfaces(surface: NurbsSurface) -> list[list[NurbsSurface]]:
    """The Bézier patches as single-span :class:`NurbsSurface` objects, ``[i][j]``."""
    patches, int_u, int_v = bezier_patches(surface)
    p, q = surface.degree_u, surface.degree_v
    rational = surface.weights is not None
    return [[NurbsSurface.from_homogeneous(patches[i, j], _bernstein_knots(*int_u[i], p),
                                           _bernstein_knots(*int_v[j], q), p, q, rational)
             for j in range(int_v.shape[0])]
            for i in range(int_u.shape[0])]


def patch_bounding_boxes(surface: NurbsSurface) -> tuple[NDArray, NDArray, NDArray]:
    """Control-net bounding box of every Bézier patch, in one vectorized pass.

    With positive weights each rational Bézier patch lies in the convex hull of
    its Cartesian poles, hence in this box.

    Returns
    -------
    boxes : (ku, kv, 2, d) float
        ``boxes[i, j, 0]`` the minimum corner, ``boxes[i, j, 1]`` the maximum.
    intervals_u : (ku, 2) float
    intervals_v : (kv, 2) float
    """
    patches, int_u, int_v = bezier_patches(surface)
    cartesian = patches[..., :-1] / patches[..., -1:]
    boxes = np.stack([cartesian.min(axis=(2, 3)), cartesian.max(axis=(2, 3))], axis=2)
    return boxes, int_u, int_v
