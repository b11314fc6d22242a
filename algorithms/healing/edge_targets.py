"""Where a face's sides go when its surface is moved onto its neighbours' edges: the
samples of a common curve mapped onto the face (:func:`on_surface`, past its sides
where they lie beyond them: :func:`beyond_sides`), their ends kept
at the face's corners (:func:`pinned_ends`, :func:`spread_ends`), and how wavy an
edge's image is (:func:`roughness`); the targets of
:func:`~surfprep.algorithms.healing.edge_fit.fit_to_edges` as
:mod:`surfprep.plugin.heal.close_gaps` builds them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ...errors import SurfprepError
from ..fitting import approximate_curve
from ..projection import project_to_surface
from ..surface import NurbsSurface

__all__ = ["along_iso", "beyond_sides", "monotone", "on_surface", "pinned_ends", "roughness", "spread_ends"]

#: a pcurve whose samples lie within this share of the domain of one of its sides runs
#: along that side (its samples then slide along the iso-curve), and the Gauss-Newton
#: steps taken there
ON_BORDER = 1e-9
ISO_STEPS = 6
#: samples closer than this share of a pcurve's extent to its end have piled up there
#: (feet clamped onto a corner lie up to 2.4e-12 of the domain apart: turbine face 12) ...
PILED = 1e-9
#: ... and samples of an edge closer than this share of its parameter lie at one place
SAME_S = 1e-12
#: a side's pcurve may end off that side by this share of the domain (its ends on the
#: face's corners, each the mean of its edges' ends there)
CORNER_OFF = 1e-3
#: a foot where a derivative is shorter than this share of its median over the surface,
#: or where the two are this close to parallel (sine), stays on its side
#: (:func:`beyond_sides`)
_DEGENERATE = 1e-3
#: share of a pcurve's parameter over which the shift of an end back to its corner fades
END_FADE = 0.25
#: knot spans of the smooth curve an image is compared with (:func:`roughness`)
SMOOTH_SPANS = 8


def on_surface(surface: NurbsSurface, points: NDArray, guess: NDArray, s: NDArray) -> NDArray:
    """Parameters on ``surface`` for ``points`` (m, 3) near the pcurve samples ``guess``
    (m, 2) at ``s`` (m,) along the edge: their closest points, or, for a pcurve along
    the domain's border (an untrimmed face's side), their closest points on that
    border's iso-curve (:func:`along_iso`; projected onto the surface, feet near a
    corner would pile up at the corner), kept in order (:func:`monotone`). A pcurve
    runs along a side when its samples farther than ``END_FADE`` of ``s`` from its ends
    lie on it within ``ON_BORDER`` of the domain, and its ends within ``CORNER_OFF``:
    a face's corner, where :func:`pinned_ends` put its ends, may lie off the side by
    what its two edges' ends there lay apart. Returns (m, 2) float."""
    u0, u1, v0, v1 = surface.domain
    span = float(np.ptp(s))
    middle = (s - s[0] >= END_FADE * span) & (s[-1] - s >= END_FADE * span)
    if not middle.any():            # (too few samples to leave the ends out)
        middle[:] = True
    for k, (lo, hi) in enumerate(((u0, u1), (v0, v1))):
        for end in (lo, hi):
            off = np.abs(guess[:, k] - end)
            if (np.all(off[middle] <= ON_BORDER * (hi - lo))
                    and np.all(off <= CORNER_OFF * (hi - lo))):
                return monotone(along_iso(surface, points, guess, k, end), 1 - k, s)
    return beyond_sides(surface, points, project_to_surface(surface, points, guess=guess).uv)


def beyond_sides(surface: NurbsSurface, points: NDArray, feet: NDArray) -> NDArray:
    """``feet`` (m, 2), the closest points of ``points`` (m, 3) within the domain, with
    those on a side of the domain (clamped there: their points lie beyond it) moved on
    by a Gauss-Newton step in the tangent plane, out of the domain: the parameters a
    point beyond the side has on the surface extended linearly.

    A common curve arriving at its vertex from beyond the face's domain (the vertex a
    little outside the face) otherwise projects onto the side there: its last samples
    pile up along the side, and the surface, asked to reach points 1e-4 apart from
    parameters 1e-6 apart, folds over (KCS hull face 5). Extended, they run on past
    the side, and :func:`pinned_ends` brings the end back to its corner in a smooth
    fade. A foot where a derivative nearly vanishes (a pole) or the two are nearly
    parallel (a cusp) stays. Returns (m, 2) float."""
    u0, u1, v0, v1 = surface.domain
    lo = np.array([u0, v0])
    hi = np.array([u1, v1])
    near = ON_BORDER * (hi - lo)
    below = np.abs(feet - lo) <= near                   # (m, 2): on the side u = u0, v = v0
    above = np.abs(feet - hi) <= near
    on_side = np.any(below | above, axis=1)
    if not on_side.any():
        return feet
    d = surface.derivatives(feet[on_side, 0], feet[on_side, 1], 1)
    su, sv, r = d[:, 1, 0], d[:, 0, 1], points[on_side] - d[:, 0, 0]
    # the normal equations of the 2 x 2 tangent-plane least squares, by Cramer's rule
    a, b, c = (np.einsum("ij,ij->i", x, y) for x, y in ((su, su), (su, sv), (sv, sv)))
    ru, rv = np.einsum("ij,ij->i", su, r), np.einsum("ij,ij->i", sv, r)
    det = a * c - b * b
    # not at a pole (a derivative shorter than 1e-3 of its median over the surface) nor
    # at a cusp
    grid = np.linspace(0.0, 1.0, 9)
    typical = surface.derivatives_grid(u0 + grid * (u1 - u0), v0 + grid * (v1 - v0), 1)
    speed_u = float(np.median(np.einsum("...i,...i->...", typical[..., 1, 0, :], typical[..., 1, 0, :])))
    speed_v = float(np.median(np.einsum("...i,...i->...", typical[..., 0, 1, :], typical[..., 0, 1, :])))
    fine = ((a > _DEGENERATE ** 2 * speed_u) & (c > _DEGENERATE ** 2 * speed_v)
            & (det > _DEGENERATE ** 2 * a * c))
    step = np.zeros((det.size, 2))
    step[fine] = np.stack([c[fine] * ru[fine] - b[fine] * rv[fine],
                           a[fine] * rv[fine] - b[fine] * ru[fine]], axis=1) / det[fine, None]
    # only out of the domain, across a side the foot is on (a step back inside would be a
    # foot the projection missed)
    out_of = np.any((below[on_side] & (step < 0)) | (above[on_side] & (step > 0)), axis=1)
    step[~out_of] = 0.0
    out = feet.copy()
    out[on_side] += step
    return out


def monotone(uv: NDArray, k: int, s: NDArray) -> NDArray:
    """``uv`` (m, 2) with parameter ``k`` made strictly monotone in ``s`` (m,), the
    samples' parameter along the edge: a sample that steps back or stays (a common
    curve passing over a crease of the surface, or round a sharp bend, projects back
    and forth or piles up on it) gets the parameter interpolated linearly in ``s``
    between the nearest samples before and after it that keep the order (samples at
    one ``s`` share it). Two targets at one parameter ask for two points there, which
    no surface meets. Returns (m, 2) float."""
    x = uv[:, k]
    sign = np.sign(x[-1] - x[0])
    first = np.concatenate([[True], np.diff(s) > SAME_S * max(float(np.ptp(s)), 1.0)])
    if sign == 0 or np.count_nonzero(first) < 3:
        return uv
    y = sign * x[first]
    before = np.maximum.accumulate(np.concatenate([[-np.inf], y[:-1]]))
    after = np.minimum.accumulate(np.concatenate([y[1:], [np.inf]])[::-1])[::-1]
    kept = (y > before) & (y < after)
    kept[[0, -1]] = True
    if kept.all():
        return uv
    t = s[first]
    out = uv.copy()
    out[:, k] = sign * np.interp(s, t[kept], y[kept])
    return out


def spread_ends(uv: NDArray, s: NDArray) -> NDArray:
    """``uv`` (m, 2) with the samples that piled up at an end (a common curve reaching
    past the surface's corner projects onto the corner) spread evenly in ``s`` (m,) up
    to the first that did not: one target per parameter."""
    uv = uv.copy()
    scale = float(np.ptp(uv, axis=0).max()) or 1.0
    for order in (slice(None), slice(None, None, -1)):
        w, t = uv[order], s[order]
        moved = np.flatnonzero(np.linalg.norm(w - w[0], axis=1) > PILED * scale)
        if moved.size and moved[0] > 1:
            k = moved[0]
            w[1:k] = w[0] + np.outer((t[1:k] - t[0]) / (t[k] - t[0]), w[k] - w[0])
    return uv


def along_iso(surface: NurbsSurface, points: NDArray, guess: NDArray, k: int, value: float
               ) -> NDArray:
    """Closest points of ``points`` (m, 3) on the iso-curve ``uv[k] = value`` by
    Gauss-Newton steps in the other parameter from ``guess`` (m, 2) (beyond the domain:
    along the tangent at its end, so the result may leave the domain there). Returns
    (m, 2) float."""
    free = 1 - k
    lo, hi = surface.domain[2 * free], surface.domain[2 * free + 1]
    uv = guess.copy()
    uv[:, k] = value
    for _ in range(ISO_STEPS):
        at = uv.copy()
        at[:, free] = np.clip(at[:, free], lo, hi)
        d = surface.derivatives(at[:, 0], at[:, 1], 1)
        tangent = d[:, 1, 0] if free == 0 else d[:, 0, 1]
        step = np.einsum("ij,ij->i", points - d[:, 0, 0], tangent) / np.maximum(
            np.einsum("ij,ij->i", tangent, tangent), 1e-300)
        # beyond an end the foot is extrapolated along the end's tangent (clamped, the
        # feet would pile up at the corner); :func:`pinned_ends` brings the ends back
        uv[:, free] = at[:, free] + step
    return uv


def pinned_ends(uv: NDArray, old: NDArray, s: NDArray) -> NDArray:
    """``uv`` (m, 2) with its ends put back where the old pcurve ``old`` (m, 2) ended, the
    shift faded out over ``END_FADE`` of the parameter ``s`` (m,) at each end by the C1
    cubic ``(1 - x)^2 (1 + 2x)``: the face's corners keep their parameters (the other
    edges there end at them; a pole's point projects to any parameter along it), the
    surface moves them to the vertices."""
    def fade(x: NDArray) -> NDArray:
        x = np.clip(x / END_FADE, 0.0, 1.0)
        return ((1.0 - x) ** 2 * (1.0 + 2.0 * x))[:, None]      # 1 at the end, C1 to 0
    return uv + fade(s - s[0]) * (old[0] - uv[0]) + fade(s[-1] - s) * (old[-1] - uv[-1])


def roughness(points: NDArray, s: NDArray) -> float:
    """How far ``points`` (m, 3) along an edge at ``s`` (m,) lie from their least-squares
    cubic with ``SMOOTH_SPANS`` spans: the waves of a pcurve approximated coarsely by an
    exporter (0 when there are too few points to fit)."""
    try:
        smooth = approximate_curve(points, SMOOTH_SPANS + 3, parameters=s)
    except SurfprepError:
        return 0.0
    return float(np.max(np.linalg.norm(smooth.evaluate(s) - points, axis=1)))
