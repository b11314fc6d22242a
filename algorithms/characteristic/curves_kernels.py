"""The tracer of :mod:`.curves` compiled: every step of every curve in one numba call.

:func:`.curves.trace_curves` batches the curves of a call, but each step still
costs some fifty small numpy operations (predictor, side clipping, the Newton
corrector's rounds, the acceptance test, the per-curve bookkeeping): on the
benchmark pairs the certificate spent about half its time there, for jets of a
few dozen points. :func:`trace_compiled` runs the same steps, stops and end
reasons curve by curve in one compiled pass, with :func:`.distance_kernels.jet_rows`
(the distance jet, 002 eqs. 24-31) at one point per evaluation:

* predictor ``x + h t + h^2 / 2 bend``, shortened to land on a side it would
  cross (then pinned there: the corrector moves along the side only);
* foot guess by eq. (21), ``st + (K^{-1} G) dx``;
* Newton corrector along ``grad g`` (``_CORRECTOR`` rounds, step capped at the
  diagonal), converged within ``min(ctol, relative_ctol h)``;
* accepted when converged, the foot still projects (§6.2 case 3), the tangent
  turns by at most ``max_turn`` and the corrector moved under ``h / 2 + ctol``;
  otherwise the step is halved, down to ``h_min``.

The result is what :func:`.curves.trace_curves` returns (its numpy form stays
the reference and the fallback without numba).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..jit import jit
from .distance_kernels import AVAILABLE, jet_rows

__all__ = ["AVAILABLE", "REASONS", "jet", "trace_compiled"]

#: end reason codes of the kernel, in :class:`.curves.EndReason` value names
REASONS = ("domain", "projection", "closed", "singular", "step_limit")
_DOMAIN, _PROJECTION, _CLOSED, _SINGULAR, _STEP_LIMIT = range(5)
#: corrector iterations per step at most (as :mod:`.curves`)
_CORRECTOR = 5


@jit
def jet(rq, pp, o, w, u, v, s0, t0):
    """The jet at ``(u, v)`` (foot seeded at ``(s0, t0)``) into row 0 of the buffers ``o``."""
    uv, st0 = w[11], w[12]
    uv[0, 0], uv[0, 1], st0[0, 0], st0[0, 1] = u, v, s0, t0
    jet_rows(rq[0], rq[1], rq[2], rq[3], rq[4], rq[5], rq[6], rq[7], uv, st0,
              pp[0], pp[1], pp[2], pp[3], pp[4], pp[5], pp[6], pp[7],
              o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7], o[8], o[9],
              w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8], w[9], w[10])


@jit
def _g(o, comp):
    """``g, g_u, g_v`` of the curve ``comp`` (0 ``phi_u``, 1 ``phi_v``, -1 ``phi``)."""
    if comp < 0:
        return o[4][0], o[5][0, 0], o[5][0, 1]
    return o[5][0, comp], o[6][0, comp, 0], o[6][0, comp, 1]


@jit
def _finite_or_zero(x):
    return x if np.isfinite(x) else 0.0


@jit
def _correct(rq, pp, o, w, comp, pin, x0, x1, s0, t0, ctol, diag, r_lo, r_hi):
    """Newton along ``grad g`` (along the side ``pin`` holds, -1 none) from ``(x0, x1)``:
    :func:`.curves.correct` for one point. Returns ``(x0, x1, converged)``; the jet
    at the returned point is in ``o``."""
    jet(rq, pp, o, w, x0, x1, s0, t0)
    converged = False
    for _ in range(_CORRECTOR):
        g, d0, d1 = _g(o, comp)
        if pin < 0:
            norm2 = d0 * d0 + d1 * d1
            if not norm2 > 1e-300:
                norm2 = 1e-300
            dx0, dx1 = -g / norm2 * d0, -g / norm2 * d1
        elif pin == 0:
            dx0, dx1 = 0.0, -g / (d1 if abs(d1) > 1e-300 else 1e-300)
        else:
            dx0, dx1 = -g / (d0 if abs(d0) > 1e-300 else 1e-300), 0.0
        dx0, dx1 = _finite_or_zero(dx0), _finite_or_zero(dx1)
        size = np.sqrt(dx0 * dx0 + dx1 * dx1)
        f = min(1.0, diag / max(size, 1e-300))
        dx0, dx1 = dx0 * f, dx1 * f
        if (size <= ctol and size > 0) or abs(g) == 0:
            converged = True
            break
        x0 = min(max(x0 + dx0, r_lo[0]), r_hi[0])
        x1 = min(max(x1 + dx1, r_lo[1]), r_hi[1])
        jet(rq, pp, o, w, x0, x1, o[3][0, 0], o[3][0, 1])
    return x0, x1, converged and np.isfinite(x0) and np.isfinite(x1)


@jit
def _tangent(o, comp, ref0, ref1):
    """Unit tangent of eqs. (19), (20), (33), oriented along ``(ref0, ref1)``."""
    _, d0, d1 = _g(o, comp)
    t0, t1 = -d1, d0
    norm = max(np.sqrt(t0 * t0 + t1 * t1), 1e-300)
    t0, t1 = t0 / norm, t1 / norm
    if t0 * ref0 + t1 * ref1 < 0:
        t0, t1 = -t0, -t1
    return t0, t1


@jit
def _store(o, x0, x1, k, j, uv, st, phi, grad, det):
    uv[k, j, 0], uv[k, j, 1] = x0, x1
    st[k, j, 0], st[k, j, 1] = o[3][0, 0], o[3][0, 1]
    phi[k, j] = o[4][0]
    grad[k, j, 0], grad[k, j, 1] = o[5][0, 0], o[5][0, 1]
    det[k, j] = o[9][0]


@jit
def _predict(x0, x1, t0, t1, b0, b1, h, r_lo, r_hi):
    """The predictor, shortened to end on a side it would cross: ``(p0, p1, pinned)``."""
    p0, p1 = x0 + h * t0 + 0.5 * h * h * b0, x1 + h * t1 + 0.5 * h * h * b1
    pinned, frac = -1, 1.0
    for coord in range(2):
        xc, pc = (x0, p0) if coord == 0 else (x1, p1)
        d = pc - xc
        for bound, sign in ((r_lo[coord], -1.0), (r_hi[coord], 1.0)):
            if (pc - bound) * sign > 0:
                f = min(max((bound - xc) / (d if d != 0 else 1.0), 0.0), 1.0)
                if f < frac:
                    frac, pinned = f, coord
    p0, p1 = x0 + frac * h * t0, x1 + frac * h * t1
    if pinned == 0:
        p0 = r_lo[0] if abs(p0 - r_lo[0]) < abs(p0 - r_hi[0]) else r_hi[0]
    elif pinned == 1:
        p1 = r_lo[1] if abs(p1 - r_lo[1]) < abs(p1 - r_hi[1]) else r_hi[1]
    return p0, p1, pinned


@jit
def _trace_one(rq, pp, o, w, k, comp, uv0, st0, direction, r_lo, r_hi, diag, h0, h_max,
               h_min, max_steps, ctol, max_turn, relative_ctol, uv, st, phi, grad, det):
    """One curve from start ``k``: samples into row ``k``; returns ``(count, reason)``."""
    x0, x1, _ = _correct(rq, pp, o, w, comp, -1, uv0[k, 0], uv0[k, 1], st0[k, 0], st0[k, 1],
                         ctol, diag, r_lo, r_hi)
    t0, t1 = _tangent(o, comp, direction[k, 0], direction[k, 1])
    _store(o, x0, x1, k, 0, uv, st, phi, grad, det)
    s0, s1 = o[3][0, 0], o[3][0, 1]
    j00, j01, j10, j11 = o[7][0, 0, 0], o[7][0, 0, 1], o[7][0, 1, 0], o[7][0, 1, 1]
    h, b0, b1, a0, a1, length = h0, 0.0, 0.0, x0, x1, 0.0
    steps, reason, attempts = 0, -1, 0
    while reason < 0 and attempts < 20 * max_steps:
        attempts += 1
        p0, p1, pinned = _predict(x0, x1, t0, t1, b0, b1, h, r_lo, r_hi)
        g0 = s0 + j00 * (p0 - x0) + j01 * (p1 - x1)                      # eq. (21)
        g1 = s1 + j10 * (p0 - x0) + j11 * (p1 - x1)
        y0, y1, conv = _correct(rq, pp, o, w, comp, pinned, p0, p1, g0, g1,
                                min(ctol, relative_ctol * h), diag, r_lo, r_hi)
        n0, n1 = _tangent(o, comp, t0, t1)
        cos = n0 * t0 + n1 * t1
        if cos > 1.0:
            cos = 1.0
        elif cos < -1.0:
            cos = -1.0
        turn = np.arccos(cos)
        lost = o[8][0] == 2
        moved = np.sqrt((y0 - p0) ** 2 + (y1 - p1) ** 2)
        if conv and not lost and turn <= max_turn and moved <= 0.5 * h + ctol:
            step = np.sqrt((y0 - x0) ** 2 + (y1 - x1) ** 2)
            b0, b1 = ((n0 - t0) / step, (n1 - t1) / step) if step > 0 else (0.0, 0.0)
            x0, x1, t0, t1 = y0, y1, n0, n1
            s0, s1 = o[3][0, 0], o[3][0, 1]
            j00, j01, j10, j11 = o[7][0, 0, 0], o[7][0, 0, 1], o[7][0, 1, 0], o[7][0, 1, 1]
            steps += 1
            _store(o, x0, x1, k, steps, uv, st, phi, grad, det)
            length += step
            h = min(1.5 * h, h_max)
            back = np.sqrt((x0 - a0) ** 2 + (x1 - a1) ** 2)
            if pinned >= 0:
                reason = _DOMAIN
            elif steps > 3 and back <= 1.2 * h and length > 4 * back:
                reason = _CLOSED
            elif steps >= max_steps:
                reason = _STEP_LIMIT
        else:
            h *= 0.5
            if h < h_min:
                reason = _PROJECTION if lost else _SINGULAR
    return steps + 1, (reason if reason >= 0 else _STEP_LIMIT)


@jit
def buffers(rq):
    """``(o, w)``: one-row jet outputs and the scratch arrays :func:`_jet` takes."""
    o = (np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 2)), np.empty(1),
         np.empty((1, 2)), np.empty((1, 2, 2)), np.empty((1, 2, 2)), np.empty(1, dtype=np.int8),
         np.empty(1))
    width = max(rq[0].shape[2], rq[4].shape[2])
    height = max(rq[0].shape[3], rq[4].shape[3])
    w = (np.empty((3, width)), np.empty((3, height)), np.empty((3, 3, 4)), np.empty((3, 3, 3)),
         np.empty((3, 3, 3)), np.empty((3, 3, 3)), np.empty(3), np.empty(3), np.empty(3),
         np.empty(3), np.empty(3), np.empty((1, 2)), np.empty((1, 2)))
    return o, w


def kernel_arguments(field) -> tuple[tuple, tuple]:
    """``(rq, pp)``: both surfaces' compiled data and the projector's settings for :func:`_jet`."""
    projector = field.projector
    lo, hi, quarter = projector.newton_bounds()
    r, q = field.evaluator.compiled, projector.evaluator.compiled
    rq = (r[0], r[1], r[2], bool(r[3]), q[0], q[1], q[2], bool(q[3]))
    pp = (lo, hi, quarter, float(projector.tol), int(projector.max_iter), projector.lower,
          projector.upper, projector.kernel_frame())
    return rq, pp


@jit
def _trace_all(rq, pp, comps, uv0, st0, direction, h0, r_lo, r_hi, diag, h_max, h_min,
               max_steps, ctol, max_turn, relative_ctol):
    m = uv0.shape[0]
    n = max_steps + 1
    uv, st, grad = np.empty((m, n, 2)), np.empty((m, n, 2)), np.empty((m, n, 2))
    phi, det = np.empty((m, n)), np.empty((m, n))
    count = np.empty(m, dtype=np.int64)
    reason = np.empty(m, dtype=np.int64)
    o, w = buffers(rq)
    for k in range(m):
        count[k], reason[k] = _trace_one(rq, pp, o, w, k, comps[k], uv0, st0, direction, r_lo,
                                         r_hi, diag, h0[k], h_max, h_min, max_steps, ctol,
                                         max_turn, relative_ctol, uv, st, phi, grad, det)
    return uv, st, phi, grad, det, count, reason


def trace_compiled(field, comps: NDArray, uv0: NDArray, st0: NDArray, direction: NDArray, *,
                   h0: NDArray, h_max: float, h_min: float, max_steps: int, ctol: float,
                   max_turn: float, relative_ctol: float
                   ) -> tuple[NDArray, NDArray, NDArray, NDArray, NDArray, NDArray, NDArray]:
    """Trace ``m`` curves (``comps (m,) int``: 0 ``phi_u = 0``, 1 ``phi_v = 0``, -1
    ``phi = 0``) from ``uv0 (m, 2)`` one way each (arguments as
    :func:`.curves.trace_curves`).

    Returns
    -------
    uv, st, grad : (m, max_steps + 1, 2) float
    phi, det_k : (m, max_steps + 1) float
        Samples of curve ``k`` in rows ``[k, :count[k]]``.
    count : (m,) int
    reason : (m,) int
        Index into :data:`REASONS`.
    """
    rq, pp = kernel_arguments(field)
    c = np.ascontiguousarray
    return _trace_all(rq, pp, c(comps, dtype=np.int64), c(uv0, dtype=float),
                      c(st0, dtype=float), c(direction, dtype=float), c(h0, dtype=float),
                      field.lower, field.upper, float(field.diagonal), float(h_max),
                      float(h_min), int(max_steps), float(ctol), float(max_turn),
                      float(relative_ctol))
