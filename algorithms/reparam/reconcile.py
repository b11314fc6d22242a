"""Reconciliation of opposite boundary curves (000 §29.2.5): the RCA parametrization.

Each boundary carries its own interpolation points, expressed as fractions of
its arc length. For every point of one set a point at the same fraction is
sought in the other set; when none lies within the matching tolerance, an
auxiliary point is inserted into the set that lacks it. Matched pairs become
one fraction (their mean). Afterwards both curves carry the same fractions,
i.e. one knot sequence for the direction, and along both curves the ratio of
neighbouring distances equals the ratio of parameter steps (eqs. 29.1/29.2).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["MATCH_FRACTION", "insert_midpoints", "reconcile_fractions"]

#: Two fractions match when closer than this share of the smaller neighbouring step.
MATCH_FRACTION = 0.25


def reconcile_fractions(*sets: NDArray | None) -> NDArray:
    """One increasing fraction sequence from 0 to 1 that serves all ``sets``.

    Parameters
    ----------
    *sets : (n_k,) float or None
        Arc-length fractions of the interpolation points of each curve of one
        direction (usually the two opposite boundaries), each increasing from
        0 to 1; ``None`` for a collapsed curve (a pole), which takes the others'.

    Returns
    -------
    (m,) float
        The union in which a cluster of values of different sets (at most one
        per set) spanning less than :data:`MATCH_FRACTION` of the smallest own
        step of its members is merged into its mean (a matched point: with
        three or more lines - boundaries and creases - a pairwise match left
        clusters of nearly equal fractions, tiny knot intervals that fold the
        relocation); every other value is an auxiliary point for the sets that
        lack it.
    """
    given = [np.asarray(s, dtype=float) for s in sets if s is not None]
    if not given:
        raise ValueError("need at least one fraction set")
    values = np.concatenate(given)
    owner = np.concatenate([np.full(len(s), k) for k, s in enumerate(given)])
    own_step = np.concatenate([_own_steps(s) for s in given])
    order = np.argsort(values, kind="stable")
    values, owner, own_step = values[order], owner[order], own_step[order]
    out, cluster = [], [0]
    for k in range(1, values.size):      # greedy left to right: clusters of matched points
        members = owner[cluster]
        reach = MATCH_FRACTION * min(own_step[cluster].min(), own_step[k])
        if (values[k] - values[cluster[0]] <= reach and owner[k] not in members) \
                or values[k] == values[cluster[-1]]:
            cluster.append(k)
        else:
            out.append(values[cluster].mean())
            cluster = [k]
    out.append(values[cluster].mean())
    out = np.unique(np.clip(out, 0.0, 1.0))
    out[0], out[-1] = 0.0, 1.0
    return out


def _own_steps(fractions: NDArray) -> NDArray:
    """Smaller neighbouring step of every value within its own set ``(n,)``."""
    gaps = np.diff(fractions)
    padded = np.concatenate([[np.inf], gaps, [np.inf]])
    return np.minimum(padded[:-1], padded[1:])


def insert_midpoints(fractions: NDArray, intervals: NDArray) -> NDArray:
    """``fractions`` with the midpoints of the flagged ``intervals (n-1,) bool`` added."""
    mid = 0.5 * (fractions[:-1] + fractions[1:])
    return np.sort(np.concatenate([fractions, mid[np.asarray(intervals, bool)]]))
