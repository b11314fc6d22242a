"""Reconciliation of opposite boundary curves (section 29.2.5): the RCA parametrization.

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
        The union in which values of different sets closer than
        :data:`MATCH_FRACTION` of the smaller adjacent step are merged into
        their mean (a matched point); every other value is an auxiliary point
        for the sets that lack it.
    """
    given = [np.asarray(s, dtype=float) for s in sets if s is not None]
    if not given:
        raise ValueError("need at least one fraction set")
    values = np.concatenate(given)
    owner = np.concatenate([np.full(len(s), k) for k, s in enumerate(given)])
    order = np.argsort(values, kind="stable")
    values, owner = values[order], owner[order]
    gaps = np.diff(values)
    padded = np.concatenate([[np.inf], gaps, [np.inf]])
    neighbour = np.minimum(padded[:-2], padded[2:])               # (n-1,) steps beside
    candidate = ((owner[1:] != owner[:-1]) & (gaps <= MATCH_FRACTION * neighbour)) | (gaps == 0)
    keep = np.ones(values.size, bool)
    out = values.copy()
    k = 0
    while k < gaps.size:                 # greedy left to right: a point matches once
        if candidate[k]:
            out[k] = 0.5 * (values[k] + values[k + 1])
            keep[k + 1] = False
            k += 2
        else:
            k += 1
    out = np.unique(np.clip(out[keep], 0.0, 1.0))
    out[0], out[-1] = 0.0, 1.0
    return out


def insert_midpoints(fractions: NDArray, intervals: NDArray) -> NDArray:
    """``fractions`` with the midpoints of the flagged ``intervals (n-1,) bool`` added."""
    mid = 0.5 * (fractions[:-1] + fractions[1:])
    return np.sort(np.concatenate([fractions, mid[np.asarray(intervals, bool)]]))
