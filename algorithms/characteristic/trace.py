"""Tracing intersection curves ``phi(u, v) = 0`` from start points (002 eq. 33, §6.3 step 4).

From each start the curve is traced one way by :func:`.curves.trace_curves`
with the tangent of eq. (33) and the Newton corrector; if it does not close,
the other way too, and the two halves are joined. A trace ends where the curve
closes, on a side of ``r``'s domain, or where its image leaves ``q``'s domain
(a border point of ``q``'s boundary curve, §6.2).

Every end on a domain side is solved again with that side's parameter held
(:func:`.points.solve_held`); the traced samples then go through the cubic
sampling of the triangle method (:func:`..intersection.result.checked_curves`,
all curves of a round in one batch), and spans whose interpolants still stray
by more than ``tol`` get refined midpoints (:func:`refine_points`), so the result is an
:class:`~surfprep.algorithms.intersection.IntersectionCurve` with the same
contract as the triangle method's.

Singular points (002 §4, §6.2) on the traces are handled by
:mod:`.singular` (``trace_intersections(..., branches=True)``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ...errors import InvalidGeometryError
from ..intersection import (
    EndKind,
    IntersectionCurve,
    RefinedCurve,
    refine_points,
)
from ..intersection import result as _result
from ..intersection.splines import SplineSet
from .curves import INTERSECTION_MAX_STEPS, CurveKind, EndReason, TracedCurve, curve_value, trace_curves
from .distance import DistanceField
from .points import solve_held
from .singular import continue_at_singular_points

__all__ = [
    "dense_polyline",
    "polyline_gap",
    "to_intersection_curve",
    "to_intersection_curves",
    "trace_intersections",
]

#: rounds of midpoint insertion at most
_SPLIT_ROUNDS = 8


def trace_intersections(field: DistanceField, uv: NDArray, st: NDArray, scale: NDArray, *,
                        tol: float, h_max: float | None = None, branches: bool = False
                        ) -> list[TracedCurve]:
    """Trace the intersection curve through each start ``uv (m, 2)`` (feet ``st``).

    ``scale (m,)`` is the size of the feature each start belongs to (parameter
    units: a loop's radius estimate); the first step is a tenth of it, so loops
    far smaller than the domain are traced with steps to match. The corrector
    runs until ``|phi| <= tol / 16`` (a parameter step below ``tol / (16 |r_u|)``),
    so every sample lies within ``tol / 16`` of both surfaces: the samples are
    refined points of the intersection already.

    With ``branches`` the traces are split at the singular points they meet and
    every branch through those is traced too (:func:`continue_at_singular_points`);
    the pieces then share their end points, so a caller that drops traces
    starting on an earlier trace must test another sample than the first.
    """
    m = uv.shape[0]
    if m == 0:
        return []
    diag = field.diagonal
    h_max = 0.03 * diag if h_max is None else h_max
    h0 = np.clip(0.1 * np.asarray(scale, float), 1e-7 * diag, h_max)
    jet = field.jet(uv, st)
    _, dg = curve_value(jet, CurveKind.INTERSECTION)
    tangent = np.stack([dg[:, 1], -dg[:, 0]], -1)
    ctol = tol / (16 * field.speed)
    forward = trace_curves(field, CurveKind.INTERSECTION, uv, st, tangent, h0=h0, h_max=h_max,
                           max_steps=INTERSECTION_MAX_STEPS, ctol=ctol)
    again = [i for i, c in enumerate(forward) if not c.closed]
    backward = trace_curves(field, CurveKind.INTERSECTION, uv[again], st[again],
                            -tangent[again], h0=h0[again], h_max=h_max, max_steps=INTERSECTION_MAX_STEPS,
                            ctol=ctol)
    out = list(forward)
    for i, b in zip(again, backward):
        out[i] = forward[i].after(b)
    if not branches:
        return out
    return continue_at_singular_points(field, out, tol=tol, h_max=h_max, ctol=ctol)


def dense_polyline(curve: IntersectionCurve, per_span: int = 32) -> NDArray:
    """``(k, 3)`` points of the curve's 3D interpolant, ``per_span`` per span (its
    samples when it has none): a polyline whose chords follow the curve closely."""
    if curve.curve3d is None:
        return curve.points
    t = curve.parameters
    s = np.arange(per_span) / per_span
    dense = (t[:-1, None] + s[None, :] * np.diff(t)[:, None]).ravel()
    if not curve.closed:
        dense = np.append(dense, t[-1])
    return curve.curve3d.evaluate(dense)


def curve_gap(points: NDArray, curves: list[IntersectionCurve], per_span: int = 64,
              k: int = 3, within: float | NDArray | None = None) -> NDArray:
    """Distance ``(n,)`` from each of ``points (n, 3)`` to the nearest of ``curves``,
    measured on their 3D interpolants: the spans next to the ``k`` nearest samples
    (a k-d tree over all samples) are evaluated at ``per_span`` points each.

    ``within`` (a scalar or ``(n,)``): a point for which a closest-point Newton on
    the interpolant from its nearest sample already finds a curve point within it
    gets that distance (an upper bound of the gap: the point found lies on the
    curve) and skips the dense sampling; a caller that only asks ``gap <= within``
    gets the same answer for less."""
    if not curves or points.shape[0] == 0:
        return np.full(points.shape[0], np.inf)
    from scipy.spatial import cKDTree
    owner = np.concatenate([np.full(c.points.shape[0], i) for i, c in enumerate(curves)])
    local = np.concatenate([np.arange(c.points.shape[0]) for c in curves])
    k = min(k, owner.size)
    _, idx = cKDTree(np.concatenate([c.points for c in curves])).query(points, k=k)
    idx = idx.reshape(points.shape[0], k)
    best = np.full(points.shape[0], np.inf)
    if within is not None:
        best = _newton_gap(points, curves, owner[idx[:, 0]], local[idx[:, 0]])
        undecided = np.flatnonzero(~(best <= np.broadcast_to(within, best.shape)))
        if undecided.size == 0:
            return best
        best[undecided] = np.minimum(best[undecided], curve_gap(points[undecided], curves,
                                                                 per_span, k))
        return best
    s = np.linspace(0.0, 1.0, per_span + 1)
    for i, curve in enumerate(curves):
        rows, cols = np.nonzero(owner[idx] == i)
        if rows.size == 0:
            continue
        n = curve.points.shape[0]
        spans = curve.parameters.size - 1
        sample = local[idx[rows, cols]]
        span = np.concatenate([sample - 1, sample])               # both spans at the sample
        who = np.concatenate([rows, rows])
        if curve.closed:
            span %= spans
        keep = (span >= 0) & (span < spans)
        span, who = span[keep], who[keep]
        if curve.curve3d is None:
            nxt = (span + 1) % n
            chain = curve.points[span][:, None] + s[None, :, None] * (
                curve.points[nxt] - curve.points[span])[:, None]
        else:
            t = curve.parameters
            tt = t[span][:, None] + s[None, :] * (t[span + 1] - t[span])[:, None]
            chain = curve.curve3d.evaluate(tt.ravel()).reshape(tt.shape + (3,))
        a, d = chain[:, :-1], np.diff(chain, axis=1)
        x = points[who][:, None]
        dd = np.einsum("mjc,mjc->mj", d, d)
        w = np.clip(np.einsum("mjc,mjc->mj", x - a, d) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
        gap = np.linalg.norm(a + w[..., None] * d - x, axis=-1).min(axis=1)
        np.minimum.at(best, who, gap)
    return best


def _closest(derivatives, t: NDArray, p: NDArray, lo: NDArray, hi: NDArray,
             iterations: int) -> NDArray:
    """Newton on ``C'(t) . (C(t) - p) = 0`` from ``t (m,)`` for ``p (m, 3)``, clipped to
    ``[lo, hi]``; ``derivatives(t) -> (m, 3, 3)`` gives ``C, C', C''``."""
    for _ in range(iterations):
        d = derivatives(t)
        off = d[:, 0] - p
        f = np.einsum("mc,mc->m", d[:, 1], off)
        df = np.einsum("mc,mc->m", d[:, 2], off) + np.einsum("mc,mc->m", d[:, 1], d[:, 1])
        t = np.clip(t - f / np.where(np.abs(df) > 1e-300, df, 1e-300), lo, hi)
    return t


def _newton_gap(points: NDArray, curves: list[IntersectionCurve], owner: NDArray,
                sample: NDArray, iterations: int = 4) -> NDArray:
    """``(n,)`` distance from each of ``points (n, 3)`` to a point of its curve
    ``owner (n,)`` found by Newton on ``C'(t) . (C(t) - p) = 0`` from the parameter of
    its nearest sample ``sample (n,)``, kept within the two spans next to it (an
    upper bound of the distance to the curve, equal to it once Newton converged).
    The polynomial interpolants of all curves are evaluated together
    (:class:`..intersection.splines.SplineSet`: one compiled call per step)."""
    offsets = np.concatenate([[0], np.cumsum([c.parameters.size for c in curves])])
    params = np.concatenate([c.parameters for c in curves]).astype(float)
    base = offsets[owner]
    lo = params[base + np.maximum(sample - 1, 0)]
    hi = params[base + np.minimum(sample + 1, offsets[owner + 1] - base - 1)]
    t0 = params[base + sample]
    best = np.empty(points.shape[0])
    kind = np.array([0 if c.curve3d is None else 1 + c.curve3d.is_rational for c in curves])
    rows = np.flatnonzero(kind[owner] == 0)              # no interpolant: the sample itself
    if rows.size:
        first = np.concatenate([[0], np.cumsum([c.points.shape[0] for c in curves])])
        samples = np.concatenate([c.points for c in curves])
        best[rows] = np.linalg.norm(samples[first[owner[rows]] + sample[rows]] - points[rows],
                                    axis=1)
    for i in np.flatnonzero(kind == 2):                  # rational: curve by curve
        rows = np.flatnonzero(owner == i)
        c = curves[i].curve3d
        t = _closest(lambda x, c=c: c.derivatives(x, 2), t0[rows], points[rows], lo[rows],
                     hi[rows], iterations)
        best[rows] = np.linalg.norm(c.evaluate(t) - points[rows], axis=1)
    rows = np.flatnonzero(kind[owner] == 1)
    if rows.size:
        index = np.flatnonzero(kind == 1)
        splines = SplineSet.of([curves[i].curve3d for i in index])
        which = np.searchsorted(index, owner[rows])
        t = _closest(lambda x: splines.derivatives(which, x, 2), t0[rows], points[rows],
                     lo[rows], hi[rows], iterations)
        best[rows] = np.linalg.norm(splines.evaluate(which, t) - points[rows], axis=1)
    return best


def polyline_gap(points: NDArray, polylines: list[NDArray], closed: list[bool],
                 k: int = 8) -> NDArray:
    """Distance ``(n,)`` from each of ``points (n, d)`` to the nearest segment of the
    polylines (the ``k`` segments with the nearest midpoints, by a k-d tree)."""
    if not polylines or points.shape[0] == 0:
        return np.full(points.shape[0], np.inf)
    from scipy.spatial import cKDTree
    a, b = [], []
    for p, c in zip(polylines, closed):
        q = np.vstack([p, p[:1]]) if c else p
        if q.shape[0] < 2:
            q = np.vstack([q, q])
        a.append(q[:-1])
        b.append(q[1:])
    a, b = np.concatenate(a), np.concatenate(b)
    d = b - a
    k = min(k, a.shape[0])
    _, idx = cKDTree(a + 0.5 * d).query(points, k=k)
    idx = idx.reshape(points.shape[0], k)
    pa, pd = a[idx], d[idx]
    dd = np.einsum("nkc,nkc->nk", pd, pd)
    t = np.clip(np.einsum("nkc,nkc->nk", points[:, None] - pa, pd) / np.where(dd > 0, dd, 1.0),
                0.0, 1.0)
    return np.linalg.norm(pa + t[..., None] * pd - points[:, None], axis=-1).min(axis=1)


def _held_side(uv: NDArray, lower: NDArray, upper: NDArray) -> tuple[int, float]:
    """``(coordinate, value)`` of the domain side nearest to ``uv (2,)``."""
    gaps = np.array([uv[0] - lower[0], upper[0] - uv[0], uv[1] - lower[1], upper[1] - uv[1]])
    k = int(np.argmin(np.abs(gaps)))
    coord = k // 2
    return coord, float(lower[coord] if k % 2 == 0 else upper[coord])


def _fix_ends(field: DistanceField, traced: TracedCurve, uv_a: NDArray, uv_b: NDArray,
              tol: float) -> tuple[NDArray, NDArray]:
    """Solve each BOUNDARY end again on its side (r's side, or q's for a lost projection)."""
    a, b = (field.q, field.r) if field.swapped else (field.r, field.q)
    uv_a, uv_b = uv_a.copy(), uv_b.copy()
    for end, reason in ((0, traced.start_reason), (-1, traced.end_reason)):
        if reason not in (EndReason.DOMAIN, EndReason.PROJECTION):
            continue
        on_q = reason is EndReason.PROJECTION
        surface_is_b = on_q != field.swapped
        side_uv = uv_b[end] if surface_is_b else uv_a[end]
        dom = (b if surface_is_b else a).domain
        coord, value = _held_side(side_uv, np.array(dom[0::2]), np.array(dom[1::2]))
        ua, ub, ok = solve_held(a, b, uv_a[end][None], uv_b[end][None], np.array([int(surface_is_b)]),
                                np.array([coord]), np.array([value]), tol / 16)
        if ok[0]:
            uv_a[end], uv_b[end] = ua[0], ub[0]
    return uv_a, uv_b


def _split_failing(curve: IntersectionCurve, a, b, tol: float) -> IntersectionCurve | None:
    """Refined midpoints inserted in spans whose interpolants stray by more than ``tol``."""
    to_a, to_b, gap = curve.span_deviation(a, b)
    bad = np.flatnonzero(np.nan_to_num(np.maximum(np.maximum(to_a, to_b), gap)) > tol)
    if bad.size == 0:
        return None
    n = curve.points.shape[0]
    nxt = (bad + 1) % n
    mid = refine_points(a, b, 0.5 * (curve.uv_a[bad] + curve.uv_a[nxt]),
                        0.5 * (curve.uv_b[bad] + curve.uv_b[nxt]), tol=tol / 16,
                        anchors=0.5 * (curve.points[bad] + curve.points[nxt]))
    ok = mid.converged
    if not ok.any():
        return None
    bad = bad[ok]
    order = np.argsort(np.concatenate([2 * np.arange(n), 2 * bad + 1]), kind="stable")

    def merged(x, y):
        return np.concatenate([x, y])[order]

    return IntersectionCurve.from_samples(
        merged(curve.points, mid.points[ok]), merged(curve.uv_a, mid.uv_a[ok]),
        merged(curve.uv_b, mid.uv_b[ok]), curve.closed, curve.start_kind, curve.end_kind,
        singular=merged(curve.singular, mid.singular[ok]))


def _closing_count(uv: NDArray) -> int:
    """Samples of a closed trace to keep: the last ones that reach or pass the start
    (ahead of it along the first step, or closer than half of it) are dropped, so
    the closing chord runs forward."""
    first = uv[1] - uv[0]
    step = float(np.linalg.norm(first))
    n = uv.shape[0]
    while n > 3:
        d = uv[n - 1] - uv[0]
        if float(d @ first) > 0 or float(np.linalg.norm(d)) < 0.5 * step:
            n -= 1
        else:
            break
    return n


def _end_kind(reason: EndReason) -> EndKind:
    if reason in (EndReason.DOMAIN, EndReason.PROJECTION):
        return EndKind.BOUNDARY
    if reason is EndReason.SINGULAR:
        return EndKind.BIFURCATION
    return EndKind.OPEN


def _dense_trace(field: DistanceField, traced: TracedCurve, tol: float
                 ) -> tuple[RefinedCurve, tuple[EndKind, EndKind]] | None:
    """A traced ``phi = 0`` curve as dense samples on both surfaces (closing overlap and
    repeated points dropped, ends on sides solved again) with its end kinds; None
    when too short."""
    uv_a, uv_b = field.ab(traced.uv, traced.st)
    closed = traced.closed
    if closed:                  # the trace ends back near its start: drop the overlap
        n = _closing_count(traced.uv)
        uv_a, uv_b = uv_a[:n], uv_b[:n]
    a, b = field.pair()
    pts = a.evaluate(uv_a[:, 0], uv_a[:, 1])
    keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-3 * tol])
    ua, ub = uv_a[keep], uv_b[keep]
    if ua.shape[0] < 2 + closed:
        return None
    if not closed:
        ua, ub = _fix_ends(field, traced, ua, ub, tol)
    pts = 0.5 * (a.evaluate(ua[:, 0], ua[:, 1]) + b.evaluate(ub[:, 0], ub[:, 1]))
    step = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    keep = np.concatenate([[True], step > 1e-3 * tol])
    if not closed and not keep[-1]:          # keep the solved end, drop its neighbour
        keep[-1], keep[-2] = True, pts.shape[0] <= 2
    pts, ua, ub = pts[keep], ua[keep], ub[keep]
    if pts.shape[0] < 2 + closed:
        return None
    kinds = ((EndKind.CLOSED, EndKind.CLOSED) if closed else
             (_end_kind(traced.start_reason), _end_kind(traced.end_reason)))
    flags = np.ones(pts.shape[0], dtype=bool)
    return RefinedCurve(pts, ua, ub, closed, flags, ~flags), kinds


def _sampled(dense: list, a, b, tol: float, refiner=None) -> list:
    """``(curve or None, largest check error)`` per dense curve: all sampled in one
    batch (:func:`..intersection.result.checked_curves`); a batch that fails is
    sampled curve by curve, so one bad curve costs only itself."""
    try:
        curves, worst = _result.checked_curves([d for d, _ in dense], [k for _, k in dense],
                                               a, b, tol=tol, aligned=True, refiner=refiner)
        return list(zip(curves, worst))
    except InvalidGeometryError:
        if len(dense) == 1:
            return [(None, float("nan"))]
    return [_sampled([d], a, b, tol, refiner)[0] for d in dense]


def to_intersection_curves(field: DistanceField, traced: list[TracedCurve], tol: float, *,
                           within_tol: bool = False, refiner=None
                           ) -> list[IntersectionCurve | None]:
    """Traced ``phi = 0`` curves refined to ``tol`` (module docstring), sampled in one
    batch; None for a curve too short, and with ``within_tol`` for one whose
    interpolants stray beyond ``tol`` (measured only where the sampling's own check did
    not pass). A curve whose check found a span over ``tol`` gets refined midpoints
    there (a few rounds). ``refiner``: how new samples are put on the curve
    (:func:`..intersection.sampling.cubic_samples`; e.g. :func:`.ridges.ridge_refiner`)."""
    a, b = field.pair()
    dense = [_dense_trace(field, t, tol) for t in traced]
    live = [i for i, d in enumerate(dense) if d is not None]
    out: list[IntersectionCurve | None] = [None] * len(traced)
    for i, (curve, worst) in zip(live, _sampled([dense[i] for i in live], a, b, tol, refiner)
                                 if live else []):
        if curve is not None and not worst <= tol:     # NaN: not verified as sampled
            for _ in range(_SPLIT_ROUNDS):
                split = _split_failing(curve, a, b, tol)
                if split is None:
                    break
                curve = split
            if within_tol and not curve.max_deviation(a, b).max <= tol:
                curve = None
        out[i] = curve
    return out


def to_intersection_curve(field: DistanceField, traced: TracedCurve, tol: float
                          ) -> IntersectionCurve | None:
    """One traced ``phi = 0`` curve refined to ``tol`` (:func:`to_intersection_curves`)."""
    return to_intersection_curves(field, [traced], tol)[0]
