"""Starts on the intersection and the check of them against known curves (002 §5, §6.3).

* :class:`Start`: points near ``phi = 0`` with the size of the feature they
  belong to and a key naming the curve they likely lie on;
* :func:`ray_starts`: from every maximum with ``phi > tol`` and minimum with
  ``phi < -tol`` (the extrema a closed loop must encircle, §4.2), rays along
  the Hessian's eigenvectors started at the quadratic model's zero distance
  ``sqrt(2 |phi| / |lambda|)``: a start on the loop however small it is;
* :func:`loop_keys`: the pair of grid components (``phi > 0`` / ``phi <= 0``)
  a start's cell joins, so one start per curve is traced per round;
* :func:`settle`: starts moved onto ``phi = 0`` by Newton along ``grad phi``;
* :func:`trace_uncovered`: in rounds, the starts that lie on none of the known
  curves (within ``10 tol / sin(angle of the surfaces)``) are traced and refined.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from ..intersection import IntersectionCurve
from .curves import TracedCurve
from .distance import DistanceField, DistanceJet
from .points import CharacteristicPoint, PointKind
from .projector import ProjectionStatus
from .trace import curve_gap, to_intersection_curves, trace_intersections

__all__ = [
    "MAX_TRACE_ROUNDS",
    "Start",
    "away_from",
    "border_keys",
    "label_components",
    "loop_keys",
    "ray_starts",
    "settle",
    "trace_uncovered",
]

#: rounds of "trace the uncovered starts" at most
MAX_TRACE_ROUNDS = 6


@dataclass(frozen=True)
class Start:
    """Starts on the intersection: ``uv`` on ``r``, feet ``st``, feature ``scale``."""

    uv: NDArray
    st: NDArray
    scale: NDArray
    group: NDArray

    @staticmethod
    def empty() -> Start:
        return Start(np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros(0, dtype=int))

    @staticmethod
    def stack(items: Sequence[Start]) -> Start:
        """Starts of all ``items``, groups kept as they are."""
        return Start(np.concatenate([s.uv for s in items]), np.concatenate([s.st for s in items]),
                     np.concatenate([s.scale for s in items]),
                     np.concatenate([s.group for s in items]))

    @staticmethod
    def concat(items: Sequence[Start]) -> Start:
        """Starts of all ``items``, each item's groups renumbered after the previous ones."""
        items = [s for s in items if s.uv.shape[0]]
        if not items:
            return Start.empty()
        groups, offset = [], 0
        for s in items:
            groups.append(s.group + offset)
            offset += int(s.group.max()) + 1 if s.group.size else 0
        return Start(np.concatenate([s.uv for s in items]), np.concatenate([s.st for s in items]),
                     np.concatenate([s.scale for s in items]), np.concatenate(groups))


def label_components(mask: NDArray) -> NDArray:
    """4-connected components of a boolean grid: labels ``1, 2, ...`` (0 outside the mask)."""
    labels, _ = ndimage.label(mask)
    return labels


def loop_keys(field: DistanceField, grid: DistanceJet, shape: tuple[int, int],
               start: Start) -> NDArray:
    """A key per start naming the curve it likely lies on: the pair of grid components
    (connected ``phi > 0`` and ``phi < 0`` regions) its grid cell joins. Starts in
    cells of one sign (a loop smaller than the grid) keep their own group."""
    nu, nv = shape
    phi = grid.phi.reshape(nu, nv)
    ok = (grid.status != ProjectionStatus.NONE).reshape(nu, nv)
    pos = label_components(ok & (phi > 0))
    neg = label_components(ok & (phi <= 0))
    cell = (field.upper - field.lower) / (np.array(shape) - 1)
    ij = np.clip(((start.uv - field.lower) / cell).astype(int), 0, np.array(shape) - 2)
    keys = np.empty(start.uv.shape[0], dtype=np.int64)
    base = (nu * nv + 1) ** 2
    for k, (i, j) in enumerate(ij):
        p = pos[i:i + 2, j:j + 2]
        n = neg[i:i + 2, j:j + 2]
        if p.max() > 0 and n.max() > 0:
            keys[k] = int(p[p > 0].min()) * (nu * nv + 1) + int(n[n > 0].min())
        else:
            keys[k] = base + int(start.group[k])
    return keys


def border_keys(start: Start) -> Start:
    """Border starts keyed ``-1, -2, ...`` (each its own group, told apart from loop starts)."""
    return Start(start.uv, start.st, start.scale, -1 - np.arange(start.uv.shape[0]))


def ray_starts(field: DistanceField, crit: DistanceJet, kinds: list[PointKind], tol: float,
                max_steps: int = 40) -> Start:
    """Starts on the loops around maxima with phi > tol and minima with phi < -tol (step 4)."""
    pick = [i for i, k in enumerate(kinds)
            if (k is PointKind.MAXIMUM and crit.phi[i] > tol)
            or (k is PointKind.MINIMUM and crit.phi[i] < -tol)]
    if not pick:
        return Start.empty()
    pick = np.array(pick)
    lam, vec = np.linalg.eigh(crit.hess[pick])                       # (k, 2), (k, 2, 2)
    origin, dirs, r0, group = [], [], [], []
    for j in range(2):
        for sign in (1.0, -1.0):
            origin.append(crit.uv[pick])
            dirs.append(sign * vec[:, :, j])
            r0.append(np.sqrt(2 * np.abs(crit.phi[pick]) / np.maximum(np.abs(lam[:, j]), 1e-300)))
            group.append(pick)
    origin, dirs = np.concatenate(origin), np.concatenate(dirs)
    r0, group = np.concatenate(r0), np.concatenate(group)
    st = np.tile(crit.st[pick], (4, 1))
    sign0 = np.sign(np.tile(crit.phi[pick], 4))
    lo = np.zeros(r0.size)
    hi = np.full(r0.size, np.nan)
    t = np.minimum(0.5 * r0, 0.5 * field.diagonal)
    alive = np.ones(r0.size, dtype=bool)
    for _ in range(max_steps):                            # march outward to a sign change
        todo = np.flatnonzero(alive & np.isnan(hi))
        if todo.size == 0:
            break
        x = origin[todo] + t[todo, None] * dirs[todo]
        inside = field.inside(x)
        jet = field.jet(np.clip(x, field.lower, field.upper), st[todo])
        st[todo] = jet.st
        lost = ~inside | (jet.status == ProjectionStatus.NONE)
        alive[todo[lost]] = False
        flip = ~lost & (np.sign(jet.phi) != sign0[todo])
        hi[todo[flip]] = t[todo[flip]]
        stay = todo[~lost & ~flip]
        lo[stay] = t[stay]
        t[stay] *= 1.5
    found = np.flatnonzero(alive & ~np.isnan(hi))
    if found.size == 0:
        return Start.empty()
    a, b = lo[found], hi[found]
    for _ in range(8):            # a few bisections: settle finishes the job by Newton
        mid = 0.5 * (a + b)
        jet = field.jet(origin[found] + mid[:, None] * dirs[found], st[found])
        st[found] = jet.st
        same = np.sign(jet.phi) == sign0[found]
        a, b = np.where(same, mid, a), np.where(same, b, mid)
        if np.all(b - a <= 1e-12 * field.diagonal):
            break
    uv = origin[found] + (0.5 * (a + b))[:, None] * dirs[found]
    return Start(uv, st[found], 0.5 * (a + b), group[found])


def settle(field: DistanceField, start: Start) -> tuple[Start, NDArray]:
    """Starts moved onto ``phi = 0`` (Newton along grad phi); ``ok (m,)``."""
    x, st = start.uv.copy(), start.st.copy()
    jet = field.jet(x, st)
    for _ in range(12):
        g = jet.grad
        n2 = np.einsum("mi,mi->m", g, g)
        step = -(jet.phi / np.maximum(n2, 1e-300))[:, None] * g
        x = np.clip(x + step, field.lower, field.upper)
        jet = field.jet(x, jet.st)
        if np.all(np.linalg.norm(step, axis=1) <= 1e-14 * field.diagonal):
            break
    ok = (jet.status != ProjectionStatus.NONE) & (np.linalg.norm(x - start.uv, axis=1)
                                                  <= np.maximum(start.scale, 1e-9 * field.diagonal))
    return Start(x, jet.st, start.scale, start.group), ok


def _on_trace(uv: NDArray, trace: TracedCurve) -> NDArray:
    """``(m,) bool``: which of ``uv (m, 2)`` lie on the traced polyline in the parameter
    plane: within the sag of one of its chords, ``length * turn / 4`` (twice the sag
    of an arc turning by ``turn``, the larger of the chord's angles with its
    neighbours), plus ``1e-6`` of the chord for rounding. Two curves close side by
    side (the circles of a torus just below a plane, 1e-3 of a chord apart) stay
    apart."""
    p = trace.uv
    q = np.vstack([p, p[:1]]) if trace.closed else p
    a, d = q[:-1], np.diff(q, axis=0)
    dd = np.einsum("sc,sc->s", d, d)
    length = np.sqrt(dd)
    unit = d / np.where(length > 0, length, 1.0)[:, None]
    cos = np.einsum("sc,sc->s", unit[:-1], unit[1:])
    turn = np.arccos(np.clip(cos, -1.0, 1.0))                       # at inner vertices
    if trace.closed:
        at_vertex = np.append(np.arccos(np.clip(unit[-1] @ unit[0], -1.0, 1.0)), turn)
        bend = np.maximum(at_vertex, np.roll(at_vertex, -1))
    else:
        bend = np.maximum(np.append(turn[:1], turn), np.append(turn, turn[-1:])) \
            if turn.size else np.zeros(length.size)
    uv = np.atleast_2d(uv)
    t = np.clip(np.einsum("msc,sc->ms", uv[:, None] - a[None], d) / np.where(dd > 0, dd, 1.0),
                0.0, 1.0)                                          # (m, chords)
    gap = np.linalg.norm(a[None] + t[..., None] * d[None] - uv[:, None], axis=-1)
    return np.any(gap <= length * (0.25 * bend + 1e-6) + 1e-14, axis=1)


def _sine(field: DistanceField, uv: NDArray, st: NDArray) -> NDArray:
    """``(m,)`` sine of the angle between the two surfaces at ``uv`` (feet ``st``)."""
    jet = field.jet(uv, st)
    d = field.evaluator.derivatives(uv[:, 0], uv[:, 1], 1)
    n_r = np.cross(d[:, 1, 0], d[:, 0, 1])
    n_r /= np.maximum(np.linalg.norm(n_r, axis=1), 1e-300)[:, None]
    return np.linalg.norm(np.cross(n_r, jet.normal), axis=1)


def _points_3d(field: DistanceField, uv: NDArray) -> NDArray:
    return field.r.evaluate(uv[:, 0], uv[:, 1])


def trace_uncovered(field: DistanceField, starts: Start, known: list[IntersectionCurve],
                     tol: float, size: float) -> list[IntersectionCurve]:
    """Trace the starts that lie on none of the ``known`` curves (3D) nor on a trace of an
    earlier round (parameter plane), in rounds; all traces sampled in one batch, the
    curves within ``tol`` returned."""
    settled, ok = settle(field, starts)
    uv, st, scale, group = (settled.uv[ok], settled.st[ok], settled.scale[ok], settled.group[ok])
    pts = _points_3d(field, uv)
    # a curve within tol of both surfaces may sit tol / sin(angle) off the exact point
    # along the surfaces where they meet at a small angle
    cover = 10 * tol / np.maximum(_sine(field, uv, st), 1e-6) + 1e-9 * size
    todo = np.arange(uv.shape[0])
    if known and todo.size:
        todo = todo[curve_gap(pts, list(known), within=cover) > cover]
    traces: list[TracedCurve] = []
    for _ in range(MAX_TRACE_ROUNDS):
        for t in traces:                      # one test of all starts per trace
            todo = todo[~_on_trace(uv[todo], t)] if todo.size else todo
        if todo.size == 0:
            break
        # one start per group and round (several starts of one loop trace once; the
        # others are traced in a later round if no trace passes through them)
        _, first = np.unique(group[todo], return_index=True)
        batch = todo[np.sort(first)]
        for t in trace_intersections(field, uv[batch], st[batch], scale[batch], tol=tol,
                                     branches=True):
            if not any(_on_trace(t.uv[t.uv.shape[0] // 2], k)[0] for k in traces):
                traces.append(t)                          # (a loop traced twice: once)
        todo = np.setdiff1d(todo, batch)
    # all traces sampled in one batch
    return [c for c in to_intersection_curves(field, traces, tol, within_tol=True)
            if c is not None]


def away_from(starts: Start, isolated: Sequence[CharacteristicPoint], field: DistanceField
               ) -> Start:
    """Starts farther than ``1e-3`` of the domain diagonal from every isolated point
    (sign changes of rounding noise around a tangential contact are not curves)."""
    if not isolated or starts.uv.shape[0] == 0:
        return starts
    at = np.array([p.uv_b if field.swapped else p.uv_a for p in isolated])
    d = np.linalg.norm(starts.uv[:, None] - at[None], axis=-1).min(axis=1)
    keep = d > 1e-3 * field.diagonal
    return Start(starts.uv[keep], starts.st[keep], starts.scale[keep], starts.group[keep])
