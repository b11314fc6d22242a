"""Bicubic B-spline surfaces through the projected grid (001 §6, eqs. 16-18; 003).

:attr:`Interpolant.C1_BICUBIC` (001, the default): a piecewise bicubic Bézier
surface written as a B-spline with quadruple end knots and triple interior
knots at the uniform values ``ξ_I = I / M``, ``η_J = J / N`` (eq. 17), control
net ``(3M + 1) x (3N + 1)`` (``m = 3M``, ``n = 3N``, eq. 16):

* ``d_{3I,3J} = q_{I,J}``, the grid points;
* the legs along each row and column from central differences,
  ``d_{3I±1,3J} = q_{I,J} ± (q_{I+1,J} - q_{I-1,J}) / 6`` (the derivative
  ``(q_{I+1} - q_{I-1}) / (2 h)`` times ``h / 3``; at the ends the derivative of
  the parabola through the first, respectively last, three points), which is
  C1 across the interior knots because the spacing is uniform;
* the four interior points of every patch from its corners by eq. (18),
  ``d_{3I±1,3J±1} = d_{3I±1,3J} + (d_{3I,3J±1} - d_{3I,3J})``, the coplanarity
  that makes the surface C1 across patch boundaries.

:attr:`Interpolant.C2_BICUBIC` (003): the classical C2 bicubic spline
interpolating the grid at the uniform parameters (not-a-knot knots,
:func:`..fitting.interpolate_surface`), ``(M + 1) x (N + 1)`` control points.
"""

from __future__ import annotations

import enum

import numpy as np
from numpy.typing import NDArray

from ..fitting import interpolate_surface, knots_from_breakpoints
from ..surface import NurbsSurface

__all__ = ["Interpolant", "c1_bicubic", "c2_bicubic", "interpolate_grid", "triple_knots"]


class Interpolant(enum.Enum):
    """The bicubic surface through the grid."""

    #: 001 eqs. 16-18: C1, triple interior knots, control net (3M + 1) x (3N + 1)
    C1_BICUBIC = "c1"
    #: 003: C2 cubic spline interpolation, control net (M + 1) x (N + 1)
    C2_BICUBIC = "c2"


def triple_knots(m: int) -> NDArray:
    """Knot vector of eq. (17): ``(0,0,0,0, ξ_1 x3, ..., ξ_{M-1} x3, 1,1,1,1)``, ``ξ_I = I/M``."""
    inner = np.repeat(np.arange(1, m) / m, 3)
    return np.concatenate([np.zeros(4), inner, np.ones(4)])


def _legs(q: NDArray) -> NDArray:
    """Bézier legs ``h C'(ξ_I) / 3`` along axis 0 (central differences, parabolic ends)."""
    legs = np.empty_like(q)
    legs[1:-1] = (q[2:] - q[:-2]) / 6.0
    legs[0] = (-3.0 * q[0] + 4.0 * q[1] - q[2]) / 6.0
    legs[-1] = (3.0 * q[-1] - 4.0 * q[-2] + q[-3]) / 6.0
    return legs


def c1_bicubic(points: NDArray) -> NurbsSurface:
    """The C1 bicubic interpolant of 001 (eqs. 16-18, module docstring).

    Parameters
    ----------
    points : (M + 1, N + 1, 3) float, ``M, N >= 2``

    Returns
    -------
    NurbsSurface
        Degrees (3, 3), knots of eq. (17), ``S(I/M, J/N) = q_{I,J}``.
    """
    q = np.asarray(points, dtype=float)
    m, n = q.shape[0] - 1, q.shape[1] - 1
    lu = _legs(q)
    lv = np.swapaxes(_legs(np.swapaxes(q, 0, 1)), 0, 1)
    net = np.zeros((3 * m + 1, 3 * n + 1, 3))
    for su in (-1, 0, 1):
        for sv in (-1, 0, 1):
            # every corner I, J gives d_{3I+su, 3J+sv} = q + su lu + sv lv (eq. 18)
            i0, i1 = (1, m + 1) if su < 0 else (0, m if su > 0 else m + 1)
            j0, j1 = (1, n + 1) if sv < 0 else (0, n if sv > 0 else n + 1)
            block = q[i0:i1, j0:j1] + su * lu[i0:i1, j0:j1] + sv * lv[i0:i1, j0:j1]
            net[3 * i0 + su:3 * (i1 - 1) + su + 1:3, 3 * j0 + sv:3 * (j1 - 1) + sv + 1:3] = block
    return NurbsSurface(net, triple_knots(m), triple_knots(n), 3, 3)


def c2_bicubic(points: NDArray) -> NurbsSurface:
    """The C2 bicubic spline through the grid at uniform parameters (003).

    Parameters
    ----------
    points : (M + 1, N + 1, 3) float, ``M, N >= 3``
    """
    q = np.asarray(points, dtype=float)
    tu = np.linspace(0.0, 1.0, q.shape[0])
    tv = np.linspace(0.0, 1.0, q.shape[1])
    return interpolate_surface(q, params_u=tu, params_v=tv,
                               knots_u=knots_from_breakpoints(tu, 3),
                               knots_v=knots_from_breakpoints(tv, 3))


def interpolate_grid(points: NDArray, interpolant: Interpolant) -> NurbsSurface:
    """The chosen interpolant of a ``(M + 1, N + 1, 3)`` grid."""
    if interpolant is Interpolant.C2_BICUBIC:
        return c2_bicubic(points)
    return c1_bicubic(points)
