"""The parameter domain cut along creases, for the closest-point Newton of
:mod:`.projection` and :mod:`.curve_projection`.

Knot lines of multiplicity >= degree may carry a jump of the first
derivatives, where Newton would stall: the domain is cut there into pieces and
each Newton problem runs inside one piece (its box).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from .basis import distinct_knots

__all__ = ["NUDGE", "CreasePieces"]

#: a piece's upper bound lies this share of the domain width below its crease
NUDGE = 1e-13


class CreasePieces:
    """The domain cut along knot lines of multiplicity >= degree (where the first
    derivatives may jump): per parameter, ``edges`` = domain ends and crease values.

    Newton works inside one piece (its box); a piece's upper bound is moved
    ``NUDGE`` of the domain width below the crease, so that evaluation there
    uses the piece's own polynomial (evaluation at a knot takes the right side).
    """

    def __init__(self, knot_vectors: list[NDArray], degrees: list[int]):
        self.edges = []
        for knots, p in zip(knot_vectors, degrees):
            values, mult = distinct_knots(knots, p)
            inner = values[1:-1][mult[1:-1] >= p]
            self.edges.append(np.concatenate([values[:1], inner, values[-1:]]))
        self.nudge = np.array([NUDGE * (e[-1] - e[0]) for e in self.edges])

    def index(self, x: NDArray) -> NDArray:
        """Piece of each parameter: (m, k) int."""
        return np.stack([np.clip(np.searchsorted(e, x[:, i], side="right") - 1, 0, e.size - 2)
                         for i, e in enumerate(self.edges)], axis=1)

    def bounds(self, piece: NDArray) -> tuple[NDArray, NDArray]:
        lo = np.stack([e[piece[:, i]] for i, e in enumerate(self.edges)], axis=1)
        hi = np.stack([np.where(piece[:, i] + 2 < e.size, e[piece[:, i] + 1] - self.nudge[i],
                                e[piece[:, i] + 1]) for i, e in enumerate(self.edges)], axis=1)
        return lo, hi

    def axis_index(self, axis: int, values: NDArray) -> NDArray:
        """Piece of parameter values along one axis: (s,) int."""
        e = self.edges[axis]
        return np.clip(np.searchsorted(e, values, side="right") - 1, 0, e.size - 2)

    def split_seeds(self, rows: NDArray, x0: NDArray) -> tuple[NDArray, NDArray]:
        """Seeds on a crease start on both of its sides (a local minimum may hide on
        either): duplicated rows and start points."""
        for i, e in enumerate(self.edges):
            on = np.isin(x0[:, i], e[1:-1])
            extra = x0[on].copy()
            extra[:, i] -= self.nudge[i]
            rows, x0 = np.concatenate([rows, rows[on]]), np.concatenate([x0, extra])
        return rows, x0

    def crossings(self, local: Callable, x: NDArray, targets: NDArray, piece: NDArray
                  ) -> tuple[NDArray, NDArray, NDArray]:
        """Problems stopped on a crease with descent on its other side.

        Returns the mask (m,), their new pieces (m, k) and start points (m, k).
        """
        lo, hi = self.bounds(piece)
        count = np.array([e.size - 1 for e in self.edges])
        up = (x >= hi) & (piece + 1 < count)
        down = (x <= lo) & (piece > 0)
        moved = np.where(up, piece + 1, np.where(down, piece - 1, piece))
        new_lo, new_hi = self.bounds(moved)
        start = np.where(up, new_lo, np.where(down, new_hi, x))
        candidates = np.flatnonzero((up | down).any(axis=1))
        if candidates.size == 0:          # surfaces cannot evaluate 0 points
            return np.zeros(x.shape[0], dtype=bool), piece, x
        f, jac, _ = local(start[candidates])
        gradient = np.einsum("md,mdk->mk", f - targets[candidates], jac)
        descend = (up[candidates] & (gradient < 0)) | (down[candidates] & (gradient > 0))
        cross = np.zeros(x.shape[0], dtype=bool)
        cross[candidates] = descend.any(axis=1)
        keep = np.zeros_like(up)
        keep[candidates] = descend
        return cross, np.where(keep, moved, piece), np.where(keep, start, x)

    def beside(self, x: NDArray, piece: NDArray, reach: float
               ) -> tuple[NDArray, NDArray, NDArray]:
        """Problems whose point ``x (m, k)`` lies within ``reach`` of its piece's width
        from an inner crease (not on it): their rows, the neighbouring pieces
        ``(q, k)`` and start points ``(q, k)`` on the crease's other side (one crease
        per problem: the nearest, along the first axis that has one)."""
        lo, hi = self.bounds(piece)
        width = np.maximum(hi - lo, 1e-300)
        count = np.array([e.size - 1 for e in self.edges])
        near_hi = (hi - x <= reach * width) & (x < hi) & (piece + 1 < count)
        near_lo = (x - lo <= reach * width) & (x > lo) & (piece > 0)
        near = near_hi | near_lo
        rows = np.flatnonzero(near.any(axis=1))
        if rows.size == 0:
            return rows, piece[:0], x[:0]
        axis = np.argmax(near[rows], axis=1)
        up = near_hi[rows, axis]
        moved = piece[rows].copy()
        moved[np.arange(rows.size), axis] += np.where(up, 1, -1)
        new_lo, new_hi = self.bounds(moved)
        start = x[rows].copy()
        pick = np.arange(rows.size)
        start[pick, axis] = np.where(up, new_lo[pick, axis], new_hi[pick, axis])
        return rows, moved, start
