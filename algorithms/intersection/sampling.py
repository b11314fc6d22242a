"""How many samples an intersection curve needs: enough for its cubic interpolants (000 §29.4.6).

The result of an intersection is a set of refined samples *and* their C2 cubic
interpolants (:func:`interpolate_samples`): ``curve3d`` through the points,
``pcurve_a`` / ``pcurve_b`` through the (u, v) on each surface, all on the
cumulative chord length of the 3D samples. Sampling so that straight chords
meet ``tol`` needs about ``L / sqrt(8 tol / kappa)`` samples (9 000 on a unit
circle at 1e-7); the cubic interpolant of samples ``h`` apart is off the
curve by about ``kappa^3 h^4 / 384`` in the interior (measured: 0.0026
``h^4`` on a unit circle; about ten times that in the end spans and at the C1
closure of a closed curve), so it needs about ``L kappa^(3/4) / (384
tol)^(1/4)`` samples: 80 on the unit circle at 1e-7, 450 at 1e-10.

:func:`cubic_samples` chooses them from the densely refined traced samples
of a curve (each within ``tol / 16`` of both surfaces):

1. an initial subset spaced ``h(s) = (384 share tol / kappa^3)^(1/4)`` along
   the curve, ``kappa^3`` the larger of the discrete (Menger) curvature of the
   3D samples cubed and the fourth derivative of the checked errors estimated
   from the dense samples (through the surfaces' Jacobians), the ends always
   kept (a closed curve keeps at least four samples), graded at the crossings of
   C1 knot lines and with a sample on each crossing of a C2 knot line
   (:mod:`.crossings`);
2. rounds of verification: every span of the interpolants is checked at a
   quarter, the midpoint and three quarters on both exact surfaces
   (``|S_a(pcurve_a(t)) - curve3d(t)|``, ``|S_b(pcurve_b(t)) - curve3d(t)|``
   and ``|S_a - S_b|``), and every dense sample left out is projected onto
   ``curve3d`` (Newton on the curve), so a feature between the kept samples
   cannot be skipped. A span over ``share tol`` gets the dense sample nearest
   its middle, or, with none inside, a new sample: the auxiliary-plane
   refinement (:func:`.refine.refine_points`) started from the interpolants'
   (u, v) at the span's midpoint, anchored at ``curve3d`` there. All spans of
   all curves are refined in one batch per round.

``share`` (1/2) leaves the rest of ``tol`` for what three points per span do
not see (the sample count grows only as ``share^(-1/4)``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..curve import NurbsCurve
from ..surface import NurbsSurface
from . import vectors
from .crossings import c1_knots, c2_knots, crossing_chords, crossing_positions, on_c2_crossings
from .interpolants import (
    interpolate_samples,
    interpolate_stacked,
    sample_parameters,
    span_errors,
)
from .refine import RefinedCurve, RefinedPoints, refine_points
from .sampling_rounds import (
    CHECK_FRACTIONS,
    MIDDLE_SHARE,
    POINT_SHARE,
    Refiner,
    VerificationState,
    verification_round,
)
from .splines import interpolate_many

__all__ = [
    "CHECK_FRACTIONS",
    "CUBIC_SHARE",
    "SampledCurve",
    "cubic_samples",
    "interpolate_samples",
    "interpolate_stacked",
    "sample_parameters",
    "span_errors",
]

#: interpolants are sampled until they are within this share of tol at the check points
CUBIC_SHARE = 0.5
#: interior error constant of the chord-length C2 cubic: kappa^3 h^4 / 384
_CUBIC_CONSTANT = 384.0
#: the spacing is this share of what the constant predicts (the interior error then about
#: 0.4 of the target; end spans and the closure of a closed curve are worse)
_SPACING = 0.8
#: weight of the measured fourth derivative against kappa^3 (a divided difference over
#: five dense samples smooths the peaks of the true one; measured on the benchmark
#: pairs: bumpy bicubic x plane 4 -> 2 rounds at 1e-7 and 7 -> 3 at 1e-10, with fewer
#: samples, against 0.41; the rational surfaces' cuts take 20-35 % more samples). With
#: the checked errors' estimate through the Jacobians, 1.5 and 4 gave the same rounds
#: on the 26 benchmark cuts within one either way (-8 % / +9 % samples)
_FOURTH_WEIGHT = 2.5
#: dense samples within this share of tol of the one before (and a rounding in both
#: parameter planes) repeat it and are left out before the samples are planned
REPEAT_SHARE = 1e-3
#: a dense chord's fourth-derivative estimate is at least this share of its neighbours'
#: (its spacing at most 0.5^(-1/4) = 1.19 times theirs): on the 14 characteristic pairs
#: and the 6 SSI benchmark pairs at 1e-7 / 1e-10, 44 -> 37 verification rounds for
#: 1.5 % more samples (0.3: 39 rounds, the bumpy bicubic's dip at 1e-9 not closed)
_NEIGHBOUR_SHARE = 0.5
#: the fourth-derivative estimate is ignored this many dense chords round a C1 knot-line
#: crossing (five-sample windows reach that far)
_KINK_REACH = 2


# ------------------------------------------------------------------ initial subset
def _menger(points: NDArray, closed: bool) -> NDArray:
    """Discrete curvature ``(n,)`` at every sample: 1 / radius of the circle through it
    and its neighbours (0 at the ends of an open polyline)."""
    n = points.shape[0]
    kappa = np.zeros(n)
    if n < 3:
        return kappa
    if closed:
        prev, here, nxt = np.roll(points, 1, axis=0), points, np.roll(points, -1, axis=0)
        idx = np.arange(n)
    else:
        prev, here, nxt = points[:-2], points[1:-1], points[2:]
        idx = np.arange(1, n - 1)
    a, b, c = here - prev, nxt - here, nxt - prev
    la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
    area2 = np.abs(a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) if points.shape[1] == 2 \
        else np.linalg.norm(vectors.cross(a, b), axis=1)
    den = la * lb * lc
    kappa[idx] = np.where(den > 0, 2.0 * area2 / np.where(den > 0, den, 1.0), 0.0)
    return kappa


def _pcurve_jacobians(surface: NurbsSurface, uv: NDArray) -> NDArray:
    """``(n, 3, 2)``: ``[S_u, S_v]`` of ``surface`` at ``uv (n, 2)``."""
    d = surface.derivatives(uv[:, 0], uv[:, 1], 1)
    return np.stack([d[:, 1, 0], d[:, 0, 1]], axis=-1)


def _scale(uv: NDArray, points: NDArray) -> float:
    """Median ratio of 3D to ``uv`` chords (model units per parameter unit)."""
    duv = np.linalg.norm(np.diff(uv, axis=0), axis=1)
    dp = np.linalg.norm(np.diff(points, axis=0), axis=1)
    ok = duv > 0
    return float(np.median(dp[ok] / duv[ok])) if np.any(ok) else 1.0


def _fourth_derivatives(curve: RefinedCurve, t: NDArray,
                        jacobians: tuple[NDArray, NDArray]) -> NDArray:
    """Fourth derivative estimate ``(chords,)`` of the checked errors per dense chord.

    The checks (:mod:`.sampling_rounds`) measure ``S_a(pcurve_a) - curve3d``,
    ``S_b(pcurve_b) - curve3d`` and ``S_a - S_b``. Interpolation is linear, so
    with ``E`` the interpolation error of the C2 cubic and ``J`` a surface's
    Jacobian (frozen over a few samples) the first is ``J E[uv] - E[C] =
    -E[C - J uv]``, of order ``h^4`` times the fourth derivative of ``C - J uv``:
    what the pcurve shares with ``curve3d`` cancels (on a plane ``C - J uv`` is
    constant and the check error vanishes at any spacing), and what remains is
    the 3D error the surface's curvature adds. Here ``d4 = 24 f[t_i..t_i+4]``
    of every five consecutive dense samples (the divided difference is the
    fourth derivative at some point over 24; wrapping round a closed curve) for
    ``C`` and for both ``uv``; per window the largest of ``|d4 C - J_a d4
    uv_a|``, ``|d4 C - J_b d4 uv_b|``, ``|J_a d4 uv_a - J_b d4 uv_b|`` (``J``
    at the window's middle sample), given to the two middle chords of the
    window and the larger taken per chord.

    A scalar scale of the pcurves instead (the median ratio of 3D to
    parameter chords) took every pcurve's own fourth derivative for error: on a
    sphere, whose parametrization turns a small circle into a 4:1 ellipse, 2.3
    times the samples the circle needs, every span at 1 % of its target.

    Where a surface's parametrization is only C1 (the knot lines of converted
    rational surfaces) the pcurve's second derivative jumps and this estimate is
    large on the chords next to the crossing, so the first subset is already
    denser there instead of rounds of splitting finding it out.

    ``jacobians``: ``(n, 3, 2)`` of each surface at the dense samples
    (:func:`_pcurve_jacobians`).
    """
    pts, closed = curve.points, curve.closed
    chords = t.size - 1
    out = np.zeros(chords)
    if pts.shape[0] < 5:
        return out
    values = np.hstack([pts, curve.uv_a, curve.uv_b])
    if closed:
        values = np.vstack([values, values[:4]])
        t = np.concatenate([t, t[1:4] + t[-1]])
    dd = values
    for k in range(1, 5):
        dd = np.diff(dd, axis=0) / (t[k:] - t[:-k])[:, None]
    middle = (np.arange(dd.shape[0]) + 2) % pts.shape[0]
    on_a = np.einsum("nij,nj->ni", jacobians[0][middle], dd[:, 3:5])
    on_b = np.einsum("nij,nj->ni", jacobians[1][middle], dd[:, 5:7])
    f4 = 24.0 * np.maximum.reduce([np.linalg.norm(d, axis=1) for d in
                                   (dd[:, :3] - on_a, dd[:, :3] - on_b, on_a - on_b)])
    for shift in (1, 2):       # window i covers chords i .. i + 3: the middle ones
        idx = np.arange(f4.size) + shift
        np.maximum.at(out, idx % chords if closed else idx, f4)
    if not closed:             # the end chords take their neighbours' values
        out[0], out[-1] = max(out[0], out[1]), max(out[-1], out[-2])
    return out


def _with_neighbours(f4: NDArray, closed: bool) -> NDArray:
    """``f4 (chords,)`` raised to ``_NEIGHBOUR_SHARE`` of each neighbouring chord's value.

    The estimate is a sample per dense chord; where the fourth derivative passes
    through zero one chord's value drops far below its neighbours', while the
    interpolant's error there is set by the neighbours too (a C2 cubic's error spreads
    over the spans around): with dense chords about as long as a cubic span, such a
    chord planned one span 1.4 times its neighbours' (bumpy bicubic x plane at 1e-9:
    1.2-1.8 x target, a second round for 7 spans of 1718)."""
    if f4.size < 2:
        return f4
    if closed:
        return np.maximum(f4, _NEIGHBOUR_SHARE * np.maximum(np.roll(f4, 1), np.roll(f4, -1)))
    out = f4.copy()
    np.maximum(out[1:], _NEIGHBOUR_SHARE * f4[:-1], out=out[1:])
    np.maximum(out[:-1], _NEIGHBOUR_SHARE * f4[1:], out=out[:-1])
    return out


def _spacing_phase(curve: RefinedCurve, t: NDArray, target: float,
                   fourth: NDArray | None = None) -> NDArray:
    """Cumulative number of cubic spans needed ``(len(t),)`` at the dense samples:
    the integral of ``(f4 / (384 target))^(1/4)`` along the chord lengths ``t``,
    ``f4`` the larger of ``kappa^3`` (Menger curvature of the 3D polyline: the
    divided differences of five dense samples smooth a peak of the true fourth
    derivative, the curvature of three does not) and ``fourth (chords,)``
    (:func:`_fourth_derivatives`), each chord's value raised to a share of its
    neighbours' (:func:`_with_neighbours`)."""
    kappa = _menger(curve.points, curve.closed)
    ds = np.diff(t)
    k_chord = np.maximum(kappa, np.roll(kappa, -1))[: ds.size]
    f4 = np.maximum(k_chord, 0.0) ** 3
    if fourth is not None:
        f4 = np.maximum(f4, _FOURTH_WEIGHT * fourth)
    f4 = _with_neighbours(f4, curve.closed)
    per_length = (f4 / (_CUBIC_CONSTANT * target)) ** 0.25 / _SPACING
    return np.concatenate([[0.0], np.cumsum(ds * per_length)])


def _without_repeats(curve: RefinedCurve, tol: float, surface_a: NurbsSurface,
                     surface_b: NurbsSurface) -> RefinedCurve:
    """``curve`` without the dense samples that repeat the one before them: within
    ``REPEAT_SHARE * tol`` in space and a rounding (``1e-9`` of the domain) in both
    parameter planes (the ends are kept; at a collapsed side, where the
    parameters move while the point does not, nothing is a repeat). The fourth
    divided differences of :func:`_fourth_derivatives` across a chord of a
    rounding are rounding over its fourth power: seven samples 1e-12 apart at a
    corner of occt_spaceship_alias.stp faces 1 x 3 planned 6.6 million samples
    on a curve of length 20."""
    n = curve.points.shape[0]
    if n < 3:
        return curve
    reach = [1e-9 * max(s.domain[1] - s.domain[0], s.domain[3] - s.domain[2])
             for s in (surface_a, surface_b)]
    points = np.vstack([curve.points, curve.points[:1]]) if curve.closed else curve.points
    uv = [np.vstack([w, w[:1]]) if curve.closed else w for w in (curve.uv_a, curve.uv_b)]
    repeat = (np.linalg.norm(np.diff(points, axis=0), axis=1) <= REPEAT_SHARE * tol) \
        & (np.abs(np.diff(uv[0], axis=0)).max(axis=1) <= reach[0]) \
        & (np.abs(np.diff(uv[1], axis=0)).max(axis=1) <= reach[1])
    keep = np.ones(n, dtype=bool)
    keep[1:] = ~repeat[: n - 1]                 # sample i + 1 repeats sample i
    if curve.closed and repeat[n - 1]:          # the last repeats the first
        keep[n - 1] = False
    if not curve.closed and not keep[-1]:       # the end stays: its repeat before it goes
        keep[-1] = True
        before = np.flatnonzero(keep[:-1])[-1]
        if before > 0:
            keep[before] = False
    if keep.all() or keep.sum() < 2 + 2 * curve.closed:
        return curve
    return RefinedCurve(curve.points[keep], curve.uv_a[keep], curve.uv_b[keep], curve.closed,
                        curve.converged[keep], curve.singular[keep])


def _dense_parameters(curve: RefinedCurve) -> NDArray | None:
    """Chord-length parameters of a densely refined curve, or None when it has too few
    converged samples to interpolate (every dense sample is kept then)."""
    if not curve.converged.all() or curve.points.shape[0] < 2 + 2 * curve.closed:
        return None
    t = sample_parameters(curve.points, curve.closed)
    return None if np.any(np.diff(t) <= 0) else t


def _resample_targets(curve: RefinedCurve, t: NDArray, target: float,
                      fourth: NDArray | None = None, knots: tuple | None = None
                      ) -> tuple[NDArray, NDArray]:
    """New sample positions of a densely refined curve (module docstring, step 1).

    Returns ``(t, positions)``: the dense chord-length parameters ``t`` and the
    interior parameters where samples should go, equally many cubic spans apart (at
    least four spans on a closed curve), on the interpolant through all dense samples;
    graded towards the crossings of C1 knot lines and with a sample on those of C2
    knot lines (:mod:`.crossings`) when ``knots`` gives ``(c1_knots(a), c1_knots(b),
    domain_a, domain_b, c2_knots(a), c2_knots(b))``.
    """
    if knots is not None and fourth is not None and fourth.size:
        # the jump at a C1 knot line shows as a large fourth derivative on the chords
        # round it; the graded zone of :mod:`.crossings` takes care of those instead
        near = crossing_chords(curve.uv_a, curve.uv_b, t, *knots[:4], curve.closed)
        if near.size:
            near = (near[:, None] + np.arange(-_KINK_REACH, _KINK_REACH + 1)[None, :]).ravel()
            near = np.mod(near, fourth.size) if curve.closed else \
                near[(near >= 0) & (near < fourth.size)]
            fourth = fourth.copy()
            fourth[near] = 0.0
    phase = _spacing_phase(curve, t, target, fourth)
    spans = max(int(np.ceil(phase[-1] - 1e-9)), 4 if curve.closed else 1)
    goal = phase[-1] * np.arange(1, spans) / spans if phase[-1] > 0 else \
        t[-1] * np.arange(1, spans) / spans
    positions = np.interp(goal, phase, t) if phase[-1] > 0 else goal
    if not curve.closed and positions.size:     # the end spans' error is ~10x the interior's
        ends = np.array([0.5 * positions[0], 0.5 * (positions[-1] + t[-1])])
        positions = np.sort(np.concatenate([positions, ends]))
    if knots is not None and phase[-1] > 0:
        ds, dphase = np.diff(t), np.diff(phase)
        regular = np.minimum(ds / np.maximum(dphase, 1e-300), t[-1] / spans)
        pts = curve.points
        stacked = np.hstack([pts, curve.uv_a * _scale(curve.uv_a, pts),
                             curve.uv_b * _scale(curve.uv_b, pts)])
        positions = crossing_positions(positions, t, regular, stacked, curve.uv_a, curve.uv_b,
                                       knots[0], knots[1], knots[2], knots[3], curve.closed,
                                       target)
        positions = on_c2_crossings(positions, t, curve.uv_a, curve.uv_b, knots[4], knots[5],
                                    knots[2], knots[3], curve.closed)
    return t, positions


def _dense_jacobians(surface_a: NurbsSurface, surface_b: NurbsSurface,
                     curves: Sequence[RefinedCurve]) -> list[tuple[NDArray, NDArray]]:
    """Per curve ``(J_a, J_b)``, each ``(n, 3, 2)``, at its dense samples (one
    evaluation per surface for all curves)."""
    if not curves:
        return []
    split = np.cumsum([c.points.shape[0] for c in curves])[:-1]
    jac_a = _pcurve_jacobians(surface_a, np.concatenate([c.uv_a for c in curves]))
    jac_b = _pcurve_jacobians(surface_b, np.concatenate([c.uv_b for c in curves]))
    return list(zip(np.split(jac_a, split), np.split(jac_b, split)))


def _merged_work(curve: RefinedCurve, t: NDArray, positions: NDArray, new) -> VerificationState:
    """Dense samples (left out) merged by parameter with the new ones (kept)."""
    m = curve.points.shape[0]
    t_dense = t[:m]
    kept_dense = np.zeros(m, dtype=bool)
    kept_dense[0] = True
    if not curve.closed:
        kept_dense[-1] = True
    # a new sample on a dense one's parameter: keep the dense one instead
    near = np.searchsorted(t_dense, positions)
    lo = np.clip(near - 1, 0, m - 1)
    hi = np.clip(near, 0, m - 1)
    close_lo = np.abs(t_dense[lo] - positions) <= 1e-9 * t[-1]
    close_hi = np.abs(t_dense[hi] - positions) <= 1e-9 * t[-1]
    kept_dense[lo[close_lo]] = True
    kept_dense[hi[close_hi & ~close_lo]] = True
    fresh = ~(close_lo | close_hi)
    key = np.concatenate([t_dense, positions[fresh]])
    order = np.argsort(key, kind="stable")

    def merge(dense, extra):
        return np.concatenate([dense, extra])[order]

    return VerificationState(merge(curve.points, new.points[fresh]), merge(curve.uv_a, new.uv_a[fresh]),
                 merge(curve.uv_b, new.uv_b[fresh]),
                 merge(curve.converged, np.ones(fresh.sum(), dtype=bool)),
                 merge(curve.singular, new.singular[fresh]), curve.closed,
                 merge(kept_dense, np.ones(fresh.sum(), dtype=bool)),
                 np.zeros(key.size, dtype=bool))


# ------------------------------------------------------------------ verification
@dataclass(frozen=True)
class SampledCurve:
    """Result of :func:`cubic_samples` for one curve.

    Attributes
    ----------
    curve : RefinedCurve
        The samples kept.
    parameters : (n,) float, or (n + 1,) when closed, or None
        Chord-length parameters of the samples (:func:`sample_parameters`).
    interpolants : (curve3d, pcurve_a, pcurve_b) or None
        The interpolants that passed the last check (None when the rounds ran
        out before every span passed: rebuild and measure them then).
    error : float
        Their largest error at the check points (NaN without interpolants).
    """

    curve: RefinedCurve
    parameters: NDArray | None
    interpolants: tuple[NurbsCurve, NurbsCurve, NurbsCurve] | None
    error: float


def cubic_samples(surface_a: NurbsSurface, surface_b: NurbsSurface,
                  curves: Sequence[RefinedCurve], *, tol: float, share: float = CUBIC_SHARE,
                  simplify: bool = True, max_rounds: int = 40,
                  tangent_sin: float = 1e-6, refiner: Refiner = refine_points
                  ) -> list[RefinedCurve]:
    """The samples the cubic interpolants of refined curves need (module docstring).

    Parameters
    ----------
    surface_a, surface_b : NurbsSurface
    curves : sequence of RefinedCurve
        Densely refined traced samples (e.g. :func:`.refine.refine_curves` with
        ``max_passes=0, simplify=False``).
    tol : float
        Model units; the interpolants are sampled until within ``share * tol``
        at the check points of every span.
    share : float in (0, 1]
    simplify : bool
        Start from the curvature-spaced subset (step 1); without it every
        dense sample is kept and only insertion happens.
    max_rounds : int
        Verification rounds at most.
    tangent_sin : float
        As in :func:`.refine.refine_points`.
    refiner : callable
        Puts new samples on the curve: ``refiner(surface_a, surface_b, uv_a, uv_b,
        tol=, anchors=, tangent_sin=) -> RefinedPoints``, by default
        :func:`.refine.refine_points` (a tangential curve, where the surfaces
        touch and points within tol of both form a band, needs its own).

    Returns
    -------
    list of SampledCurve or None
        Each with a subset of its dense samples plus inserted ones, in curve
        order (the ends of open curves are kept), and, when it passed, its
        interpolants and their largest check-point error; None for a curve whose
        samples all collapse onto one point (within ``tol / 1000``).
    """
    target = share * tol
    curves = [_without_repeats(c, tol, surface_a, surface_b) for c in curves]
    plans = [_dense_parameters(c) if simplify else None for c in curves]
    live = [i for i, t in enumerate(plans) if t is not None]
    new = None
    if live:                # the interpolants through all dense samples, evaluated at once
        dense = interpolate_many([np.hstack([curves[i].points, curves[i].uv_a, curves[i].uv_b])
                                  for i in live], [plans[i] for i in live],
                                 [curves[i].closed for i in live])
        knots = (c1_knots(surface_a), c1_knots(surface_b), surface_a.domain, surface_b.domain,
                 c2_knots(surface_a), c2_knots(surface_b))
        jacobians = _dense_jacobians(surface_a, surface_b, [curves[i] for i in live])
        for i, jac in zip(live, jacobians):
            plans[i] = _resample_targets(curves[i], plans[i], target,
                                         _fourth_derivatives(curves[i], plans[i], jac), knots)
        planned = [(curves[i], plans[i]) for i in live]
        at = dense.evaluate(np.repeat(np.arange(len(planned)), [p.size for _, (_, p) in planned]),
                            np.concatenate([p for _, (_, p) in planned]))
        anchors = at[:, :3]
        new = refiner(surface_a, surface_b, at[:, 3:5], at[:, 5:7], tol=POINT_SHARE * tol,
                      anchors=anchors, tangent_sin=tangent_sin)
        # a sample that slid along the curve (near-tangential surfaces) is left out
        moved = np.linalg.norm(new.points - anchors, axis=1)
    works, offset = [], 0
    for c, plan in zip(curves, plans):
        m = c.points.shape[0]
        if plan is None:
            works.append(VerificationState(c.points, c.uv_a, c.uv_b, c.converged.copy(), c.singular.copy(),
                               c.closed, np.ones(m, dtype=bool), np.zeros(m, dtype=bool)))
            continue
        t, pos = plan
        sl = slice(offset, offset + pos.size)
        offset += pos.size
        spacing = t[-1] / (pos.size + 1)
        ok = new.converged[sl] & (moved[sl] <= MIDDLE_SHARE * spacing)
        part = RefinedPoints(new.points[sl][ok], new.uv_a[sl][ok], new.uv_b[sl][ok],
                             new.gap[sl][ok], new.iterations[sl][ok], new.converged[sl][ok],
                             new.singular[sl][ok])
        works.append(_merged_work(c, t, pos[ok], part))
    for _ in range(max_rounds):
        verification_round(works, surface_a, surface_b, target, tol, tangent_sin, refiner)
        if all(w.done for w in works):
            break
    out = []
    for w in works:
        if w.degenerate:
            out.append(None)
            continue
        curve = RefinedCurve(w.points[w.kept], w.uv_a[w.kept], w.uv_b[w.kept], w.closed,
                             w.converged[w.kept], w.singular[w.kept])
        if w.result is None:                       # rounds ran out: not verified as is
            out.append(SampledCurve(curve, None, None, float("nan")))
            continue
        out.append(SampledCurve(curve, w.result.t, w.result.parts(), w.error))
    return out
