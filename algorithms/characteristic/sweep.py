"""The characteristic curves of the stage (002 §5, §6.2, §6.3 steps 2-3), complete to the grid.

:func:`sweep` traces the u-characteristic curves (``phi_u = 0``, eq. 13)
from the roots of ``phi_u`` on the sides of ``r``'s domain (step 2 of §6.3),
and then makes sure no component of ``phi_u = 0`` crossing the sample grid
was left out:

* a component that does not reach a side — a closed characteristic curve, or
  one that starts and ends where the projection onto ``q`` stops existing
  (the boundary of the valid region, §6.2 case 3, where the paper starts
  characteristic curves) — shows as grid cells whose corners see ``phi_u``
  change sign but that no traced curve passes near. From one cell of every
  such group a curve is traced both ways, in rounds, until every sign-change
  cell is accounted for (:func:`unvisited_seeds`);
* when a u-characteristic curve cannot be followed to its end (it stops at a
  singular point of ``phi_u = 0``, §6.2, or hits the step cap) or when
  ``trace_critical`` asks for the full §6.3, the v-characteristic curves
  (``phi_v = 0``, eq. 14) are traced the same way; with ``trace_critical``
  both curves through every critical point too (:func:`from_critical`);
* where ``det K`` changes sign along a traced curve (the cut locus of ``q``:
  multiple projections, §6.2 case 2) the point is projected afresh and, on
  another foot, the curve is traced again on that branch
  (:func:`other_branches`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .curves import CurveKind, EndReason, TracedCurve, curve_value, trace_curves
from .distance import DistanceField, DistanceJet
from .points import CharacteristicPoint, PointKind, edge_roots, make_points
from .projector import ProjectionStatus
from .starts import label_components

__all__ = [
    "CHARACTERISTIC_CTOL",
    "CHARACTERISTIC_TURN",
    "SWEEP_ROUNDS",
    "from_critical",
    "other_branches",
    "sweep",
    "trace_characteristic",
    "unvisited_seeds",
]

#: largest turn per step on a characteristic curve (only sign changes are read off it)
CHARACTERISTIC_TURN = 0.6
#: corrector tolerance on a characteristic curve: a share of the step and of the
#: diagonal (its sign changes seed Newton on the exact points afterwards)
CHARACTERISTIC_CTOL = 5e-2
#: rounds of "trace from the sign-change cells no curve passed" at most
SWEEP_ROUNDS = 3
_FAMILIES = ((0, CurveKind.U_CHARACTERISTIC, PointKind.EDGE_ROOT_U),
             (1, CurveKind.V_CHARACTERISTIC, PointKind.EDGE_ROOT_V))


def trace_characteristic(field: DistanceField, kind, uv: NDArray, st: NDArray,
                         direction: NDArray, h_max: float) -> list[TracedCurve]:
    """Characteristic curves from ``uv (m, 2)`` one way each, with the loose corrector."""
    return trace_curves(field, kind, uv, st, direction, h0=h_max, h_max=h_max,
                        max_steps=400, max_turn=CHARACTERISTIC_TURN,
                        ctol=1e-3 * field.diagonal, relative_ctol=CHARACTERISTIC_CTOL)


def from_critical(field: DistanceField, crit: DistanceJet, h_max: float) -> list[TracedCurve]:
    """Both characteristic curves through each critical point, both ways (§5)."""
    uvs, sts, dirs, kinds = [], [], [], []
    for kind in (CurveKind.U_CHARACTERISTIC, CurveKind.V_CHARACTERISTIC):
        _, dg = curve_value(crit, kind)
        tangent = np.stack([-dg[:, 1], dg[:, 0]], -1)
        for sign in (1.0, -1.0):
            uvs.append(crit.uv)
            sts.append(crit.st)
            dirs.append(sign * tangent)
            kinds += [kind] * crit.uv.shape[0]
    return trace_characteristic(field, kinds, np.concatenate(uvs), np.concatenate(sts),
                                np.concatenate(dirs), h_max)


def _cells_of(field: DistanceField, shape: tuple[int, int], curves: list[TracedCurve]
              ) -> NDArray:
    """``(nu - 1, nv - 1) bool``: cells a traced polyline passes through, grown by one cell
    (a curve near a cell corner may hold its crossing in the neighbour)."""
    nu, nv = shape
    cell = (field.upper - field.lower) / (np.array(shape) - 1)
    hit = np.zeros((nu - 1, nv - 1), dtype=bool)
    polylines = [c.uv for c in curves if c.uv.shape[0]]
    if polylines:                             # chords cut at a quarter cell, all curves at once
        p = np.concatenate(polylines)
        last = np.cumsum([q.shape[0] for q in polylines]) - 1
        d = np.diff(p, axis=0)
        pieces = np.maximum(np.ceil(4 * np.abs(d / cell).max(axis=1)).astype(int), 1)
        pieces[last[:-1]] = 1                 # no chord from one curve's end to the next
        d[last[:-1]] = 0.0
        start = np.repeat(np.arange(d.shape[0]), pieces)
        first = np.repeat(np.cumsum(pieces) - pieces, pieces)
        w = (np.arange(start.size) - first) / pieces[start]
        p = np.vstack([p[start] + w[:, None] * d[start], p[-1:]])
        ij = np.clip(((p - field.lower) / cell).astype(int), 0, np.array(shape) - 2)
        hit[ij[:, 0], ij[:, 1]] = True
    rows = hit.copy()
    rows[1:] |= hit[:-1]
    rows[:-1] |= hit[1:]
    grown = rows.copy()
    grown[:, 1:] |= rows[:, :-1]
    grown[:, :-1] |= rows[:, 1:]
    return grown


def unvisited_seeds(field: DistanceField, grid: DistanceJet, shape: tuple[int, int],
                    component: int, curves: list[TracedCurve], noise: float) -> NDArray:
    """Cell centres ``(k, 2)``: one per connected group of grid cells whose corners with a
    regular projection (two at least) see ``phi_u`` (``component`` 0) or ``phi_v`` (1)
    change sign beyond ``noise`` and that none of ``curves`` passes near."""
    nu, nv = shape
    g = grid.grad[:, component].reshape(nu, nv)
    ok = (grid.status == ProjectionStatus.UNIQUE).reshape(nu, nv)
    corners = [(slice(0, -1), slice(0, -1)), (slice(1, None), slice(0, -1)),
               (slice(0, -1), slice(1, None)), (slice(1, None), slice(1, None))]
    valid = np.stack([ok[c] for c in corners])
    vals = np.stack([g[c] for c in corners])
    low = np.where(valid, vals, np.inf).min(axis=0)
    high = np.where(valid, vals, -np.inf).max(axis=0)
    size = np.where(valid, np.abs(vals), 0.0).max(axis=0)
    change = (valid.sum(axis=0) >= 2) & (low <= 0) & (high >= 0) & (size > noise)
    todo = change & ~_cells_of(field, shape, curves)
    if not todo.any():
        return np.zeros((0, 2))
    labels = label_components(todo).ravel()
    # per group the cell with the most regular corners; the seed: their mean
    count = valid.sum(axis=0).ravel()
    order = np.lexsort((-count, labels))
    _, first = np.unique(labels[order], return_index=True)
    pick = order[first][labels[order[first]] > 0]
    i, j = np.unravel_index(pick, todo.shape)
    uv = grid.uv.reshape(nu, nv, 2)
    corner_uv = np.stack([uv[c][i, j] for c in corners])             # (4, k, 2)
    weight = valid[:, i, j][..., None]
    return (corner_uv * weight).sum(axis=0) / weight.sum(axis=0)


def _both_ways(field: DistanceField, kind: CurveKind, seeds: NDArray, h_max: float
               ) -> list[TracedCurve]:
    """Characteristic curves of ``kind`` through ``seeds (k, 2)``, both ways each."""
    jet = field.jet(seeds)
    keep = jet.status == ProjectionStatus.UNIQUE
    if not keep.any():
        return []
    _, dg = curve_value(jet, kind)
    tangent = np.stack([-dg[keep, 1], dg[keep, 0]], -1)
    uv, st = seeds[keep], jet.st[keep]
    return trace_characteristic(field, kind, np.vstack([uv, uv]), np.vstack([st, st]),
                                np.vstack([tangent, -tangent]), h_max)


def other_branches(field: DistanceField, curves: list[TracedCurve], h_max: float
                   ) -> list[TracedCurve]:
    """Where the foot a traced curve carries stops being a minimum of the distance
    (``K`` no longer positive definite: ``det K`` changes sign, or a focal point was
    crossed; the cut locus of ``q``, §6.2 case 2), the point is projected afresh
    (seed grid); when that foot is another one, the curve of the same kind is
    traced from it both ways: each projection branch followed."""
    if not curves:
        return []
    every = field.jet(np.concatenate([c.uv for c in curves]),
                      np.concatenate([c.st for c in curves]))
    multiple = every.status == ProjectionStatus.MULTIPLE
    uv, st, kinds, offset = [], [], [], 0
    for c in curves:
        n = c.uv.shape[0]
        # K stops being positive definite (det K changes sign, or both eigenvalues
        # turn negative past an umbilic focal point: det K keeps its sign there)
        past = multiple[offset:offset + n] | (np.sign(c.det_k) != np.sign(c.det_k[0]))
        for j in np.flatnonzero(past):
            uv.append(c.uv[j])
            st.append(c.st[j])
            kinds.append(c.kind)
            break                                       # one re-start per curve and round
        offset += n
    if not uv:
        return []
    uv, st = np.array(uv), np.array(st)
    fresh = field.jet(uv)
    q_diag = float(np.linalg.norm(field.projector.upper - field.projector.lower))
    new = (fresh.status == ProjectionStatus.UNIQUE) & (
        np.linalg.norm(fresh.st - st, axis=1) > 1e-3 * q_diag)
    if not new.any():
        return []
    rows = np.flatnonzero(new)
    kind = [kinds[i] for i in rows]
    _, dg = curve_value(fresh, np.array([0 if k is CurveKind.U_CHARACTERISTIC else 1
                                         for k in kinds]))
    tangent = np.stack([-dg[rows, 1], dg[rows, 0]], -1)
    return trace_characteristic(field, kind + kind, np.vstack([uv[rows]] * 2),
                                np.vstack([fresh.st[rows]] * 2),
                                np.vstack([tangent, -tangent]), h_max)


def _family(field: DistanceField, grid: DistanceJet, shape: tuple[int, int], comp: int,
            kind: CurveKind, root_kind: PointKind, noise: float, h_max: float
            ) -> tuple[list[CharacteristicPoint], list[TracedCurve]]:
    """One family: from the side roots, then from the cells no curve passed (rounds)."""
    points: list[CharacteristicPoint] = []
    curves: list[TracedCurve] = []
    uv, st, _ = edge_roots(field, comp, noise=noise)
    if uv.shape[0]:
        jet = field.jet(uv, st)
        points += make_points(field, root_kind, uv, jet.st, jet.point, jet.phi)
        inward = 0.5 * (field.lower + field.upper) - uv
        curves += trace_characteristic(field, kind, uv, jet.st, inward, h_max)
    for _ in range(SWEEP_ROUNDS):
        seeds = unvisited_seeds(field, grid, shape, comp, curves, noise)
        if seeds.shape[0] == 0:
            break
        curves += _both_ways(field, kind, seeds, h_max)
    fresh = curves
    for _ in range(SWEEP_ROUNDS):               # each projection branch (§6.2 case 2)
        fresh = other_branches(field, fresh, h_max)
        if not fresh:
            break
        curves += fresh
    return points, curves


def sweep(field: DistanceField, grid: DistanceJet, shape: tuple[int, int], noise: float,
          h_max: float, *, both: bool) -> tuple[list[CharacteristicPoint], list[TracedCurve]]:
    """Side roots and characteristic curves of the stage (module docstring).

    Parameters
    ----------
    grid : DistanceJet
        ``phi`` on the tensor grid ``shape`` of ``r``'s domain.
    noise : float
        Gradient values within it are rounding.
    both : bool
        Trace the v-family too (the full §6.3); otherwise only when a
        u-characteristic curve stops at a singular point or the step cap.
    """
    points, curves = _family(field, grid, shape, *_FAMILIES[0], noise, h_max)
    stuck = any(c.end_reason in (EndReason.SINGULAR, EndReason.STEP_LIMIT) for c in curves)
    if both or stuck:
        more_points, more_curves = _family(field, grid, shape, *_FAMILIES[1], noise, h_max)
        points += more_points
        curves += more_curves
    return points, curves
