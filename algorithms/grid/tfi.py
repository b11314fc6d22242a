"""Transfinite interpolation weighted by normalized arc length (003, "remapping").

The *distribution mesh* of a four-sided grid is the grid in the unit square whose
node ``(i, j)`` is the crossing of the straight line from ``(a_i, 0)`` to
``(b_i, 1)`` with the line from ``(0, c_j)`` to ``(1, d_j)``, where ``a, b`` are
the normalized arc lengths of the nodes along the sides ``j = 0`` and
``j = nj - 1`` and ``c, d`` those along ``i = 0`` and ``i = ni - 1``. Solving the
two line equations ``s = a + t (b - a)``, ``t = c + s (d - c)``:

.. math::

    s_{ij} = \\frac{a_i + c_j (b_i - a_i)}{1 - (b_i - a_i)(d_j - c_j)}, \\qquad
    t_{ij} = \\frac{c_j + a_i (d_j - c_j)}{1 - (b_i - a_i)(d_j - c_j)}.

Used as the blending weights of transfinite interpolation (Soni's weighted TFI,
003 ref. [5]), it carries the boundary distributions into the interior, and the
interpolation of four straight sides with uniform nodes is the bilinear map,
exactly. The same mesh, taken as the (normalized) parameters of a surface whose
sides have the desired arc-length distributions, is 003's redistribution.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...errors import InvalidGeometryError

__all__ = ["carried_inward", "distribution_mesh", "normalized_arc_length", "transfinite"]


def _fractions(x: ArrayLike, name: str) -> NDArray:
    x = np.asarray(x, dtype=float)
    if x.ndim != 1 or x.size < 2 or not np.all(np.isfinite(x)):
        raise InvalidGeometryError(f"{name} must be a 1-D array of at least 2 finite fractions")
    if abs(x[0]) > 1e-12 or abs(x[-1] - 1.0) > 1e-12 or np.any(np.diff(x) < 0):
        raise InvalidGeometryError(f"{name} must run from 0 to 1 without decreasing")
    return x


def distribution_mesh(bottom: ArrayLike, top: ArrayLike, left: ArrayLike,
                      right: ArrayLike) -> tuple[NDArray, NDArray]:
    """The normalized arc-length distribution mesh of four side distributions.

    Parameters
    ----------
    bottom, top : (ni,) float
        Fractions along the sides ``j = 0`` and ``j = nj - 1`` (from 0 to 1).
    left, right : (nj,) float
        Fractions along the sides ``i = 0`` and ``i = ni - 1``.

    Returns
    -------
    s, t : (ni, nj) float
        The mesh in the unit square; its sides are the four distributions.

    Examples
    --------
    >>> s, t = distribution_mesh([0, .5, 1], [0, .5, 1], [0, 1], [0, 1])
    >>> s[:, 0].tolist(), t[0].tolist()
    ([0.0, 0.5, 1.0], [0.0, 1.0])
    """
    a, b = _fractions(bottom, "bottom"), _fractions(top, "top")
    c, d = _fractions(left, "left"), _fractions(right, "right")
    if a.size != b.size or c.size != d.size:
        raise InvalidGeometryError(
            f"opposite sides need the same node count: bottom {a.size}, top {b.size}, "
            f"left {c.size}, right {d.size}")
    ba = (b - a)[:, None]
    dc = (d - c)[None, :]
    den = 1.0 - ba * dc       # > 0: |b - a| < 1 and |d - c| < 1 except at the corners
    s = (a[:, None] + c[None, :] * ba) / den
    t = (c[None, :] + a[:, None] * dc) / den
    s[:, 0], s[:, -1], s[0, :], s[-1, :] = a, b, 0.0, 1.0
    t[0, :], t[-1, :], t[:, 0], t[:, -1] = c, d, 0.0, 1.0
    return s, t


def normalized_arc_length(points: ArrayLike) -> NDArray:
    """Cumulative chord length of a polyline, divided by its total.

    Parameters
    ----------
    points : (n, d) float

    Returns
    -------
    (n,) float from 0 to 1 (uniform for a polyline of zero length: a collapsed side).
    """
    p = np.asarray(points, dtype=float)
    legs = np.linalg.norm(np.diff(p, axis=0), axis=1)
    total = legs.sum()
    if not total > 0.0:
        return np.linspace(0.0, 1.0, p.shape[0])
    x = np.concatenate([[0.0], np.cumsum(legs)]) / total
    x[-1] = 1.0
    return x


def transfinite(bottom: ArrayLike, top: ArrayLike, left: ArrayLike, right: ArrayLike, *,
                weights: tuple[ArrayLike, ArrayLike] | None = None) -> NDArray:
    """Transfinite interpolation of four sides of nodes, blended by arc length.

    .. math::

        x_{ij} = (1 - t) B_i + t T_i + (1 - s) L_j + s R_j
                 - [(1-s)(1-t) P_{00} + s (1-t) P_{10} + (1-s) t P_{01} + s t P_{11}]

    with ``(s, t) = (s_ij, t_ij)`` the :func:`distribution_mesh` of the sides'
    normalized arc lengths (or the ``weights`` given).

    Parameters
    ----------
    bottom, top : (ni, d) float
        Nodes of the sides ``j = 0`` and ``j = nj - 1``, in increasing ``i``.
    left, right : (nj, d) float
        Nodes of the sides ``i = 0`` and ``i = ni - 1``, in increasing ``j``.
    weights : ((ni, nj) float, (ni, nj) float), optional
        The blending ``(s, t)``; default the arc-length distribution mesh.

    Returns
    -------
    (ni, nj, d) float, equal to the given sides on the boundary.

    Raises
    ------
    InvalidGeometryError
        Sizes that do not match, or corners that are not shared.
    """
    B, T = np.asarray(bottom, dtype=float), np.asarray(top, dtype=float)
    L, R = np.asarray(left, dtype=float), np.asarray(right, dtype=float)
    if B.ndim != 2 or B.shape != T.shape or L.ndim != 2 or L.shape != R.shape \
            or B.shape[1] != L.shape[1]:
        raise InvalidGeometryError(
            f"sides must be (ni, d), (ni, d), (nj, d), (nj, d) arrays, got {B.shape}, {T.shape}, "
            f"{L.shape}, {R.shape}")
    scale = max(float(np.ptp(np.concatenate([B, T, L, R]), axis=0).max()), 1.0)
    for name, p, q in (("bottom-left", B[0], L[0]), ("bottom-right", B[-1], R[0]),
                       ("top-left", T[0], L[-1]), ("top-right", T[-1], R[-1])):
        if np.linalg.norm(p - q) > 1e-9 * scale:
            raise InvalidGeometryError(f"the {name} corner is not shared by its two sides")
    if weights is None:
        s, t = distribution_mesh(normalized_arc_length(B), normalized_arc_length(T),
                                 normalized_arc_length(L), normalized_arc_length(R))
    else:
        s, t = (np.asarray(w, dtype=float) for w in weights)
        if s.shape != (B.shape[0], L.shape[0]) or t.shape != s.shape:
            raise InvalidGeometryError(f"weights must be two ({B.shape[0]}, {L.shape[0]}) arrays")
    s, t = s[..., None], t[..., None]
    x = ((1 - t) * B[:, None] + t * T[:, None] + (1 - s) * L[None] + s * R[None]
         - ((1 - s) * (1 - t) * B[0] + s * (1 - t) * B[-1] + (1 - s) * t * T[0] + s * t * T[-1]))
    x[:, 0], x[:, -1], x[0], x[-1] = B, T, L, R
    return x


def carried_inward(before: ArrayLike, after: ArrayLike) -> NDArray:
    """The grid ``before`` with its boundary moved to that of ``after``, the moves of the
    sides carried into the interior by :func:`transfinite` interpolation.

    A grid refined before whose side nodes then slid (along the sides, the corners
    held) is a poor start for an iterative smoother if only its boundary moves: a smooth
    slide of a whole side is the long-wave error relaxation sweeps remove slowest. The
    displacement ``d`` of the sides, interpolated transfinitely with the weights of the
    grid's own lines (normalized arc length along each line of ``before``), is added to
    every node; the result equals ``after`` on the boundary.

    Parameters
    ----------
    before, after : (ni, nj, d) float
        Two grids; only the boundary of ``after`` is read. Their corners must agree.

    Returns
    -------
    (ni, nj, d) float
    """
    a, b = np.asarray(before, dtype=float), np.asarray(after, dtype=float)
    if a.ndim != 3 or a.shape != b.shape or min(a.shape[:2]) < 2:
        raise InvalidGeometryError(f"before and after must be two (ni, nj, d) grids of one shape, "
                                   f"got {a.shape} and {b.shape}")
    d = b - a
    legs_i = np.linalg.norm(np.diff(a, axis=0), axis=-1)            # (ni - 1, nj)
    legs_j = np.linalg.norm(np.diff(a, axis=1), axis=-1)            # (ni, nj - 1)
    along_i = np.concatenate([np.zeros((1, a.shape[1])), np.cumsum(legs_i, axis=0)])
    along_j = np.concatenate([np.zeros((a.shape[0], 1)), np.cumsum(legs_j, axis=1)], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(along_i[-1] > 0, along_i / along_i[-1], np.linspace(0, 1, a.shape[0])[:, None])
        t = np.where(along_j[:, -1:] > 0, along_j / along_j[:, -1:], np.linspace(0, 1, a.shape[1])[None])
    moved = a + transfinite(d[:, 0], d[:, -1], d[0], d[-1], weights=(s, t))
    moved[0], moved[-1], moved[:, 0], moved[:, -1] = b[0], b[-1], b[:, 0], b[:, -1]
    return moved
