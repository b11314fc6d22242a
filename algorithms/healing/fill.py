"""Positions over holes: the fill of the artificial projections (001 §5, eqs. 12-15;
000 §29.3.4).

Where a segment ``a b`` of the local approximant hits nothing (a hole or gap in
the original geometry) its position ``t`` on the segment is interpolated from
the positions found elsewhere, as a bivariate function of the grid parameters
``(u, v)``; the artificial projection is ``z = (1 - t) a + t b`` (eq. 15).
Three methods (:class:`FillMethod`):

==================  ================================================  ====================
method              interpolant                                       data used
==================  ================================================  ====================
``HARDY_LOCAL``     Hardy's reciprocal multiquadric,                  the ``K`` nearest
                    :math:`\\sum_i c_i (R + |x - x_i|^2)^{-\\gamma}`    found (eq. 13, 14)
``HARDY_GLOBAL``    the same kernel                                   all found (eq. 12)
``THIN_PLATE``      thin-plate spline :math:`r^2 \\log r` plus a       all found up to
                    linear polynomial (not Hardy's kernel)            1500, else the 64
                                                                      nearest
==================  ================================================  ====================

Hardy's method is the one of 001 §5, with ``R = (δ_u + δ_v) / 2`` (mean
parameter spacings, :func:`hardy_parameters`) and ``γ = 0.001``; the localized
form uses the at least ``K`` found positions nearest in the Manhattan norm of the
grid indices (eq. 13: all at index distance 1, then 2, ... until ``K`` is reached
or exceeded). The thin-plate spline is the smoothest interpolant of the found
positions (it minimises the bending energy; no ``R`` or ``γ`` to tune) and,
with the ring of projections beyond a hole's rim (:mod:`.ring`), continues the
surroundings' slope and bending into the hole: it is the default of
:func:`.approximant.local_approximant`.

References
----------
.. [H71] R. L. Hardy, "Multiquadric equations of topography and other irregular
   surfaces", *Journal of Geophysical Research* 76(8), 1905-1915, 1971.
.. [D77] J. Duchon, "Splines minimizing rotation-invariant semi-norms in Sobolev
   spaces", in *Constructive Theory of Functions of Several Variables*, Lecture
   Notes in Mathematics 571, Springer, 1977, 85-100.
.. [001] B. Hamann, B. A. Jean, "Interactive surface correction based on a local
   approximation scheme", *Computer Aided Geometric Design* 13(4), 351-368, 1996, §5.
"""

from __future__ import annotations

import enum

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import RBFInterpolator

from ...errors import DegenerateGeometryError

__all__ = ["HARDY_GAMMA", "FillMethod", "fill_positions", "hardy_parameters"]

#: the exponent of 001 §5
HARDY_GAMMA = 0.001
#: thin-plate fill: one global system up to this many found positions
THIN_PLATE_GLOBAL = 1500
#: ... else each missing position from this many nearest found ones
THIN_PLATE_NEIGHBOURS = 64


class FillMethod(enum.Enum):
    """How the missing positions are interpolated from the found ones (module docstring)."""

    #: Hardy's reciprocal multiquadric over the K Manhattan-nearest found positions
    #: of every missing one (001 eq. 14)
    HARDY_LOCAL = "hardy_local"
    #: Hardy's reciprocal multiquadric over all found positions, one system (001 eq. 12)
    HARDY_GLOBAL = "hardy_global"
    #: the thin-plate spline ``r^2 log r`` plus a linear polynomial: not Hardy's kernel
    #: (the smoothest interpolant; with the ring of :mod:`.ring` it continues the
    #: surroundings' slope and bending into a hole); over all found positions up to
    #: :data:`THIN_PLATE_GLOBAL`, else the :data:`THIN_PLATE_NEIGHBOURS` nearest
    THIN_PLATE = "thin_plate"


def hardy_parameters(u: NDArray, v: NDArray) -> float:
    """``R = (δ_u + δ_v) / 2`` from the mean spacings of the boundary parameters (001 §5).

    Parameters
    ----------
    u, v : (M + 1, N + 1) float
    """
    du = 0.5 * (np.mean(np.diff(u[:, 0])) + np.mean(np.diff(u[:, -1])))
    dv = 0.5 * (np.mean(np.diff(v[0, :])) + np.mean(np.diff(v[-1, :])))
    return 0.5 * float(du + dv)


def _kernel(du: NDArray, dv: NDArray, radius: float, gamma: float) -> NDArray:
    return (radius + du * du + dv * dv) ** (-gamma)


def _solve(matrix: NDArray, rhs: NDArray) -> NDArray:
    """Batched solve, least squares where a system is singular."""
    try:
        return np.linalg.solve(matrix, rhs[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.stack([np.linalg.lstsq(m, r, rcond=None)[0] for m, r in zip(matrix, rhs,
                                                                              strict=True)])


def _global(u: NDArray, v: NDArray, t: NDArray, found: NDArray, radius: float,
            gamma: float) -> NDArray:
    uf, vf, tf = u[found], v[found], t[found]
    matrix = _kernel(uf[:, None] - uf[None], vf[:, None] - vf[None], radius, gamma)
    c = _solve(matrix[None], tf[None])[0]
    um, vm = u[~found], v[~found]
    return _kernel(um[:, None] - uf[None], vm[:, None] - vf[None], radius, gamma) @ c


def _local(u: NDArray, v: NDArray, t: NDArray, found: NDArray, radius: float,
           gamma: float, neighbours: int) -> NDArray:
    ii, jj = np.indices(found.shape)
    fi, fj = ii[found], jj[found]
    mi, mj = ii[~found], jj[~found]
    dist = np.abs(mi[:, None] - fi[None]) + np.abs(mj[:, None] - fj[None])   # eq. (13)
    k = min(neighbours, fi.size)
    kth = np.partition(dist, k - 1, axis=1)[:, k - 1]
    chosen = dist <= kth[:, None]                                           # "at least K"
    count = chosen.sum(axis=1)
    uf, vf, tf = u[found], v[found], t[found]
    um, vm = u[~found], v[~found]
    out = np.empty(mi.size)
    for size in np.unique(count):
        rows = np.flatnonzero(count == size)
        cols = np.nonzero(chosen[rows])[1].reshape(rows.size, size)
        pu, pv = uf[cols], vf[cols]                                         # (r, K)
        matrix = _kernel(pu[:, :, None] - pu[:, None], pv[:, :, None] - pv[:, None],
                         radius, gamma)
        c = _solve(matrix, tf[cols])
        weights = _kernel(um[rows, None] - pu, vm[rows, None] - pv, radius, gamma)
        out[rows] = np.einsum("rk,rk->r", weights, c)
    return out


def _thin_plate(u: NDArray, v: NDArray, t: NDArray, found: NDArray) -> NDArray:
    data = np.stack([u[found], v[found]], axis=1)
    near = None if data.shape[0] <= THIN_PLATE_GLOBAL else THIN_PLATE_NEIGHBOURS
    degree = 1 if data.shape[0] >= 3 else 0
    try:
        rbf = RBFInterpolator(data, t[found], kernel="thin_plate_spline", degree=degree,
                              neighbors=near)
        return rbf(np.stack([u[~found], v[~found]], axis=1))
    except (np.linalg.LinAlgError, ValueError):   # collinear data: Hardy's global form
        return _global(u, v, t, found, hardy_parameters(u, v), HARDY_GAMMA)


def fill_positions(u: NDArray, v: NDArray, t: NDArray, found: NDArray, *,
                   method: FillMethod = FillMethod.HARDY_LOCAL, neighbours: int = 8,
                   radius: float | None = None, gamma: float = HARDY_GAMMA) -> NDArray:
    """Segment positions ``t`` everywhere: found ones kept, missing ones filled by ``method``.

    Parameters
    ----------
    u, v : (M + 1, N + 1) float
        Grid parameters.
    t : (M + 1, N + 1) float
        Found positions (anything where ``found`` is False).
    found : (M + 1, N + 1) bool
    method : FillMethod
    neighbours : int
        ``K`` of Hardy's localized version (5-10 in 001).
    radius : float, optional
        ``R``; default :func:`hardy_parameters`.
    gamma : float

    Returns
    -------
    (M + 1, N + 1) float

    Raises
    ------
    DegenerateGeometryError
        No position was found at all (the boundary lies over no source).
    """
    if not np.any(found):
        raise DegenerateGeometryError(
            "no segment of the Coons patch meets the original surfaces: the boundary does not "
            "lie over them (or the offset distance is too small)")
    out = np.array(t, dtype=float)
    if np.all(found):
        return out
    r = hardy_parameters(u, v) if radius is None else float(radius)
    if method is FillMethod.THIN_PLATE:
        out[~found] = _thin_plate(u, v, out, found)
    elif method is FillMethod.HARDY_GLOBAL:
        out[~found] = _global(u, v, out, found, r, gamma)
    else:
        out[~found] = _local(u, v, out, found, r, gamma, max(1, int(neighbours)))
    return out
