"""Verification rounds of the cubic sampling (step 2 of :mod:`.sampling`; 000 §29.4 step 6).

Every round checks the interpolants of all unfinished curves at once: one
collocation solve and one evaluation for all of them (:mod:`.splines`), every
span at a quarter, the midpoint and three quarters on both exact surfaces, and
the dense samples left out projected onto ``curve3d``; failing spans get the
dense sample nearest their middle or new refined samples (all curves in one
:func:`.refine.refine_points` batch).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ..curve import NurbsCurve
from .interpolants import sample_parameters
from .refine import RefinedPoints, refine_points
from .splines import SplineSet, interpolate_many

__all__ = ["CHECK_FRACTIONS", "MIDDLE_SHARE", "POINT_SHARE", "Refiner", "VerificationState",
           "verification_round"]

#: ``refiner(surface_a, surface_b, uv_a, uv_b, *, tol, anchors, tangent_sin)``: new
#: samples put on the curve (:func:`.refine.refine_points` or a tangential curve's own)
Refiner = Callable[..., RefinedPoints]

#: where every span is checked (fractions of the span)
CHECK_FRACTIONS = (0.25, 0.5, 0.75)
#: samples are refined to this share of tol (as in :mod:`.refine`)
POINT_SHARE = 1.0 / 16.0
#: Newton steps projecting left-out dense samples onto curve3d
_PROJECTION_STEPS = 4
#: a projection onto curve3d stops once its steps move the foot by this share of the target
_SETTLED = 1e-2
#: a span longer than this times a neighbour is split (graded sampling), into at most
#: _MAX_GRADED pieces per round, by a closure of at most _GRADE_PASSES passes
_MAX_RATIO = 4.0
_MAX_GRADED = 8
_GRADE_PASSES = 32
#: a failing span takes a dense sample within this fraction of its middle, else a new one
MIDDLE_SHARE = 0.25
#: a new sample must project onto its span's chord this far from both ends
_INSIDE = 0.02
#: a failing span is cut into at most this many pieces per round
_MAX_PIECES = 8
#: spans within this many of a failing span are split with it when over _NEAR_SHARE target
_SPREAD = 4
_NEAR_SHARE = 0.6
#: a curve whose error has not halved in this many rounds is given up
_STALL_ROUNDS = 3
#: kept samples closer than this times tol to the previous one are duplicates
_DUPLICATE = 1e-3
#: spans within this many of a new sample are checked again (0.27^8 = 3e-5)
_LOCALITY = 8
#: a new sample is taken when its two images are this close (times tol), even if the
#: refinement stopped short of tol / 16 (low-angle cuts near 1e-10 converge slowly)
_ACCEPT = 0.25


@dataclass
class VerificationState:
    """One curve under sampling: its dense samples and which of them are kept."""

    points: NDArray
    uv_a: NDArray
    uv_b: NDArray
    converged: NDArray
    singular: NDArray
    closed: bool
    kept: NDArray          # (m,) bool
    stuck: NDArray         # (m,) bool: the span starting at this sample cannot be split
    done: bool = False
    error: float = float("inf")    # largest check-point error in the last round
    result: object = None          # the passing _Check (interpolants) once done
    history: list = field(default_factory=list)     # (error, failing spans) per round
    degenerate: bool = False       # all samples on one point (left out of the result)
    fresh: NDArray | None = None   # (m,) bool: kept since the last check
    span_error: NDArray | None = None   # (m,) float: last checked error of the span from here


def _project_on_curve(curves: SplineSet, index: NDArray, x: NDArray, t0: NDArray, lo: NDArray,
                      hi: NDArray, settled: float = 0.0) -> tuple[NDArray, NDArray]:
    """Distances ``(m,)`` of points ``x (m, 3)``, and their feet ``(m,)``, to the first three coordinates of
    curves ``index (m,)`` of ``curves`` near ``t0`` (Newton within ``[lo, hi]``,
    ``_PROJECTION_STEPS`` at most; stopped once every step moves the foot by
    ``settled`` model units or less: the distance is stationary at the foot, so its
    error is of second order in that)."""
    t = t0.copy()
    for _ in range(_PROJECTION_STEPS):
        d = curves.derivatives(index, t, 2)[..., :3]
        r = d[:, 0] - x
        num = np.einsum("ij,ij->i", r, d[:, 1])
        speed = np.einsum("ij,ij->i", d[:, 1], d[:, 1])
        den = speed + np.einsum("ij,ij->i", r, d[:, 2])
        den = np.where(den > 0, den, speed)
        moved = np.clip(t - num / np.where(den > 0, den, 1.0), lo, hi)
        step = np.abs(moved - t) * np.sqrt(speed)
        t = moved
        if np.all(step <= settled):
            break
    return np.linalg.norm(curves.evaluate(index, t)[:, :3] - x, axis=1), t


@dataclass
class _Check:
    """One curve's interpolants and their check points in a verification round."""

    kept: NDArray          # kept dense indices
    t: NDArray             # their parameters ((k + 1,) when closed)
    curves: SplineSet      # curve3d | pcurve_a | pcurve_b as one 7-dimensional curve ...
    index: int             # ... number ``index`` of this round's set
    dirty: NDArray         # the spans checked this round
    at: NDArray | None = None   # (dirty * 3, 7) interpolant values at the check points

    def evaluate(self, t: NDArray) -> NDArray:
        """The stacked interpolant at ``t (m,)``: ``(m, 7)``."""
        return self.curves.evaluate(np.full(t.size, self.index), t)

    def parts(self) -> tuple[NurbsCurve, NurbsCurve, NurbsCurve]:
        """``(curve3d, pcurve_a, pcurve_b)``."""
        stacked = self.curves.curve(self.index)
        return tuple(NurbsCurve.construct_fast(stacked.control_points[:, a:b], stacked.knots,
                                               stacked.degree)
                     for a, b in ((0, 3), (3, 5), (5, 7)))


def _drop_duplicates(w: VerificationState, tol: float) -> NDArray:
    """Kept indices, after dropping kept samples within ``_DUPLICATE tol`` of the previous
    one (near-tangential refinement can land two samples on one point); they are
    marked unconverged so that no later round takes them again."""
    k = np.flatnonzero(w.kept)
    ring = np.vstack([w.points[k], w.points[k[:1]]]) if w.closed else w.points[k]
    step = np.linalg.norm(np.diff(ring, axis=0), axis=1)
    dup = step <= _DUPLICATE * tol                      # step i: kept i -> i + 1 (wrapping)
    drop = k[1:][dup[: k.size - 1]]
    if w.closed and k.size > 1 and dup[-1] and k[-1] not in drop:
        drop = np.append(drop, k[-1])
    w.kept[drop] = False
    w.converged[drop] = False
    if drop.size:                                        # their neighbours' spans changed
        w.fresh[k[np.maximum(np.searchsorted(k, drop) - 1, 0)]] = True
    return np.flatnonzero(w.kept)


def _dirty_spans(w: VerificationState, k: NDArray, spans: int) -> NDArray:
    """Spans (indices into the kept samples) to check this round: those within
    ``_LOCALITY`` spans of a sample kept since the last check (all in the first
    round). A C2 cubic interpolant moves by a factor ``2 - sqrt(3)`` less per span
    away from a changed sample, so farther spans keep their checked error."""
    if w.span_error is None:
        return np.arange(spans)
    pos = np.flatnonzero(w.fresh[k])
    if pos.size == 0:
        return np.zeros(0, dtype=np.int64)
    near = (pos[:, None] + np.arange(-_LOCALITY - 1, _LOCALITY + 1)[None, :]).ravel()
    near = np.mod(near, spans) if w.closed else near[(near >= 0) & (near < spans)]
    return np.unique(near)


def _checks(works: list[VerificationState], tol: float) -> list[_Check]:
    """This round's interpolants of all curves (one solve, :func:`.splines.interpolate_many`)
    and their values at the check points of the spans to check (one evaluation);
    None for a curve collapsed onto a point."""
    kept, params = [None] * len(works), [None] * len(works)
    for i, w in enumerate(works):
        if w.fresh is None:
            w.fresh = np.zeros(w.points.shape[0], dtype=bool)
        k = _drop_duplicates(w, tol)
        if k.size >= 2 + w.closed:         # else collapsed onto a point: nothing to interpolate
            kept[i], params[i] = k, sample_parameters(w.points[k], w.closed)
    live = [i for i, k in enumerate(kept) if k is not None]
    if not live:
        return [None] * len(works)
    curves = interpolate_many(
        [np.hstack([works[i].points[kept[i]], works[i].uv_a[kept[i]], works[i].uv_b[kept[i]]])
         for i in live], [params[i] for i in live], [works[i].closed for i in live])
    s = np.asarray(CHECK_FRACTIONS)
    out, index, where = [None] * len(works), [], []
    for j, i in enumerate(live):
        w, k, t = works[i], kept[i], params[i]
        dirty = _dirty_spans(w, k, t.size - 1)
        w.fresh[:] = False
        dt = np.diff(t)[dirty]
        where.append((t[dirty, None] + s[None, :] * dt[:, None]).ravel())
        index.append(np.full(where[-1].size, j))
        out[i] = _Check(k, t, curves, j, dirty)
    at = curves.evaluate(np.concatenate(index), np.concatenate(where))
    split = np.cumsum([x.size for x in where])[:-1]
    for i, values in zip(live, np.split(at, split)):
        out[i].at = values
    return out


def _stacked_errors(at: NDArray, surface_a, surface_b) -> NDArray:
    """``(m,)``: the largest of ``|S_a(pcurve_a) - curve3d|``, ``|S_b(pcurve_b) - curve3d|``,
    ``|S_a - S_b|`` at stacked interpolant values ``at (m, 7)``."""
    on_a = surface_a.evaluate(at[:, 3], at[:, 4])
    on_b = surface_b.evaluate(at[:, 5], at[:, 6])
    return np.maximum.reduce([np.linalg.norm(on_a - at[:, :3], axis=1),
                              np.linalg.norm(on_b - at[:, :3], axis=1),
                              np.linalg.norm(on_a - on_b, axis=1)])


def _check_errors(checks: list[_Check], surface_a, surface_b) -> list[NDArray]:
    """Per curve ``(spans,)``: the largest of ``|S_a(pcurve_a) - curve3d|``,
    ``|S_b(pcurve_b) - curve3d|``, ``|S_a - S_b|`` at the check points; one
    evaluation per surface for all curves."""
    err = _stacked_errors(np.concatenate([c.at for c in checks]), surface_a, surface_b)
    split = np.cumsum([c.at.shape[0] for c in checks])[:-1]
    return [e.reshape(-1, len(CHECK_FRACTIONS)).max(axis=1) for e in np.split(err, split)]


def _span_errors_now(w: VerificationState, check: _Check, dirty_error: NDArray) -> NDArray:
    """Errors ``(spans,)`` of all spans: just checked, or as last checked."""
    m = w.points.shape[0]
    if w.span_error is None or w.span_error.shape[0] != m:
        w.span_error = np.full(m, np.nan)
    spans = check.t.size - 1
    w.span_error[check.kept[check.dirty]] = dirty_error
    return w.span_error[check.kept[:spans]]


def _failing_spans(w: VerificationState, check: _Check, error: NDArray, target: float, tol: float,
                   surface_a, surface_b):
    """Spans (by index into the kept samples) over ``target`` at their check points, their
    errors, the dense samples farther than ``target`` from ``curve3d`` where the
    interpolants at their feet are over ``target`` too (the worst per span; those spans
    take them), what the insertion needs and which spans may be split."""
    k, t = check.kept, check.t
    dt = np.diff(t)
    error = np.nan_to_num(error)
    # left-out dense samples: projected onto curve3d within their span
    m = w.points.shape[0]
    ends = np.append(k, m) if w.closed else k                     # span j: ends[j]..ends[j+1]
    span_of = np.searchsorted(ends, np.arange(m), side="right") - 1
    checked = np.zeros(dt.size + 1, dtype=bool)
    checked[check.dirty] = True
    inner = ~w.kept & w.converged & (span_of < dt.size)
    inner &= checked[np.clip(span_of, 0, dt.size)]
    ring = np.vstack([w.points, w.points[:1]]) if w.closed else w.points
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(ring, axis=0), axis=1))])
    off = np.zeros(0, dtype=np.int64)           # dense samples off curve3d: kept next round
    if np.any(inner):
        idx = np.flatnonzero(inner)
        j = span_of[idx]
        a0, a1 = arc[ends[j]], arc[ends[j + 1]]
        frac = (arc[idx] - a0) / np.where(a1 > a0, a1 - a0, 1.0)
        dist, foot = _project_on_curve(check.curves, np.full(idx.size, check.index),
                                       w.points[idx], t[j] + frac * dt[j], t[j], t[j + 1],
                                       settled=_SETTLED * target)
        far = dist > target
        if np.any(far):         # a miss only where the interpolants leave the surfaces there:
            # near-tangential dense samples scatter along the surfaces by gap / sin(angle),
            # which is no error (and keeping them puts kinks into the interpolants)
            far[far] = _stacked_errors(check.evaluate(foot[far]), surface_a, surface_b) > target
        if np.any(far):                          # the worst of each span
            order = np.lexsort((-dist[far], j[far]))
            first = np.concatenate([[True], np.diff(j[far][order]) != 0])
            off = idx[far][order][first]
    can = (dt > tol) & ~w.stuck[k[: dt.size]]
    bad = (error > target) & can
    # spans next to a failing one and nearly failing themselves are split with it: a
    # C2 cubic spreads a split to its neighbours, which would otherwise fail one
    # after another over as many rounds (a front moving a few spans per round)
    near = np.zeros(bad.size, dtype=bool)
    for shift in range(1, _SPREAD + 1):
        near[shift:] |= bad[:-shift]
        near[:-shift] |= bad[shift:]
        if w.closed:
            near[:shift] |= bad[-shift:]
            near[-shift:] |= bad[:shift]
    bad |= near & (error > _NEAR_SHARE * target) & can
    bad[span_of[off]] = False                    # those get their dense sample instead
    bad = np.flatnonzero(bad)
    return bad, error[bad], off, ends, span_of, arc, can


def _graded(dt: NDArray, pieces: NDArray, cut: NDArray, closed: bool, can: NDArray) -> NDArray:
    """Pieces per span ``(spans,) int`` after grading: no piece longer than
    ``_MAX_RATIO`` times the piece beside it across a span end (a C2 cubic swings
    between the check points of a long span next to a short one).

    ``pieces (spans,) int``: the equal pieces planned for each span (1: not split);
    ``cut (spans,) float``: where a kept dense sample splits a span (fraction of it;
    NaN: none), such spans are left as they are; ``can (spans,) bool``: spans that
    may be split. The grading is closed in one go (a front of halvings moving a span
    per round would cost a round per span); at most ``_MAX_GRADED`` pieces.
    """
    n = pieces.astype(np.float64)
    has_cut = ~np.isnan(cut)
    fixed = has_cut | ~can
    any_cut = bool(has_cut.any())
    head, tail = (np.where(has_cut, cut * dt, 0.0), np.where(has_cut, (1 - cut) * dt, 0.0)) \
        if any_cut else (None, None)
    wrap = np.inf
    for _ in range(_GRADE_PASSES):
        first = last = dt / n
        if any_cut:
            first, last = np.where(has_cut, head, first), np.where(has_cut, tail, last)
        before = np.concatenate(([last[-1] if closed else wrap], last[:-1]))
        after = np.concatenate((first[1:], [first[0] if closed else wrap]))
        need = np.ceil(dt / (_MAX_RATIO * np.minimum(before, after)))
        grow = (need > n) & ~fixed
        if not grow.any():
            break
        n[grow] = np.minimum(need[grow], _MAX_GRADED)
    return n.astype(np.int64)


def _insert(w: VerificationState, after: NDArray, points: NDArray, uv_a: NDArray, uv_b: NDArray,
            singular: NDArray) -> None:
    """New kept dense samples right after dense indices ``after`` (sorted, distinct)."""
    m, q = w.points.shape[0], after.size
    new_at = after + 1 + np.arange(q)            # as np.insert places them
    old_at = np.ones(m + q, dtype=bool)
    old_at[new_at] = False

    def put(old: NDArray, new) -> NDArray:
        out = np.empty((m + q,) + old.shape[1:], dtype=old.dtype)
        out[old_at] = old
        out[new_at] = new
        return out

    w.points, w.uv_a, w.uv_b = put(w.points, points), put(w.uv_a, uv_a), put(w.uv_b, uv_b)
    w.converged, w.singular = put(w.converged, True), put(w.singular, singular)
    w.kept, w.stuck, w.fresh = put(w.kept, True), put(w.stuck, False), put(w.fresh, True)
    w.span_error = put(w.span_error, np.nan)


def _place(w: VerificationState, start: NDArray, stop: NDArray, points: NDArray
           ) -> tuple[NDArray, NDArray, NDArray]:
    """Where new samples go in their spans ``start -> stop`` (dense indices, ``stop`` may
    be ``m`` for the closing span): ``(inside, after, fraction)``, three ``(q,)`` arrays.

    ``fraction``: where the point projects onto the span's chord; ``inside``:
    in ``[_INSIDE, 1 - _INSIDE]`` (a point held on a domain side may slide onto
    the span's end);
    ``after``: the dense sample it follows (by that fraction among the dense
    samples of the span).
    """
    m = w.points.shape[0]
    p0, p1 = w.points[start], w.points[stop % m]
    chord = p1 - p0
    den = np.maximum(np.einsum("ij,ij->i", chord, chord), np.finfo(float).tiny)
    frac = np.einsum("ij,ij->i", points - p0, chord) / den
    # anywhere strictly inside: near-tangential surfaces let points slide along the
    # curve (consistently, so the order is kept), which does not hurt the sampling
    inside = (frac >= _INSIDE) & (frac <= 1.0 - _INSIDE)
    after = start.copy()
    busy = np.flatnonzero(inside & (stop - start > 1))      # dense samples inside the span
    if busy.size:
        count = stop[busy] - start[busy] - 1
        item = np.repeat(busy, count)
        between = start[item] + 1 + np.arange(item.size) - np.repeat(np.cumsum(count) - count,
                                                                      count)
        f = np.einsum("ij,ij->i", w.points[between] - p0[item], chord[item]) / den[item]
        after[busy] += np.bincount(np.searchsorted(busy, item[f < frac[item]]),
                                   minlength=busy.size)
    return inside, after, frac


def _stalled(history: list[tuple[float, int]], target: float) -> bool:
    """True when a curve still fails and over the last ``_STALL_ROUNDS`` rounds neither
    its largest error has halved nor its number of failing spans gone down
    (near-tangential surfaces, where the samples themselves are only as good as the
    refinement's convergence): it is given up and measured as it is. ``history``
    holds ``(largest error, failing spans)`` of every round."""
    if len(history) <= _STALL_ROUNDS or history[-1][0] <= target:
        return False
    (error, failing), (before, failing_before) = history[-1], history[-1 - _STALL_ROUNDS]
    return error > 0.5 * before and failing >= failing_before


def _pieces(error: NDArray, target: float) -> NDArray:
    """Into how many pieces a failing span is cut: ``sqrt(error / target)`` (the error of
    a C2 cubic across a kink in the second derivative, where a surface's parametrization
    is only C1, falls only as ``h^2``), 2 to ``_MAX_PIECES``."""
    ratio = np.maximum(error / target, 1.0)
    return np.clip(np.ceil(np.sqrt(ratio)), 2, _MAX_PIECES).astype(np.int64)


def _middle_samples(w: VerificationState, bad: NDArray, pieces: NDArray, span_of: NDArray, ends: NDArray,
                    arc: NDArray) -> tuple[NDArray, NDArray]:
    """Dense samples that split failing spans in two: for every span of ``bad`` to be cut
    in 2 pieces, the left-out converged dense sample nearest its middle (by arc length),
    if within ``MIDDLE_SHARE`` of it. Returns the dense indices taken and a ``(len(bad),)``
    mask of the spans they split (all spans at once)."""
    covered = np.zeros(bad.size, dtype=bool)
    halves = bad[pieces == 2]
    if halves.size == 0:
        return np.zeros(0, dtype=np.int64), covered
    wanted = np.zeros(max(int(span_of.max()), int(halves.max())) + 2, dtype=bool)
    wanted[halves] = True
    cand = np.flatnonzero(~w.kept & w.converged & wanted[span_of])
    if cand.size == 0:
        return np.zeros(0, dtype=np.int64), covered
    j = span_of[cand]
    a0, a1 = arc[ends[j]], arc[ends[j + 1]]
    frac = np.where(a1 > a0, (arc[cand] - a0) / np.where(a1 > a0, a1 - a0, 1.0), 0.5)
    dev = np.abs(frac - 0.5)
    order = np.lexsort((dev, j))                     # per span, the nearest first (stable)
    first = np.concatenate([[True], np.diff(j[order]) != 0])
    best = order[first]
    best = best[dev[best] <= MIDDLE_SHARE]
    covered = np.isin(bad, j[best]) & (pieces == 2)
    return cand[best], covered


def verification_round(works: list[VerificationState], surface_a, surface_b, target: float, tol: float,
                       tangent_sin: float, refiner: Refiner = refine_points) -> None:
    """One verification round over all unfinished curves (module docstring, step 2)."""
    todo = [w for w in works if not w.done]
    checks = _checks(todo, tol)
    for w, check in zip(todo, checks):
        if check is None:
            w.done, w.degenerate = True, True
    todo = [w for w, check in zip(todo, checks) if check is not None]
    checks = [check for check in checks if check is not None]
    if not todo:
        return
    errors = _check_errors(checks, surface_a, surface_b)
    jobs = []        # per curve: work, span start / stop (dense), parameters of the pieces
    curves = []      # per job: its check (the stacked interpolant)
    for w, check, error in zip(todo, checks, errors):
        error = _span_errors_now(w, check, error)
        w.error = float(np.nanmax(error)) if error.size else 0.0
        bad, error, off, ends, span_of, arc, can = _failing_spans(w, check, error, target, tol,
                                                             surface_a, surface_b)
        w.history.append((w.error, bad.size + off.size))
        if _stalled(w.history, target):         # near-tangential: splitting does not help
            w.done = True
            if w.error <= tol:                  # within the contract all the same
                w.result = check
            continue
        t = check.t
        dt = np.diff(t)
        planned = np.ones(dt.size, dtype=np.int64)
        cut = np.full(dt.size, np.nan)
        if bad.size == 0 and off.size == 0 and not np.any(_graded(dt, planned, cut, w.closed,
                                                                  can) > 1):
            w.done = True
            w.result = check
            continue
        pieces = _pieces(error, target)
        taken, covered = _middle_samples(w, bad, pieces, span_of, ends, arc)
        planned[bad[~covered]] = pieces[~covered]
        for idx in (off, taken):                 # spans split at a kept dense sample
            j = span_of[idx]
            a0, a1 = arc[ends[j]], arc[ends[j + 1]]
            cut[j] = (arc[idx] - a0) / np.where(a1 > a0, a1 - a0, 1.0)
        split = _graded(dt, planned, cut, w.closed, can)
        w.kept[off] = True
        w.fresh[off] = True
        w.kept[taken] = True
        w.fresh[taken] = True
        span = np.flatnonzero(split > 1)
        if span.size:
            inner = split[span] - 1                     # new samples per span
            count = np.repeat(split[span], inner)
            local = np.arange(inner.sum()) - np.repeat(np.cumsum(inner) - inner, inner) + 1
            span = np.repeat(span, inner)
            jobs.append((w, ends[span], ends[span + 1], t[span] + local / count * dt[span]))
            curves.append(check)
    if not jobs:
        return
    at = curves[0].curves.evaluate(np.concatenate([np.full(j[3].size, c.index)
                                                   for j, c in zip(jobs, curves)]),
                                   np.concatenate([j[3] for j in jobs]))
    new = refiner(surface_a, surface_b, at[:, 3:5], at[:, 5:7], tol=POINT_SHARE * tol,
                  anchors=at[:, :3], tangent_sin=tangent_sin)
    offset = 0
    for w, start, stop, _ in jobs:
        sl = slice(offset, offset + start.size)
        offset += start.size
        inside, after, frac = _place(w, start, stop, new.points[sl])
        ok = (new.gap[sl] <= _ACCEPT * tol) & inside   # refined to tol / 16, or nearly
        # two pieces of one span that slid onto each other: the first only
        order = np.lexsort((frac, start))
        same = np.zeros(start.size, dtype=bool)
        same[order[1:]] = (start[order[1:]] == start[order[:-1]]) & \
            (np.diff(frac[order]) < _INSIDE)
        ok &= ~same
        failed = np.setdiff1d(start[~ok], start[ok])
        w.stuck[failed] = True                       # no piece of the span could be placed
        if np.any(ok):
            order = np.lexsort((frac[ok], after[ok]))
            _insert(w, after[ok][order], new.points[sl][ok][order], new.uv_a[sl][ok][order],
                    new.uv_b[sl][ok][order], new.singular[sl][ok][order])
