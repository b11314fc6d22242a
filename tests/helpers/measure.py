"""Measuring SSI answers densely, shared by the test_ssi_* evidence files of tests/plugin.

Our curves carry few samples (only as many as their cubic interpolants need),
so polylines through the samples, or even through a few interpolant points
per span, sag by more than the tolerances checked. Distances to OUR curves are
therefore taken to the interpolants themselves: the nearest of a dense set of
interpolant points seeds a local closest-point projection
(:func:`surfprep.algorithms.projection.project_to_curve` with ``guess``), which
costs memory linear in the points.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from surfprep.algorithms.projection import project_to_curve

#: interpolant points per span that seed the projection
SEED_PER_SPAN = 16


def span_points(curve, per_span: int) -> tuple[np.ndarray, np.ndarray]:
    """Parameters ``(m,)`` and points ``(m, 3)`` of ``curve.curve3d``: ``per_span``
    equally spaced per span of the samples, and the last parameter."""
    t = curve.parameters
    s = np.arange(per_span) / per_span
    params = np.append((t[:-1, None] + s * np.diff(t)[:, None]).ravel(), t[-1])
    return params, curve.curve3d.evaluate(params)


def dense(curves, per_span: int = 4) -> list[np.ndarray]:
    """Our curves as ``(m, 3)`` polylines through their interpolants."""
    return [span_points(c, per_span)[1] for c in curves]


def distance_to_curves(curves, points: np.ndarray, tol: float) -> np.ndarray:
    """Distance ``(n,)`` of each point to the nearest of our curves' interpolants.

    ``tol`` is the projection's convergence tolerance (model units); make it
    well below the distances that matter.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    best = np.full(points.shape[0], np.inf)
    for c in curves:
        params, seeds = span_points(c, SEED_PER_SPAN)
        nearest = cKDTree(seeds).query(points)[1]
        found = project_to_curve(c.curve3d, points, tol=tol, guess=params[nearest])
        best = np.minimum(best, found.distance)
        if c.closed:
            # first and last seed are one point at the two domain ends: a projection
            # from the wrong end stops there, so points near the closure try both ends
            end = (nearest == 0) | (nearest == params.size - 1)
            if end.any():
                other = np.where(nearest[end] == 0, params[-1], params[0])
                again = project_to_curve(c.curve3d, points[end], tol=tol, guess=other)
                best[end] = np.minimum(best[end], again.distance)
    return best


def polyline_length(points: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def dense_length(curves, per_span: int = 64) -> float:
    """Total length of our curves through their interpolants (``per_span`` chords per span:
    relative chord error about ``(kappa h)^2 / 24``, far below 1e-6 here)."""
    return sum(polyline_length(p) for p in dense(curves, per_span))


def check_on_surfaces(curves, a, b, tol: float = 1e-7) -> None:
    """Every curve lies within ``tol`` of both surfaces (its interpolants, densely) and has
    its 3D curve and both pcurves."""
    assert curves, "no curve found"
    for c in curves:
        dev = c.max_deviation(a, b)
        assert dev.max <= tol, dev
        assert c.curve3d is not None and c.pcurve_a is not None and c.pcurve_b is not None
