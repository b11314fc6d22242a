"""Interior interpolation points by relocation with a penalty factor (000 §29.2.6).

The interpolation grid has ``n_u x n_v`` points; node ``(i, j)`` belongs to the
new parameters ``(f^u_i, f^v_j)`` (the reconciled fractions). Its position is
kept as *original* parameters ``(u_ij, v_ij)``, so the point
``x_ij = s(u_ij, v_ij)`` always lies on the original surface.

**Initial guess.** The boundary points are marked in the original domain; the
nodes of opposite boundaries are joined by straight lines there and the
interior nodes are the intersections (:func:`initial_guess`).

**Penalty factor.** At an interior node the chord-length conditions (29.1) and
(29.2) read, as logarithms,

.. math:: R^u_{ij} = \\log\\frac{|x_{ij} - x_{i-1,j}|}{|x_{i+1,j} - x_{ij}|}
                     - \\log\\frac{\\Delta f^u_{i-1}}{\\Delta f^u_i}, \\qquad
          R^v_{ij} = \\log\\frac{|x_{ij} - x_{i,j-1}|}{|x_{i,j+1} - x_{ij}|}
                     - \\log\\frac{\\Delta f^v_{j-1}}{\\Delta f^v_j}

and the penalty is ``|R^u| + |R^v|`` (0: the node is where the new
parametrization wants it).

**Global solve first.** All movable nodes are first moved together by a
damped Newton (Levenberg-Marquardt) solve of the square system
``R^u = R^v = 0`` (:func:`solve_globally`, sparse): node-by-node moves need
O(n^2) sweeps to carry a correction across an ``n x n`` grid, a global step
does it at once (3-5 steps on smooth surfaces). The sweeps below then only
finish what it left (nodes it could not move without fold-over).

**Relocation.** A node is moved *in the original domain* by a damped Newton
step on ``(R^u, R^v)`` with its neighbours held (the 2 x 2 Jacobian comes from
``s_u``, ``s_v`` and the chord directions); the step is accepted only if it
lowers the penalty (halving up to four times) and it stays inside the box of
the eight neighbours (no fold-over). Following the paper, the node with the
worst penalty goes first, a node is a candidate again only when a neighbour
(or itself) moved in the previous sweep, and the iteration stops when no node
moves. Vectorized: nodes of one colour of a checkerboard do not share a
penalty term, so all candidates of one colour are moved at once (their order
within the colour does not change any result); the colour that holds the
worst penalty goes first.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse.linalg import spsolve

from ..surface import NurbsSurface

__all__ = [
    "PENALTY_TOL",
    "RelocationResult",
    "initial_guess",
    "penalties",
    "relocate",
]

#: A node with penalty below this (0.1 % in the distance ratios) is in place.
PENALTY_TOL = 1e-3
#: Step scales tried for every moved node.
_SCALES = np.array([1.0, 0.5, 0.25, 0.125, 0.0625])
#: Levenberg-Marquardt steps of the global solve at most, and its damping range.
GLOBAL_STEPS = 40
_DAMPING = (1e-6, 1e6)
#: Relative drop of the squared residuals below which a global step counts as stalled
#: (three in a row end the solve; the sweeps take over).
_STALL = 0.01


@dataclass(frozen=True)
class RelocationResult:
    """Relocated interpolation grid.

    Attributes
    ----------
    uv : (n_u, n_v, 2) float
        Original-domain parameters of the nodes.
    points : (n_u, n_v, 3) float
        ``s(uv)``, on the original surface.
    sweeps : int
        Sweeps over the candidates done.
    converged : bool
        No node moved in the last sweep (within ``max_sweeps``).
    penalty_before, penalty_after : float
        Largest penalty of an interior node before and after.
    newton_steps : int
        Accepted steps of the global solve that precedes the sweeps.
    """

    uv: NDArray
    points: NDArray
    sweeps: int
    converged: bool
    penalty_before: float
    penalty_after: float
    newton_steps: int = 0


def initial_guess(bottom: NDArray, top: NDArray, left: NDArray, right: NDArray,
                  domain: tuple[float, float, float, float]) -> NDArray:
    """Intersections of the straight lines joining opposite boundary nodes.

    Parameters
    ----------
    bottom, top : (n_u,) float
        Original ``u`` of the nodes on ``v = v0`` and ``v = v1``.
    left, right : (n_v,) float
        Original ``v`` of the nodes on ``u = u0`` and ``u = u1``.
    domain : (u0, u1, v0, v1)

    Returns
    -------
    (n_u, n_v, 2) float
        The boundary nodes exactly; interior nodes where the line from
        ``(bottom_i, v0)`` to ``(top_i, v1)`` meets the line from
        ``(u0, left_j)`` to ``(u1, right_j)``.
    """
    u0, u1, v0, v1 = domain
    b, t = (bottom - u0) / (u1 - u0), (top - u0) / (u1 - u0)
    lo, ri = (left - v0) / (v1 - v0), (right - v0) / (v1 - v0)
    d, e = (t - b)[:, None], (ri - lo)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        uu = (b[:, None] + lo[None, :] * d) / (1.0 - e * d)
    uu = np.clip(np.nan_to_num(uu, nan=0.5), 0.0, 1.0)
    vv = np.clip(lo[None, :] + uu * e, 0.0, 1.0)
    uv = np.stack([u0 + uu * (u1 - u0), v0 + vv * (v1 - v0)], axis=-1)
    uv[:, 0] = np.stack([bottom, np.full_like(bottom, v0)], axis=-1)
    uv[:, -1] = np.stack([top, np.full_like(top, v1)], axis=-1)
    uv[0, :] = np.stack([np.full_like(left, u0), left], axis=-1)
    uv[-1, :] = np.stack([np.full_like(right, u1), right], axis=-1)
    return uv


def _targets(fractions: NDArray) -> NDArray:
    steps = np.diff(fractions)
    return np.log(steps[:-1] / steps[1:])


def _log_ratio(x: NDArray, before: NDArray, after: NDArray, floor: float) -> NDArray:
    a = np.linalg.norm(x - before, axis=-1)
    b = np.linalg.norm(after - x, axis=-1)
    ok = (a > floor) & (b > floor)
    with np.errstate(divide="ignore"):
        return np.where(ok, np.log(np.maximum(a, floor)) - np.log(np.maximum(b, floor)), np.nan)


def _residuals(points: NDArray, target_u: NDArray, target_v: NDArray, floor: float
               ) -> tuple[NDArray, NDArray]:
    """``R^u, R^v`` at the interior nodes ``(n_u-2, n_v-2)`` (0 where a chord collapsed)."""
    x = points[1:-1, 1:-1]
    ru = _log_ratio(x, points[:-2, 1:-1], points[2:, 1:-1], floor) - target_u[:, None]
    rv = _log_ratio(x, points[1:-1, :-2], points[1:-1, 2:], floor) - target_v[None, :]
    return np.nan_to_num(ru), np.nan_to_num(rv)


def penalties(points: NDArray, fractions_u: NDArray, fractions_v: NDArray,
              floor: float = 0.0) -> NDArray:
    """Penalty factor ``|R^u| + |R^v|`` of every interior node, ``(n_u-2, n_v-2)``."""
    ru, rv = _residuals(points, _targets(fractions_u), _targets(fractions_v), floor)
    return np.abs(ru) + np.abs(rv)


def _neighbour_box(uv: NDArray) -> tuple[NDArray, NDArray]:
    """Per interior node, min and max of its 8 neighbours' parameters ``(n_u-2, n_v-2, 2)``."""
    shifts = [uv[1 + di:uv.shape[0] - 1 + di, 1 + dj:uv.shape[1] - 1 + dj]
              for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj]
    stack = np.stack(shifts)
    return stack.min(axis=0), stack.max(axis=0)


def _grad_log_ratio(x, before, after):
    """Gradient of ``log|x - before| - log|after - x|`` with respect to ``x``: (k, 3)."""
    a, b = x - before, after - x
    return (a / np.maximum(np.sum(a * a, axis=-1), 1e-300)[:, None]
            + b / np.maximum(np.sum(b * b, axis=-1), 1e-300)[:, None])


def _move(surface: NurbsSurface, uv: NDArray, points: NDArray, selected: NDArray,
          targets: tuple[NDArray, NDArray], floor: float) -> NDArray:
    """Newton-relocate the ``selected (n_u-2, n_v-2)`` nodes in place; returns which moved."""
    ii, jj = np.nonzero(selected)
    i, j = ii + 1, jj + 1
    x = points[i, j]
    left, right, below, above = points[i - 1, j], points[i + 1, j], points[i, j - 1], points[i, j + 1]
    ru, rv = _residuals(points, *targets, floor)
    r = np.stack([ru[ii, jj], rv[ii, jj]], axis=-1)                    # (k, 2)
    old = np.abs(r).sum(axis=1)
    d = surface.derivatives(uv[i, j, 0], uv[i, j, 1], 1)               # (k, 2, 2, 3)
    su, sv = d[:, 1, 0], d[:, 0, 1]
    gu, gv = _grad_log_ratio(x, left, right), _grad_log_ratio(x, below, above)
    jac = np.stack([np.stack([np.sum(gu * su, -1), np.sum(gu * sv, -1)], -1),
                    np.stack([np.sum(gv * su, -1), np.sum(gv * sv, -1)], -1)], -2)
    det = jac[:, 0, 0] * jac[:, 1, 1] - jac[:, 0, 1] * jac[:, 1, 0]
    ok = np.abs(det) > 1e-300
    safe = np.where(ok, det, 1.0)
    step = -np.stack([(jac[:, 1, 1] * r[:, 0] - jac[:, 0, 1] * r[:, 1]) / safe,
                      (-jac[:, 1, 0] * r[:, 0] + jac[:, 0, 0] * r[:, 1]) / safe], -1)
    step[~ok] = 0.0
    lo, hi = _neighbour_box(uv)
    trial = np.clip(uv[i, j][None] + _SCALES[:, None, None] * step[None],
                    lo[ii, jj][None], hi[ii, jj][None])                # (s, k, 2)
    xt = surface.evaluate(trial[..., 0], trial[..., 1])                  # (s, k, 3)
    pu = _log_ratio(xt, left[None], right[None], floor) - targets[0][ii][None]
    pv = _log_ratio(xt, below[None], above[None], floor) - targets[1][jj][None]
    pen = np.abs(np.nan_to_num(pu, nan=np.inf)) + np.abs(np.nan_to_num(pv, nan=np.inf))
    best = np.argmin(pen, axis=0)
    k = np.arange(ii.size)
    better = pen[best, k] < old * (1.0 - 1e-6)
    uv[i[better], j[better]] = trial[best[better], k[better]]
    points[i[better], j[better]] = xt[best[better], k[better]]
    moved = np.zeros_like(selected)
    moved[ii[better], jj[better]] = True
    return moved


def _sum_squares(points, targets, floor, rows) -> float:
    ru, rv = _residuals(points, *targets, floor)
    return float(np.sum(ru[rows] ** 2) + np.sum(rv[rows] ** 2))


def _global_jacobian(surface, uv, points, movable):
    """Sparse Jacobian of ``(R^u, R^v)`` at the movable nodes with respect to their
    original parameters ``(2m, 2m)`` (each residual involves a node and its two
    neighbours along one direction; fixed neighbours contribute nothing)."""
    inner = movable.shape
    index = -np.ones(inner, int)
    ii, jj = np.nonzero(movable)
    index[ii, jj] = np.arange(ii.size)
    i, j = ii + 1, jj + 1
    d = surface.derivatives(uv[i, j, 0], uv[i, j, 1], 1)
    tangents = np.stack([d[:, 1, 0], d[:, 0, 1]], axis=1)            # (m, 2, 3)
    padded = -np.ones((inner[0] + 2, inner[1] + 2), int)
    padded[1:-1, 1:-1] = index
    rows, cols, vals = [], [], []
    x = points[i, j]
    for eq, (before, after) in enumerate((((i - 1, j), (i + 1, j)), ((i, j - 1), (i, j + 1)))):
        a, b = x - points[before], points[after] - x
        ga = a / np.maximum(np.sum(a * a, -1), 1e-300)[:, None]     # d log|a| / d x
        gb = b / np.maximum(np.sum(b * b, -1), 1e-300)[:, None]     # -d log|b| / d x
        row = 2 * np.arange(ii.size) + eq
        for node, grad in (((i, j), ga + gb), (before, -ga), (after, -gb)):
            col = padded[node]
            ok = col >= 0
            if not np.any(ok):
                continue
            k = np.nonzero(ok)[0]
            t = tangents[col[ok]]                                    # (k, 2, 3)
            g = np.einsum("kc,kdc->kd", grad[ok], t)                 # (k, 2)
            for c in range(2):
                rows.append(row[k])
                cols.append(2 * col[ok] + c)
                vals.append(g[:, c])
    n = 2 * ii.size
    jac = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                        shape=(n, n))
    return jac, ii, jj


def solve_globally(surface: NurbsSurface, uv: NDArray, points: NDArray,
                   targets: tuple[NDArray, NDArray], floor: float, movable: NDArray,
                   steps: int = GLOBAL_STEPS) -> tuple[NDArray, NDArray, int]:
    """All movable nodes at once: Levenberg-Marquardt on the residuals ``(R^u, R^v)``.

    The penalty conditions of all interior nodes form a square nonlinear system
    in the nodes' original parameters; a node-by-node relocation (Gauss-Seidel)
    needs O(n^2) sweeps to carry a correction across an ``n x n`` grid, a
    global Newton step does it at once. Each step solves the damped normal
    equations ``(J^T J + lambda D) delta = -J^T r`` (sparse; ``D`` the diagonal
    of ``J^T J``), is cut to the box of each node's neighbours (no fold-over) and
    is accepted only if the sum of squared residuals drops (else ``lambda`` x 10);
    three steps in a row that gain less than 1 % end it.

    Parameters
    ----------
    uv, points : (n_u, n_v, 2), (n_u, n_v, 3) float
        Start grid (not modified).
    movable : (n_u - 2, n_v - 2) bool

    Returns
    -------
    uv, points : the improved grid; steps : Newton steps accepted.
    """
    uv, points = uv.copy(), points.copy()
    rows = movable
    if not np.any(rows):
        return uv, points, 0
    cost = _sum_squares(points, targets, floor, rows)
    damping, accepted, stalled = 1e-3, 0, 0
    for _ in range(steps):
        jac, ii, jj = _global_jacobian(surface, uv, points, movable)
        ru, rv = _residuals(points, *targets, floor)
        r = np.stack([ru[ii, jj], rv[ii, jj]], -1).ravel()
        jtj = (jac.T @ jac).tocsc()
        diag = jtj.diagonal()
        scale = np.where(diag > 0, diag, max(float(diag.max(initial=0.0)), 1e-300))
        grad = jac.T @ r
        improved = False
        while damping <= _DAMPING[1]:
            delta = spsolve(jtj + sp.diags(damping * scale, format="csc"), -grad)
            if not np.all(np.isfinite(delta)):
                damping *= 10.0
                continue
            trial_uv = uv.copy()
            lo, hi = _neighbour_box(uv)
            moved = uv[ii + 1, jj + 1] + delta.reshape(-1, 2)
            trial_uv[ii + 1, jj + 1] = np.clip(moved, lo[ii, jj], hi[ii, jj])
            trial_points = points.copy()
            trial_points[ii + 1, jj + 1] = surface.evaluate(trial_uv[ii + 1, jj + 1, 0],
                                                            trial_uv[ii + 1, jj + 1, 1])
            trial = _sum_squares(trial_points, targets, floor, rows)
            if trial < cost:
                uv, points, improved = trial_uv, trial_points, True
                damping = max(damping / 10.0, _DAMPING[0])
                break
            damping *= 10.0
        if not improved:
            break
        accepted += 1
        stalled = stalled + 1 if trial > (1.0 - _STALL) * cost else 0
        cost = trial
        if stalled >= 3 or np.sqrt(cost / r.size) < 1e-2 * PENALTY_TOL:
            break
    return uv, points, accepted


def _spread(moved: NDArray) -> NDArray:
    """Nodes that moved or have a moved 4-neighbour."""
    out = moved.copy()
    out[1:] |= moved[:-1]
    out[:-1] |= moved[1:]
    out[:, 1:] |= moved[:, :-1]
    out[:, :-1] |= moved[:, 1:]
    return out


def relocate(surface: NurbsSurface, uv: NDArray, fractions_u: NDArray, fractions_v: NDArray,
             *, max_sweeps: int = 2000, penalty_tol: float = PENALTY_TOL,
             fixed: NDArray | None = None) -> RelocationResult:
    """Move the interior nodes until no node with a penalty above ``penalty_tol`` moves.

    Parameters
    ----------
    surface : NurbsSurface
        The original surface.
    uv : (n_u, n_v, 2) float
        Original-domain parameters of the nodes (boundary nodes are kept).
    fractions_u, fractions_v : (n_u,), (n_v,) float
        The reconciled parameters of the nodes (any scale).
    max_sweeps : int
    penalty_tol : float
    fixed : (n_u, n_v) bool, optional
        Nodes that never move besides the boundary (crease lines).

    Returns
    -------
    RelocationResult
        When the sweeps ran out with a worse largest penalty than at the
        start, the start grid (``converged`` False).
    """
    uv0 = np.array(uv, dtype=float)
    uv = uv0.copy()
    points = surface.evaluate(uv[..., 0], uv[..., 1])
    targets = (_targets(fractions_u), _targets(fractions_v))
    size = float(np.ptp(points.reshape(-1, points.shape[-1]), axis=0).max(initial=0.0))
    floor = 1e-12 * max(size, 1e-300)
    inner = (uv.shape[0] - 2, uv.shape[1] - 2)
    if min(inner) <= 0:
        return RelocationResult(uv, points, 0, True, 0.0, 0.0)
    colour = (np.add.outer(np.arange(inner[0]), np.arange(inner[1])) % 2).astype(bool)
    pen = penalties(points, fractions_u, fractions_v, floor)
    before = float(pen.max())
    movable = np.ones(inner, bool) if fixed is None else ~np.asarray(fixed)[1:-1, 1:-1]
    uv, points, newton = solve_globally(surface, uv, points, targets, floor, movable)
    candidates = movable.copy()
    sweeps, converged = 0, False
    while sweeps < max_sweeps:
        sweeps += 1
        moved = np.zeros(inner, bool)
        pen = penalties(points, fractions_u, fractions_v, floor)
        active = candidates & (pen > penalty_tol)
        if not np.any(active):
            converged = True
            break
        worst = np.unravel_index(np.argmax(np.where(active, pen, -1.0)), inner)
        first = colour[worst]
        for c in (first, not first):
            selected = active & (colour == c)
            if np.any(selected):
                moved |= _move(surface, uv, points, selected, targets, floor)
        if not np.any(moved):
            converged = True
            break
        candidates = _spread(moved) & movable
    after = float(penalties(points, fractions_u, fractions_v, floor).max())
    if not converged and after > before:         # wandered off: keep the start
        start = np.array(uv0)
        return RelocationResult(start, surface.evaluate(start[..., 0], start[..., 1]), sweeps,
                                False, before, before)
    return RelocationResult(uv, points, sweeps, converged, before, after, newton)
