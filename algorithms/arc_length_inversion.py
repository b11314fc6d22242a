"""Arc length of a path known by its speed: short lengths by Gauss quadrature, and the
parameters at given lengths (the inverse of a tabulated arc length).

A grid side is a 3D curve (:func:`.grid.distribution.points_along`) or a pcurve seen
through its surface (:class:`.grid.region.Side`), an approximant's boundary curve is
sampled uniformly in arc length (:mod:`.healing.boundary`); all know their speed
``|dP/dt|`` and a fine table of ``(t, s(t))``. :func:`parameters_at_lengths` turns target lengths
into parameters the same way for both: monotone interpolation in the table, then
Newton on ``s(t) - target`` with the speed, each ``s(t)`` measured from the table's
nearest entry below by 8-point Gauss--Legendre (exact for polynomial speed of
degree 15, far below the table's cell size otherwise).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

__all__ = ["GAUSS_NODES", "GAUSS_WEIGHTS", "NEWTON_STEPS", "lengths_between",
           "parameters_at_lengths"]

#: 8-point Gauss--Legendre nodes and weights on [-1, 1]
GAUSS_NODES, GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(8)
#: Newton steps after the interpolated start (quadratic convergence from the table)
NEWTON_STEPS = 4


def lengths_between(speed: Callable[[NDArray], NDArray], a: NDArray, b: NDArray) -> NDArray:
    """Arc lengths from ``a`` to ``b`` (``(m,)`` each), 8-point Gauss on the speed.

    ``speed(t)`` takes and returns ``(k,)`` float arrays (``|dP/dt|``).
    """
    mid, half = 0.5 * (a + b), 0.5 * (b - a)
    nodes = mid[:, None] + half[:, None] * GAUSS_NODES[None, :]
    return half * (speed(nodes.reshape(-1)).reshape(nodes.shape) @ GAUSS_WEIGHTS)


def parameters_at_lengths(speed: Callable[[NDArray], NDArray], t: NDArray, s: NDArray,
                          target: NDArray, inner: NDArray) -> NDArray:
    """Parameters where the arc length reaches ``target``.

    Parameters
    ----------
    speed : callable, (k,) float -> (k,) float
        ``|dP/dt|``.
    t, s : (n,) float
        Increasing parameters and the arc length at each (``s[0] = 0``).
    target : (m,) float
        Lengths in ``[0, s[-1]]``.
    inner : (m,) bool
        The targets to polish by Newton (the others keep the interpolated start:
        the caller puts the ends exactly).

    Returns
    -------
    (m,) float, in ``[t[0], t[-1]]``.
    """
    out = np.interp(target, s, t)
    for _ in range(NEWTON_STEPS):
        if not np.any(inner):
            break
        ti = out[inner]
        k = np.clip(np.searchsorted(t, ti, side="right") - 1, 0, t.size - 2)
        base = s[k] + lengths_between(speed, t[k], ti)
        v = speed(ti)
        step = np.where(v > 0, (target[inner] - base) / np.maximum(v, 1e-300), 0.0)
        out[inner] = np.clip(ti + step, t[0], t[-1])
    return out
