"""Singular points on traced curves ``g = 0`` (002 §4, §6.2).

Where a traced curve ``g = 0`` meets a point with ``grad g = 0`` (a double
point of the intersection where the surfaces touch while crossing, or a
self-crossing of a characteristic curve) the tracer of :mod:`.curves` either
stops (``SINGULAR``) or steps over it onto some branch.
:func:`continue_at_singular_points` locates such points (Newton on
``grad g = 0`` from the samples where ``|grad g|`` dips), splits the traces
there (the point becomes an end of kind BIFURCATION), takes the branch
directions from the Hessian of ``g`` (:func:`..intersection.branches.branch_directions`:
two for a double point, none for an isolated point, one for a cusp) and
traces every half-branch no trace has arrived along yet.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..intersection.branches import SingularKind, branch_directions
from .curves import INTERSECTION_MAX_STEPS, CurveKind, EndReason, TracedCurve, curve_value, trace_curves
from .distance import DistanceField

__all__ = ["continue_at_singular_points"]

#: a sample whose ``|grad g|`` is below this share of its trace's median may be
#: next to a singular point
_GRAD_DIP = 0.25
#: singular points whose branches are traced, one per round, at most
_BRANCH_ROUNDS = 8
#: a half-branch counts as traced when a trace arrives within this angle of it
_ARRIVAL_COS = np.cos(np.radians(30.0))
#: a point whose two branches would cross at less than this angle (uv plane) lies on a
#: tangential contact, not at a branch point: ``|lambda_min / lambda_max|`` of its
#: Hessian below ``tan^2(angle / 2)`` (the branches leave along ``d^T H d = 0``)
_MIN_BRANCH_ANGLE = np.radians(1.0)


def _g_hessian(field: DistanceField, kind: CurveKind, jet) -> NDArray:
    """``(m, 2, 2)`` Hessian of ``g``: ``phi``'s (eqs. 26-29) for the intersection; for
    a characteristic curve (``g = phi_u`` or ``phi_v``) central differences of
    the jet's Hessian row."""
    if kind is CurveKind.INTERSECTION:
        return jet.hess
    row = 0 if kind is CurveKind.U_CHARACTERISTIC else 1
    delta = 1e-6 * field.diagonal
    out = np.empty((jet.uv.shape[0], 2, 2))
    for i in range(2):
        e = np.zeros(2)
        e[i] = delta
        plus, minus = field.jet(jet.uv + e, jet.st), field.jet(jet.uv - e, jet.st)
        out[:, i, :] = (plus.hess[:, row, :] - minus.hess[:, row, :]) / (2 * delta)
    return 0.5 * (out + np.swapaxes(out, 1, 2))


def _locate(field: DistanceField, kind: CurveKind, uv: NDArray, st: NDArray, gtol: float,
            iterations: int = 30):
    """Newton on ``grad g = 0`` from ``uv (k, 2)``: the jet at the points found and
    ``ok (k,)`` (converged, inside, a unique foot, ``|g| <= gtol``)."""
    x = uv.copy()
    jet = field.jet(x, st)
    for _ in range(iterations):
        _, dg = curve_value(jet, kind)
        h = _g_hessian(field, kind, jet)
        ok = np.abs(np.linalg.det(h)) > 1e-300
        step = np.zeros_like(x)
        if ok.any():
            step[ok] = -np.linalg.solve(h[ok], dg[ok][..., None])[..., 0]
        x = np.clip(x + step, field.lower, field.upper)
        jet = field.jet(x, jet.st)
        if np.all(np.linalg.norm(step, axis=1) <= 1e-13 * field.diagonal):
            break
    g, dg = curve_value(jet, kind)
    h = _g_hessian(field, kind, jet)
    small = np.linalg.norm(dg, axis=1) <= 1e-9 * np.abs(h).max(axis=(1, 2)) * field.diagonal
    from .projector import ProjectionStatus
    ok = small & (np.abs(g) <= gtol) & (jet.status == ProjectionStatus.UNIQUE)
    return jet, h, ok


def _candidates(field: DistanceField, curve: TracedCurve) -> NDArray:
    """Sample indices where ``|grad g|`` dips (local minima below ``_GRAD_DIP`` of the
    median) and the end samples of a trace that stopped SINGULAR. (A trace
    stores ``grad phi``; for a characteristic curve ``grad g`` is a row of the
    Hessian, from one batched jet.)"""
    if curve.kind is CurveKind.INTERSECTION:
        norm = np.linalg.norm(curve.grad, axis=1)
    else:
        norm = np.linalg.norm(curve_value(field.jet(curve.uv, curve.st), curve.kind)[1], axis=1)
    out = []
    if norm.size >= 3:
        inner = np.flatnonzero((norm[1:-1] <= norm[:-2]) & (norm[1:-1] <= norm[2:])) + 1
        out.extend(inner[norm[inner] < _GRAD_DIP * np.median(norm)])
    if curve.end_reason is EndReason.SINGULAR:
        out.append(curve.uv.shape[0] - 1)
    if curve.start_reason is EndReason.SINGULAR:
        out.append(0)
    return np.unique(np.array(out, dtype=int))


def _rows(curve: TracedCurve, idx) -> list:
    return [curve.uv[idx], curve.st[idx], curve.phi[idx], curve.grad[idx], curve.det_k[idx]]


def _at(field: DistanceField, point: list, st_near: NDArray) -> list:
    """The point's rows ``[uv, st, phi, grad, det_k]`` with its foot projected again
    from ``st_near`` (a neighbouring sample's): on that side of a seam of ``q``."""
    jet = field.jet(point[0][None], st_near[None])
    return [point[0], jet.st[0], jet.phi[0], jet.grad[0], jet.projection.det_k[0]]


def _make(kind: CurveKind, rows: list, start: EndReason, end: EndReason) -> TracedCurve:
    return TracedCurve(kind, *rows, start, end)


def _split(field: DistanceField, curve: TracedCurve, point: list, reach: float
           ) -> list[TracedCurve] | None:
    """``curve`` cut at the singular point ``point = [uv, st, phi, grad, det_k]`` (each
    one row), which becomes an end (reason SINGULAR) of both parts; None when the
    curve does not pass within ``reach`` of it (uv units)."""
    uv = curve.uv
    if curve.closed:
        uv = np.vstack([uv, uv[:1]])
    d = np.linalg.norm(uv - point[0], axis=1)
    if d.min() > reach:
        return None
    if uv.shape[0] >= 2:
        a, b = uv[:-1], uv[1:]
        w = np.clip(np.einsum("ij,ij->i", point[0] - a, b - a)
                    / np.maximum(np.einsum("ij,ij->i", b - a, b - a), 1e-300), 0, 1)
        j = int(np.argmin(np.linalg.norm(a + w[:, None] * (b - a) - point[0], axis=1)))
        j = j + 1 if w[j] >= 1 else j          # S lies after sample j
    else:
        j = 0
    n = curve.uv.shape[0]
    near = 1e-9 * max(reach, 1e-300)
    rows = _rows(curve, slice(None))
    if curve.closed:
        order = np.roll(np.arange(n), -(j + 1) % n)
        rows = [r[order] for r in rows]
        keep = np.linalg.norm(rows[0] - point[0], axis=1) > near
        rows = [r[keep] for r in rows]
        head, tail = _at(field, point, rows[1][0]), _at(field, point, rows[1][-1])
        rows = [np.concatenate([p[None], r, q[None]]) for p, r, q in zip(head, rows, tail)]
        return [_make(curve.kind, rows, EndReason.SINGULAR, EndReason.SINGULAR)]
    out = []
    before = [r[:j + 1] for r in rows]
    after = [r[j + 1:] for r in rows]
    for part, first in ((before, False), (after, True)):
        keep = np.linalg.norm(part[0] - point[0], axis=1) > near
        if not keep.any():
            continue
        part = [r[keep] for r in part]
        here = _at(field, point, part[1][0 if first else -1])
        part = [np.concatenate([p[None], r]) if first else
                np.concatenate([r, p[None]]) for p, r in zip(here, part)]
        if first:
            out.append(_make(curve.kind, part, EndReason.SINGULAR, curve.end_reason))
        else:
            out.append(_make(curve.kind, part, curve.start_reason, EndReason.SINGULAR))
    return out


def _arrivals(curves: list[TracedCurve], centre: NDArray) -> list[NDArray]:
    """Unit uv directions from ``centre`` along which traces end there."""
    out = []
    for c in curves:
        for end, nxt in ((0, 1), (-1, -2)):
            if c.uv.shape[0] >= 2 and np.linalg.norm(c.uv[end] - centre) == 0:
                d = c.uv[nxt] - centre
                out.append(d / max(np.linalg.norm(d), 1e-300))
    return out


def continue_at_singular_points(field: DistanceField, curves: list[TracedCurve], *, tol: float,
                                h_max: float, ctol: float | None = None) -> list[TracedCurve]:
    """Traces split at the singular points they meet and continued along every branch.

    A singular point of ``g = 0`` has ``g = 0`` and ``grad g = 0`` (002 §4: for
    the intersection ``g = phi``, the surfaces cross with parallel normals; for
    a characteristic curve ``g = phi_u`` or ``phi_v``, it crosses itself). To
    second order ``g = 1/2 d^T H d`` there, so the branches leave along the
    roots of that form (:func:`..intersection.branches.branch_directions`,
    classified by ``det H``: double point, isolated point, cusp).

    Parameters
    ----------
    curves : list of TracedCurve
        The tracer's output (kinds may be mixed: each kind is handled on its own).
    tol : float
        Model units: ``|phi| <= tol`` at a singular point of the intersection
        (for characteristic curves ``|g|`` of about the Hessian times ``1e-6``
        of the domain diagonal).
    h_max, ctol : float
        The tracer's step bound and corrector tolerance (parameter units).

    Returns
    -------
    list of TracedCurve
        The input pieces (split at each singular point, which ends them with
        reason SINGULAR) and the traces of the half-branches nobody arrived
        along, starting at the point (reason SINGULAR).
    """
    kinds = {c.kind for c in curves}
    if len(kinds) > 1:                    # each kind on its own
        return [p for k in CurveKind for p in continue_at_singular_points(
            field, [c for c in curves if c.kind is k], tol=tol, h_max=h_max, ctol=ctol)]
    if not curves:
        return curves
    kind = curves[0].kind
    gtol = tol if kind is CurveKind.INTERSECTION else None
    found: list[list] = []            # singular points, as one-row lists
    pending: list[int] = []
    work = list(curves)
    fresh = list(range(len(work)))
    for _ in range(_BRANCH_ROUNDS + 1):
        work, new_points = _split_at_found(field, kind, work, fresh, found, gtol, h_max)
        pending.extend(range(len(found) - new_points, len(found)))
        if not pending:
            break
        k = pending.pop(0)
        traced = _trace_branches(field, kind, work, found[k], h_max, ctol)
        fresh = list(range(len(work), len(work) + len(traced)))
        work += traced
        if not traced and not pending:
            break
    return work


def _tangential_contact(hess: NDArray) -> NDArray:
    """``(k,) bool``: which Hessians ``(k, 2, 2)`` are those of points on a curve where
    the two surfaces touch, not of branch points. Along such a curve ``grad g``
    vanishes everywhere, so Newton on ``grad g = 0`` converges wherever it starts,
    to a point whose Hessian is of rank one to rounding: its "branches" cross at
    under ``_MIN_BRANCH_ANGLE``. (Faces 43 and 177 of occt_bearing_euclid.iges meet
    tangentially along a side of one of them: 198 such points; splitting 115
    traces at each and tracing their branches took 580 s and added no curve.)"""
    lam = np.linalg.eigvalsh(0.5 * (hess + np.swapaxes(hess, 1, 2)))
    big = np.abs(lam).max(axis=1)
    return np.abs(lam).min(axis=1) < np.tan(0.5 * _MIN_BRANCH_ANGLE) ** 2 * big


def _split_at_found(field: DistanceField, kind: CurveKind, work: list[TracedCurve],
                    fresh: list[int], found: list, gtol: float | None, h_max: float
                    ) -> tuple[list[TracedCurve], int]:
    """New singular points from the candidates of the ``fresh`` traces, appended to
    ``found``; every trace split at every point of ``found`` it passes."""
    uv, st, reach = [], [], []
    for i in fresh:
        c = work[i]
        idx = _candidates(field, c)
        if idx.size:
            uv.append(c.uv[idx])
            st.append(c.st[idx])
            steps = np.linalg.norm(np.diff(c.uv, axis=0), axis=1)
            local = np.maximum(np.concatenate([[0], steps])[idx], np.concatenate([steps, [0]])[idx])
            reach.append(np.maximum(2 * local, 1e-6 * field.diagonal))
    new = 0
    if uv:
        uv, st, reach = np.concatenate(uv), np.concatenate(st), np.concatenate(reach)
        jet, hess, ok = _locate(field, kind, uv, st, np.inf if gtol is None else gtol)
        if gtol is None:          # characteristic: |g| small against the Hessian
            g, _ = curve_value(jet, kind)
            ok &= np.abs(g) <= 1e-6 * np.abs(hess).max(axis=(1, 2)) * field.diagonal
        ok &= np.linalg.norm(jet.uv - uv, axis=1) <= reach
        ok &= ~_tangential_contact(hess)
        for i in np.flatnonzero(ok):
            if any(np.linalg.norm(f[0] - jet.uv[i]) <= 1e-9 * field.diagonal for f in found):
                continue
            found.append([jet.uv[i], jet.st[i], jet.phi[i], jet.grad[i],
                          jet.projection.det_k[i], hess[i]])
            new += 1
    if not found:
        return work, new
    # each trace is split once at each point: the fresh ones at all points, the others
    # (split in earlier rounds) only at the points new in this one. Splitting them all
    # again every round cut the pieces between 27 clustered points of a ventilator face
    # pair (pyocc_ventilator_catia5.stp faces 235 x 244) into ever more pieces: 60 ->
    # 514951 traces in 7 rounds, the whole-model run stalled there
    fresh_set, first_new = set(fresh), len(found) - new
    out = []
    for k, c in enumerate(work):
        out.extend(_split_in_order(field, c, found if k in fresh_set else found[first_new:],
                                   h_max))
    return out, new


def _reach(curve: TracedCurve, h_max: float) -> float:
    """How far from ``curve`` (uv units) a point may lie and still cut it: twice its
    longest step, at most ``h_max``."""
    steps = np.linalg.norm(np.diff(curve.uv, axis=0), axis=1)
    return min(2 * float(steps.max(initial=0.0)), h_max)


def _first_cut(curve: TracedCurve, centres: NDArray, reach: float) -> int | None:
    """Index of the first of ``centres (m, 2)`` that cuts ``curve`` (:func:`_split`
    would not return None: a sample within ``reach``) and is not one of its end
    samples; None when none does."""
    uv = curve.uv
    if curve.closed:
        uv = np.vstack([uv, uv[:1]])
    low, high = uv.min(axis=0) - reach, uv.max(axis=0) + reach
    near = np.flatnonzero(np.all((centres >= low) & (centres <= high), axis=1))
    if near.size == 0:
        return None
    ends = np.all(centres[near] == curve.uv[0], axis=1) | np.all(centres[near] == curve.uv[-1],
                                                                  axis=1)
    near = near[~ends]
    for chunk in np.array_split(near, max(1, near.size * uv.shape[0] // 2_000_000)):
        if chunk.size == 0:
            continue
        d = np.linalg.norm(centres[chunk, None, :] - uv[None], axis=2).min(axis=1)
        hit = np.flatnonzero(d <= reach)
        if hit.size:
            return int(chunk[hit[0]])
    return None


def _split_in_order(field: DistanceField, curve: TracedCurve, points: list, h_max: float
                    ) -> list[TracedCurve]:
    """``curve`` split at each of ``points`` it passes, in their order: the pieces
    of splitting it at the first (:func:`_split`), each split at the following
    ones, and so on: the pieces of trying every point on every piece one by one,
    with each piece compared with all the points still to come at once (one
    array operation per piece instead of one Python call per piece and point)."""
    if not points:
        return [curve]
    centres = np.array([p[0] for p in points])
    out: list[TracedCurve] = []
    stack = [(curve, 0)]
    while stack:
        piece, start = stack.pop()
        reach = _reach(piece, h_max)
        k = _first_cut(piece, centres[start:], reach) if start < len(points) else None
        if k is None:
            out.append(piece)
            continue
        k += start
        parts = _split(field, piece, points[k][:5], reach)
        stack.extend((p, k + 1) for p in reversed(parts if parts is not None else [piece]))
    return out


def _returns_at(uv: NDArray, centre: NDArray, delta: float) -> int | None:
    """Index of the last sample before the trace ``uv (n, 2)`` (leaving ``centre``)
    first comes back to ``centre``: a chord passing within a quarter of its length
    of it (or a sample within ``delta``), once the trace has been farther than
    ``4 delta``; None if it never does."""
    far = np.flatnonzero(np.linalg.norm(uv - centre, axis=1) > 4 * delta)
    if far.size == 0 or uv.shape[0] < 2:
        return None
    a, d = uv[:-1], np.diff(uv, axis=0)
    dd = np.einsum("ij,ij->i", d, d)
    w = np.clip(np.einsum("ij,ij->i", centre - a, d) / np.maximum(dd, 1e-300), 0, 1)
    gap = np.linalg.norm(a + w[:, None] * d - centre, axis=1)
    hit = np.flatnonzero(((gap <= 0.25 * np.sqrt(dd)) | (gap <= delta))
                         & (np.arange(a.shape[0]) >= far[0]))
    if hit.size == 0:
        return None
    k = int(hit[0])
    return k if w[k] < 1 else k + 1


def _trace_branches(field: DistanceField, kind: CurveKind, work: list[TracedCurve],
                    point: list, h_max: float, ctol: float | None) -> list[TracedCurve]:
    """Traces from the singular point ``point`` along its half-branches that no trace
    arrives along, one at a time (a trace coming back to the point, as a lobe
    of a figure eight, ends there and covers the half-branch it arrives along);
    each starts with the point itself."""
    kinds, dirs = branch_directions(point[5][None])
    if kinds[0] is SingularKind.DOUBLE_POINT:
        halves = np.concatenate([dirs[0], -dirs[0]])
    elif kinds[0] is SingularKind.CUSP:
        halves = np.stack([dirs[0, 0], -dirs[0, 0]])
    else:
        return []
    delta = min(1e-3 * field.diagonal, 0.1 * h_max)
    out: list[TracedCurve] = []
    for d in halves:
        arrived = _arrivals(work + out, point[0])
        if any(d @ a >= _ARRIVAL_COS for a in arrived):
            continue
        start = np.clip(point[0] + delta * d, field.lower, field.upper)[None]
        t = trace_curves(field, kind, start, point[1][None], d[None], h0=delta, h_max=h_max,
                         max_steps=INTERSECTION_MAX_STEPS, ctol=ctol)[0]
        if t.uv.shape[0] < 2 or (t.uv[1] - point[0]) @ d <= 0:   # fell back onto the point
            continue
        rows = _rows(t, slice(None))
        end = t.end_reason
        back = _returns_at(t.uv, point[0], delta)
        if back is None and end is EndReason.CLOSED:     # stopped short of the point
            back = t.uv.shape[0] - 1
        if back is not None:                   # came back to the point: ends there
            rows = [r[:back + 1] for r in rows]
            rows = [np.concatenate([r, p[None]])
                    for p, r in zip(_at(field, point, rows[1][-1]), rows)]
            end = EndReason.SINGULAR
        rows = [np.concatenate([p[None], r]) for p, r in zip(_at(field, point, rows[1][0]), rows)]
        out.append(_make(kind, rows, EndReason.SINGULAR, end))
    return out


