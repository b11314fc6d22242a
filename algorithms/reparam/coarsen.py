"""Fewer interpolation lines where the dense error leaves headroom (after 000 §29.2.3).

The error loop of :mod:`.rca` only ever adds grid lines, and it adds them in
whole batches (every interval that is off gets its midpoint), so a finished fit
usually has more lines than the tolerance needs. This step removes them again:

* a grid line is a *candidate* when the largest dense error (eq. 29.3) in the
  cells on both sides of it is below :data:`HEADROOM` ``* tol`` - merging two
  intervals of a C2 cubic interpolant doubles ``h`` and multiplies the error
  by about ``2^4 = 16``;
* every other candidate (never two neighbours, never a boundary or a crease
  line) is dropped at once, the surface is interpolated again through the
  remaining nodes (they keep their relocated positions, so the chord-length
  conditions 29.1/29.2 still hold between them) and measured densely again;
* the coarser fit is kept only if it is within ``tol``; a rejected batch is
  retried once with a stricter headroom, then that direction is done.

The dense error check is the arbiter: nothing is accepted that it has not
measured within ``tol``.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["HEADROOM", "RESPACE_TARGET", "Fit", "coarsen", "respaced_fractions"]

#: Cells on both sides of a line below this share of ``tol``: the line may go.
HEADROOM = 0.25
#: Headroom of the single retry after a rejected batch.
STRICT_HEADROOM = 1.0 / 16.0
#: Error aimed at per direction (share of ``tol``) when the point sets are respaced
#: (a cell's error is about the sum of its u and v parts, hence below one half).
RESPACE_TARGET = 0.45
#: Largest factor by which one interval may grow or shrink in a respacing.
RESPACE_LIMITS = (0.5, 2.0)
#: Batches tried at most (each costs one fit and one dense measurement).
MAX_BATCHES = 12


@dataclass(frozen=True)
class Fit:
    """A measured fit on a subset of the grid lines.

    Attributes
    ----------
    keep_u, keep_v : (n_u,), (n_v,) bool
        Lines of the full grid that are interpolated.
    worst : float
        Largest dense distance, both ways.
    cell_errors : (k_u - 1, k_v - 1) float
        Largest distance per cell of the kept grid.
    payload : object
        What the caller's fit returned (the surface and its parameters).
    """

    keep_u: NDArray
    keep_v: NDArray
    worst: float
    cell_errors: NDArray
    payload: object


def _candidates(keep: NDArray, fixed: NDArray, interval_errors: NDArray, limit: float,
                min_lines: int) -> NDArray:
    """Every other kept, not fixed line with both neighbouring intervals below ``limit``,
    leaving at least ``min_lines`` lines (ends included) in every piece between fixed lines."""
    kept = np.nonzero(keep)[0]                       # indices into the full grid
    drop = np.zeros_like(keep)
    previous_dropped, in_piece, dropped = False, 1, 0
    for k in range(1, kept.size):
        line = kept[k]
        if fixed[line]:                              # a piece ends: undo drops beyond its budget
            in_piece += 1
            piece = np.nonzero(drop[kept[k - in_piece + 1]:line])[0] + kept[k - in_piece + 1]
            excess = dropped - max(in_piece - min_lines, 0)
            if excess > 0:
                drop[piece[-excess:]] = False
            previous_dropped, in_piece, dropped = False, 1, 0
            continue
        in_piece += 1
        quiet = max(interval_errors[k - 1], interval_errors[k]) < limit
        if quiet and not previous_dropped:
            drop[line] = True
            dropped += 1
            previous_dropped = True
        else:
            previous_dropped = False
    return drop


def coarsen(fit: Callable[[NDArray, NDArray], Fit], start: Fit, fixed_u: NDArray,
            fixed_v: NDArray, tol: float, min_lines: int = 4) -> Fit:
    """Drop grid lines while the dense error stays within ``tol`` (module docstring).

    Parameters
    ----------
    fit : callable ``(keep_u, keep_v) -> Fit``
        Interpolates through the kept lines and measures densely.
    start : Fit
        The fit on all lines, within ``tol``.
    fixed_u, fixed_v : (n_u,), (n_v,) bool
        Lines that must stay (boundaries, creases).
    tol : float
    min_lines : int
        Lines at least in every piece between fixed lines (ends included).

    Returns
    -------
    Fit
        The coarsest accepted fit (``start`` if nothing could go).
    """
    best = start
    open_dirs = {0: HEADROOM, 1: HEADROOM}
    for _ in range(MAX_BATCHES):
        if not open_dirs:
            break
        axis = max(open_dirs, key=lambda a: int((best.keep_u, best.keep_v)[a].sum()))
        keep = (best.keep_u, best.keep_v)[axis]
        intervals = best.cell_errors.max(axis=1 - axis)
        drop = _candidates(keep, (fixed_u, fixed_v)[axis], intervals, open_dirs[axis] * tol,
                           min_lines)
        if not np.any(drop):
            del open_dirs[axis]
            continue
        trial_keep = keep & ~drop
        trial = fit(trial_keep, best.keep_v) if axis == 0 else fit(best.keep_u, trial_keep)
        if trial.worst <= tol:
            best = trial
        elif open_dirs[axis] > STRICT_HEADROOM:
            open_dirs[axis] = STRICT_HEADROOM
        else:
            del open_dirs[axis]
    return best


def respaced_fractions(fractions: NDArray, interval_errors: NDArray, tol: float,
                       f_breaks: NDArray, target: float = RESPACE_TARGET,
                       min_points: int = 4, grow: bool = True) -> NDArray:
    """A new point set whose intervals aim at ``target * tol`` (the h^4 law).

    An interval of width ``h`` with error ``e`` wants width
    ``h (target tol / e)^(1/4)`` (within :data:`RESPACE_LIMITS`); the wanted
    density ``1 / width`` is integrated over each piece between crease
    fractions ``f_breaks`` and the piece gets ``ceil`` of it intervals (at least
    ``min_points - 1``) at equal steps of the integral. With ``grow`` False no
    interval may grow (refining a point set that missed ``tol``).

    Parameters
    ----------
    fractions : (n,) float
        Current common fractions, 0 to 1, containing ``f_breaks``.
    interval_errors : (n - 1,) float
        Largest dense error per interval (model units).

    Returns
    -------
    (m,) float
    """
    h = np.diff(fractions)
    factor = (target * tol / np.maximum(interval_errors, 1e-300 * tol)) ** 0.25
    density = 1.0 / (h * np.clip(factor, RESPACE_LIMITS[0], RESPACE_LIMITS[1] if grow else 1.0))
    effort = np.concatenate([[0.0], np.cumsum(density * h)])
    out = [np.array([0.0])]
    for a, b in itertools.pairwise(f_breaks):
        ia, ib = int(np.argmin(np.abs(fractions - a))), int(np.argmin(np.abs(fractions - b)))
        count = max(min_points - 1, int(np.ceil(effort[ib] - effort[ia] - 1e-9)))
        goal = np.linspace(effort[ia], effort[ib], count + 1)[1:]
        piece = np.interp(goal, effort[ia:ib + 1], fractions[ia:ib + 1])
        piece[-1] = b
        out.append(piece)
    return np.concatenate(out)
