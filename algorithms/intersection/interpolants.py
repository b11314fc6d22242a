"""Interpolants of intersection samples: one chord-length parametrization shared by
the 3D curve and both pcurves (000 §29.4.6), and their deviation from the surfaces.

:func:`interpolate_samples` is the C2 cubic (:func:`fitting.interpolate_curve`;
a closed sequence gets a C1 closure); :func:`interpolate_stacked` builds
several on one parametrization with one collocation solve; :func:`span_errors`
measures ``|S_a(pcurve_a) - curve3d|``, ``|S_b(pcurve_b) - curve3d|`` and
``|S_a - S_b|`` at given parameters of every span.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..curve import NurbsCurve
from ..fitting import interpolate_curve
from ..surface import NurbsSurface

__all__ = ["interpolate_samples", "interpolate_stacked", "sample_parameters", "span_errors"]


def sample_parameters(points: NDArray, closed: bool) -> NDArray:
    """Cumulative chord length ``(n,)`` (``(n + 1,)`` when closed: the closing chord too)."""
    pts = np.vstack([points, points[:1]]) if closed else points
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])


def interpolate_samples(values: ArrayLike, parameters: ArrayLike, closed: bool) -> NurbsCurve:
    """The interpolant of samples: one call of :func:`fitting.interpolate_curve`.

    Parameters
    ----------
    values : (n, d) float
        A closed sequence does not repeat its first sample.
    parameters : (n,) float, or (n + 1,) float when closed
    closed : bool
        Closed: the first sample is appended, with a C1 closure when
        there are at least 4 samples.

    Returns
    -------
    NurbsCurve of degree ``min(3, samples - 1)``
    """
    q = np.asarray(values, dtype=float)
    if closed:
        q = np.vstack([q, q[:1]])
    degree = min(3, q.shape[0] - 1)
    return interpolate_curve(q, degree=degree, parameters=parameters,
                             smooth_closure=closed and q.shape[0] >= 4)


def interpolate_stacked(values: Sequence[NDArray | None], parameters: NDArray,
                        closed: bool) -> list[NurbsCurve | None]:
    """Interpolants of several sample sequences on one parametrization, by one solve.

    ``values`` are ``(n, d_i)`` arrays (or None); the collocation system of
    :func:`interpolate_samples` is the same for all of them, so they are
    interpolated together as one ``(n, sum d_i)`` sequence and split again.
    Returns one NurbsCurve per entry (None for None).
    """
    present = [v for v in values if v is not None]
    stacked = interpolate_samples(np.hstack(present), parameters, closed)
    out, col = [], 0
    for v in values:
        if v is None:
            out.append(None)
            continue
        d = v.shape[1]
        out.append(NurbsCurve.construct_fast(stacked.control_points[:, col:col + d],
                                             stacked.knots, stacked.degree))
        col += d
    return out


def span_errors(t: NDArray, curve3d: NurbsCurve, pcurve_a: NurbsCurve | None,
                pcurve_b: NurbsCurve | None, surface_a: NurbsSurface | None,
                surface_b: NurbsSurface | None) -> tuple[NDArray, NDArray, NDArray]:
    """Per span, the largest of ``|S_a(pcurve_a) - curve3d|``, ``|S_b(pcurve_b) - curve3d|``
    and ``|S_a(pcurve_a) - S_b(pcurve_b)|`` at the parameters ``t (spans, k)``:
    three ``(spans,) float`` (NaN where a side is missing)."""
    c = curve3d.evaluate(t)
    on = []
    for surface, pcurve in ((surface_a, pcurve_a), (surface_b, pcurve_b)):
        if surface is None or pcurve is None:
            on.append(None)
            continue
        uv = pcurve.evaluate(t)
        on.append(surface.evaluate(uv[..., 0], uv[..., 1]))
    nan = np.full(t.shape[0], np.nan)
    dist = [nan if s is None else np.linalg.norm(s - c, axis=-1).max(axis=1) for s in on]
    gap = nan if any(s is None for s in on) else np.linalg.norm(on[0] - on[1], axis=-1).max(axis=1)
    return dist[0], dist[1], gap
