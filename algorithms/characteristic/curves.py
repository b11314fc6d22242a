"""Tracing implicit curves of the distance function (002 §6.1, eqs. 15-21 and 32-33).

One tracer serves the three kinds of curve:

====================  ===============  ====================================
kind                  ``g(u, v) = 0``  tangent ``(du, dv) / dw``
====================  ===============  ====================================
u-characteristic      ``phi_u``        ``± (-phi_uv, phi_uu) / |.|``  (19)
v-characteristic      ``phi_v``        ``± (phi_vv, -phi_uv) / |.|``  (20)
intersection          ``phi``          ``(phi_v, -phi_u) / |.|``      (33)
====================  ===============  ====================================

``w`` is arc length in ``r``'s parameter plane; the image on ``q`` follows
from the projection at every sample (eq. 21 is its derivative, used as the
continuation guess of the foot). The integrator is an explicit Euler predictor
with adaptive step and a Newton corrector along ``grad g`` (the paper: "the
Newton-Raphson corrector often converges at once"): a step is accepted when
the corrector converges within ``ctol`` and the tangent turns by less than
``MAX_TURN``; otherwise it is halved. A step that would leave ``r``'s domain
is shortened to end on the side, where the corrector moves along the side only.
A curve ends on a side (``DOMAIN``), where ``q``'s foot leaves ``q``'s domain
(``PROJECTION``, §6.2 case 3, the step halved down to ``h_min`` first), back at
its start (``CLOSED``), where the corrector fails at the smallest step
(``SINGULAR``: ``grad g = 0``, §6.2), or after ``max_steps`` (``STEP_LIMIT``: a
cap, never a hang). A sign change of ``det K`` between two samples is counted
as a crossing of the cut locus (§6.2 case 2).

All curves given are traced at once: every step is one batched evaluation.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from . import curves_kernels
from .distance import DistanceField, DistanceJet
from .projector import Projection, ProjectionStatus

__all__ = [
    "INTERSECTION_MAX_STEPS",
    "MAX_TURN",
    "CurveKind",
    "EndReason",
    "TracedCurve",
    "correct",
    "curve_value",
    "trace_curves",
]

#: accepted steps per traced intersection curve at most (a cap: never a hang; the
#: characteristic curves take ``max_steps`` of :func:`trace_curves`)
INTERSECTION_MAX_STEPS = 4000
#: largest turn of the tangent per accepted step (radians)
MAX_TURN = 0.3
#: the corrector stops within this share of the step (and within ``ctol``)
RELATIVE_CTOL = 1e-4
#: corrector iterations per step at most
_CORRECTOR = 5


class CurveKind(enum.Enum):
    """Which implicit curve of ``phi``."""

    U_CHARACTERISTIC = "u"          # phi_u = 0 (eq. 13)
    V_CHARACTERISTIC = "v"          # phi_v = 0 (eq. 14)
    INTERSECTION = "intersection"   # phi = 0 (eq. 5)


class EndReason(enum.Enum):
    """Why a traced curve stopped."""

    DOMAIN = "domain"               # reached a side of r's domain
    PROJECTION = "projection"       # the foot left q's domain (no projection)
    CLOSED = "closed"               # came back to its start
    SINGULAR = "singular"           # the corrector fails at the smallest step
    STEP_LIMIT = "step_limit"       # max_steps reached (a cap)
    START = "start"                 # the other end of a one-way trace


@dataclass(frozen=True)
class TracedCurve:
    """One traced curve, samples in order.

    Attributes
    ----------
    kind : CurveKind
    uv : (n, 2) float
        On ``r``'s domain.
    st : (n, 2) float
        Feet on ``q``.
    phi : (n,) float
    grad : (n, 2) float
        ``(phi_u, phi_v)`` at the samples.
    det_k : (n,) float
    start_reason, end_reason : EndReason
    """

    kind: CurveKind
    uv: NDArray
    st: NDArray
    phi: NDArray
    grad: NDArray
    det_k: NDArray
    start_reason: EndReason
    end_reason: EndReason

    @property
    def closed(self) -> bool:
        return self.end_reason is EndReason.CLOSED

    @property
    def cut_locus_crossings(self) -> int:
        """Sign changes of ``det K`` between samples (§6.2 case 2)."""
        return int(np.count_nonzero(np.diff(np.sign(self.det_k)) != 0))

    def reversed(self) -> TracedCurve:
        return TracedCurve(self.kind, self.uv[::-1], self.st[::-1], self.phi[::-1],
                           self.grad[::-1], self.det_k[::-1], self.end_reason, self.start_reason)

    def after(self, backward: TracedCurve) -> TracedCurve:
        """``backward`` (traced the other way from the same start) reversed, then this
        curve: the two halves of one curve, their common start once."""
        b = backward.reversed()
        return TracedCurve(self.kind, np.vstack([b.uv[:-1], self.uv]),
                           np.vstack([b.st[:-1], self.st]),
                           np.concatenate([b.phi[:-1], self.phi]),
                           np.vstack([b.grad[:-1], self.grad]),
                           np.concatenate([b.det_k[:-1], self.det_k]),
                           b.start_reason, self.end_reason)


def _component(kind: CurveKind) -> int:
    return {CurveKind.U_CHARACTERISTIC: 0, CurveKind.V_CHARACTERISTIC: 1,
            CurveKind.INTERSECTION: -1}[kind]


def curve_value(jet: DistanceJet, kind: CurveKind | NDArray) -> tuple[NDArray, NDArray]:
    """``g (m,)`` and ``grad g (m, 2)`` of the curve ``kind`` from a jet.

    ``kind`` may also be ``(m,) int`` per row: 0 for ``phi_u``, 1 for ``phi_v``,
    -1 for ``phi``.
    """
    comp = np.full(jet.phi.shape[0], _component(kind)) if isinstance(kind, CurveKind) else kind
    rows = np.arange(comp.size)
    c = np.maximum(comp, 0)
    inter = comp < 0
    g = np.where(inter, jet.phi, jet.grad[rows, c])
    dg = np.where(inter[:, None], jet.grad, jet.hess[rows, c, :])
    return g, dg


def _tangent(dg: NDArray) -> NDArray:
    """Unit tangents ``(m, 2)`` of eqs. (19), (20), (33) (orientation left to the caller)."""
    t = np.stack([-dg[:, 1], dg[:, 0]], -1)
    return t / np.maximum(np.linalg.norm(t, axis=1), 1e-300)[:, None]


def _assign(jet: DistanceJet, rows: NDArray, sub: DistanceJet) -> DistanceJet:
    """``jet`` with ``rows`` replaced by ``sub`` (a new object; arrays copied)."""
    proj = jet.projection
    parts = {}
    for name, full, part in (("st", proj.st, sub.projection.st), ("foot", proj.foot, sub.projection.foot),
                             ("status", proj.status, sub.projection.status),
                             ("det_k", proj.det_k, sub.projection.det_k)):
        arr = full.copy()
        arr[rows] = part
        parts[name] = arr
    out = {}
    for name in ("uv", "point", "normal", "phi", "grad", "hess", "st_jacobian"):
        arr = getattr(jet, name).copy()
        arr[rows] = getattr(sub, name)
        out[name] = arr
    return DistanceJet(out["uv"], out["point"], Projection(**parts), out["normal"], out["phi"],
                       out["grad"], out["hess"], out["st_jacobian"])


def correct(field: DistanceField, kind: NDArray, uv: NDArray, st: NDArray,
             pinned: NDArray, ctol: float | NDArray) -> tuple[NDArray, DistanceJet, NDArray]:
    """Newton along ``grad g`` (along the side for ``pinned`` rows: held coordinate,
    -1 for none); only the rows not yet converged are evaluated again. Returns the
    corrected uv, the jet there and ``converged (m,)``."""
    x = uv.copy()
    jet = field.jet(x, st)
    ctol = np.broadcast_to(np.asarray(ctol, dtype=float), (x.shape[0],))
    converged = np.zeros(x.shape[0], dtype=bool)
    todo = np.arange(x.shape[0])
    for _ in range(_CORRECTOR):
        g, dg = curve_value(jet, kind)
        g, dg = g[todo], dg[todo]
        pin = pinned[todo]
        norm2 = np.einsum("mi,mi->m", dg, dg)
        dx = np.where((pin < 0)[:, None], -(g / np.maximum(norm2, 1e-300))[:, None] * dg, 0.0)
        for coord in (0, 1):
            rows = pin == coord
            if rows.any():
                other = 1 - coord
                d = dg[rows, other]
                dx[rows, other] = -g[rows] / np.where(np.abs(d) > 1e-300, d, 1e-300)
        dx = np.nan_to_num(dx, nan=0.0, posinf=0.0, neginf=0.0)
        size = np.sqrt(np.einsum("mi,mi->m", dx, dx))
        dx *= np.minimum(1.0, field.diagonal / np.maximum(size, 1e-300))[:, None]
        done = (size <= ctol[todo]) & (size > 0) | (np.abs(g) == 0)
        converged[todo[done]] = True
        todo, dx = todo[~done], dx[~done]
        if todo.size == 0:
            break
        x[todo] = np.clip(x[todo] + dx, field.lower, field.upper)
        jet = _assign(jet, todo, field.jet(x[todo], jet.st[todo]))
    return x, jet, converged & np.isfinite(x).all(axis=1)


def trace_curves(field: DistanceField, kind: CurveKind | list[CurveKind], uv0: NDArray, st0: NDArray,
                 direction: NDArray, *, h0: float | NDArray, h_max: float,
                 h_min: float | None = None, max_steps: int = 2000,
                 ctol: float | None = None, max_turn: float = MAX_TURN,
                 relative_ctol: float = RELATIVE_CTOL, compiled: bool | None = None
                 ) -> list[TracedCurve]:
    """Trace ``m`` curves of ``kind`` from ``uv0 (m, 2)`` one way each, all at once.

    Parameters
    ----------
    field : DistanceField
    kind : CurveKind, or one per curve
    uv0, st0 : (m, 2) float
        Starts (on or near the curve) and their feet.
    direction : (m, 2) float
        The tangent orientation to take: the first tangent has a positive dot
        product with it.
    h0 : float or (m,) float
        First step (parameter units).
    h_max, h_min : float
        Step bounds (default ``h_min`` 1e-9 of the domain diagonal).
    max_steps : int
        Accepted steps per curve at most.
    max_turn : float
        Largest accepted turn of the tangent per step (radians).
    ctol : float
        Corrector convergence in parameter units (default 1e-7 of the diagonal;
        never more than ``relative_ctol`` of the step). The samples are starts
        for a later refinement (:mod:`.trace`), not the final answer.
    relative_ctol : float
        Share of the step the corrector must reach (default ``RELATIVE_CTOL``);
        curves read only for sign changes (characteristic curves) take a
        looser one: their crossings are refined by Newton afterwards.
    compiled : bool, optional
        Trace by :mod:`.curves_kernels` (the same steps in one numba call); default
        whenever numba is there. False: the batched numpy form (the reference).

    Returns
    -------
    list of TracedCurve, one per start (``start_reason`` START).
    """
    m = uv0.shape[0]
    if m == 0:
        return []
    kinds = [kind] * m if isinstance(kind, CurveKind) else list(kind)
    comp_all = np.array([_component(k) for k in kinds])
    diag = field.diagonal
    h_min = 1e-9 * diag if h_min is None else h_min
    ctol = 1e-7 * diag if ctol is None else ctol
    if compiled is None:
        compiled = curves_kernels.AVAILABLE
    if compiled:
        return _traced_compiled(field, kinds, comp_all, uv0, st0, direction, h0=h0, h_max=h_max,
                                h_min=h_min, max_steps=max_steps, ctol=ctol, max_turn=max_turn,
                                relative_ctol=relative_ctol)
    none = np.full(m, -1)
    uv, jet, _ = correct(field, comp_all, np.asarray(uv0, float), np.asarray(st0, float), none,
                          ctol)
    _, dg = curve_value(jet, comp_all)
    tan = _tangent(dg)
    tan *= np.where(np.einsum("mi,mi->m", tan, direction) < 0, -1.0, 1.0)[:, None]
    h = np.broadcast_to(np.asarray(h0, dtype=float), (m,)).copy()
    bend = np.zeros((m, 2))                   # d tangent / d w of the last step
    start = uv.copy()
    length = np.zeros(m)
    samples = [[(uv[i].copy(), jet.st[i].copy(), jet.phi[i], jet.grad[i], jet.projection.det_k[i])]
               for i in range(m)]
    reason = [None] * m
    st = jet.st.copy()
    jac = jet.st_jacobian.copy()
    active = np.arange(m)
    steps = np.zeros(m, dtype=int)
    iteration = 0
    while active.size and iteration < 20 * max_steps:
        iteration += 1
        x0, t0, hh = uv[active], tan[active], h[active]
        pred = x0 + hh[:, None] * t0 + 0.5 * hh[:, None] ** 2 * bend[active]
        # shorten steps that would leave the domain: land on the side, pinned
        pinned = np.full(active.size, -1)
        frac = np.ones(active.size)
        for coord in (0, 1):
            d = pred[:, coord] - x0[:, coord]
            for bound, sign in ((field.lower[coord], -1.0), (field.upper[coord], 1.0)):
                over = (pred[:, coord] - bound) * sign > 0
                f = np.where(over, (bound - x0[:, coord]) / np.where(d != 0, d, 1.0), 1.0)
                f = np.clip(f, 0.0, 1.0)
                better = over & (f < frac)
                frac = np.where(better, f, frac)
                pinned = np.where(better, coord, pinned)
        pred = x0 + (frac * hh)[:, None] * t0
        for coord in (0, 1):
            rows = pinned == coord
            pred[rows, coord] = np.where(np.abs(pred[rows, coord] - field.lower[coord])
                                         < np.abs(pred[rows, coord] - field.upper[coord]),
                                         field.lower[coord], field.upper[coord])
        comp = comp_all[active]
        st_guess = st[active] + np.einsum("mij,mj->mi", jac[active], pred - x0)   # eq. (21)
        x, nj, conv = correct(field, comp, pred, st_guess, pinned,
                               np.minimum(ctol, relative_ctol * hh))
        _, ndg = curve_value(nj, comp)
        ntan = _tangent(ndg)
        ntan *= np.where(np.einsum("mi,mi->m", ntan, t0) < 0, -1.0, 1.0)[:, None]
        turn = np.arccos(np.clip(np.einsum("mi,mi->m", ntan, t0), -1, 1))
        status = nj.status
        moved = np.linalg.norm(x - pred, axis=1)
        lost = status == ProjectionStatus.NONE
        accept = conv & ~lost & (turn <= max_turn) & (moved <= 0.5 * hh + ctol)
        for k, i in enumerate(active):
            if accept[k]:
                w = np.linalg.norm(x[k] - x0[k])
                bend[i] = (ntan[k] - t0[k]) / w if w > 0 else 0.0
                uv[i], tan[i], st[i], jac[i] = x[k], ntan[k], nj.st[k], nj.st_jacobian[k]
                samples[i].append((x[k].copy(), nj.st[k].copy(), nj.phi[k], nj.grad[k],
                                   nj.projection.det_k[k]))
                length[i] += w
                steps[i] += 1
                h[i] = min(1.5 * h[i], h_max)
                back = np.linalg.norm(x[k] - start[i])
                if pinned[k] >= 0:
                    reason[i] = EndReason.DOMAIN
                elif steps[i] > 3 and back <= 1.2 * h[i] and length[i] > 4 * back:
                    reason[i] = EndReason.CLOSED
                elif steps[i] >= max_steps:
                    reason[i] = EndReason.STEP_LIMIT
            else:
                h[i] *= 0.5
                if h[i] < h_min:
                    reason[i] = EndReason.PROJECTION if lost[k] else EndReason.SINGULAR
        active = np.array([i for i in active if reason[i] is None], dtype=int)
    out = []
    for i in range(m):
        uv_s, st_s, phi_s, grad_s, det_s = (np.array(c) for c in zip(*samples[i]))
        out.append(TracedCurve(kinds[i], uv_s, st_s, phi_s, grad_s, det_s, EndReason.START,
                               reason[i] or EndReason.STEP_LIMIT))
    return out


def _traced_compiled(field: DistanceField, kinds: list[CurveKind], comps: NDArray, uv0: NDArray,
                     st0: NDArray, direction: NDArray, *, h0: float | NDArray, h_max: float,
                     h_min: float, max_steps: int, ctol: float, max_turn: float,
                     relative_ctol: float) -> list[TracedCurve]:
    """:func:`trace_curves` by :func:`.curves_kernels.trace_compiled`."""
    m = comps.size
    h0 = np.broadcast_to(np.asarray(h0, dtype=float), (m,))
    uv, st, phi, grad, det, count, reason = curves_kernels.trace_compiled(
        field, comps, np.asarray(uv0, float).reshape(m, 2), np.asarray(st0, float).reshape(m, 2),
        np.asarray(direction, float).reshape(m, 2), h0=h0, h_max=h_max, h_min=h_min,
        max_steps=max_steps, ctol=ctol, max_turn=max_turn, relative_ctol=relative_ctol)
    ends = [EndReason(name) for name in curves_kernels.REASONS]
    return [TracedCurve(kinds[i], uv[i, :n].copy(), st[i, :n].copy(), phi[i, :n].copy(),
                        grad[i, :n].copy(), det[i, :n].copy(), EndReason.START, ends[reason[i]])
            for i, n in enumerate(count)]
