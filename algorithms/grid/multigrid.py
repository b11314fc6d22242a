"""Coarse-grid corrections for the elliptic grid system: the full approximation scheme.

SOR sweeps (:mod:`.elliptic_kernels`) remove the short waves of the error in a few
sweeps and the long ones in about as many sweeps as the grid has nodes along a side:
on a 450 x 230 block the last decade of the residual took 300 sweeps. A long wave on
the fine grid is a short one on a grid of half the nodes, so the error left after a
few sweeps is corrected there, and the same recursively (a V-cycle).

The system is nonlinear (its coefficients are the grid's own metric), so the coarse
level carries the full solution, not an error (the full approximation scheme, FAS
[Brandt]): with ``u`` the fine parameters after the pre-sweeps, ``I u`` their
interpolation on the coarse nodes and ``R`` the operator of :func:`.elliptic_kernels.numerators`
(tangential part, at each level's own nodes),

.. math::

    R_c(u_c) = \\tau, \\qquad \\tau = R_c(I u) - \\rho\\, \\bar I R_f(u),

``rho = r_i^2 r_j^2`` the scaling of ``R`` with the index spacing (``R`` is the
metric, quadratic in the spacing, times second differences: the coarse grid's are
``r_i = (n_i - 1) / (n_{ci} - 1) ~ 2`` times the fine one's in each direction) and
``bar I`` a full-weighting restriction. The coarse solution's change
``u_c - I u`` is interpolated back and added to ``u``, then swept again. At a fine
solution ``R_f = 0``, ``tau = R_c(I u)`` and ``u_c = I u``: a solution is a fixed
point whatever the coarse grid's truncation error. The control functions go down
scaled with the spacing (``P r_xi`` keeps its weight when ``P`` scales as ``r_i``).

A correction that would fold a cell of the fine grid is halved, twice, then dropped.

References
----------
.. [Brandt] A. Brandt, "Multi-level adaptive solutions to boundary-value problems",
   Math. Comp. 31 (1977) 333-390 (FAS: section 8).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..surface import NurbsSurface
from .elliptic_kernels import folds, sor_relaxation, sweep, tangential_residual

__all__ = ["COARSEST", "POST", "PRE", "SMOOTHING", "coarse_shape", "correct", "prolonged", "restricted"]

#: Gauss-Seidel sweeps before and after each coarse-grid correction
PRE, POST = 2, 2
#: relaxation of those sweeps: a smoother, not an accelerator (SOR near 2 damps the
#: short waves poorly)
SMOOTHING = 1.0
#: a level with fewer nodes than this along a side is only swept (the coarsest)
COARSEST = 9
#: SOR sweeps on the coarsest level
COARSEST_SWEEPS = 24


def coarse_shape(shape: tuple[int, ...]) -> tuple[int, int]:
    """The coarse grid of a grid of ``shape`` (ni, nj, ...): about half the nodes, the same ends."""
    return (shape[0] + 1) // 2, (shape[1] + 1) // 2


def _positions(n: int, at: NDArray) -> tuple[NDArray, NDArray]:
    """Left neighbours and weights of fractional index positions ``at`` in ``0..n-1``."""
    left = np.minimum(np.floor(at).astype(np.intp), n - 2)
    return left, at - left


def _resampled(a: NDArray, at_i: NDArray, at_j: NDArray) -> NDArray:
    """``a`` (ni, nj[, k]) interpolated linearly at the index positions ``at_i x at_j`` (a
    tensor grid of fractional positions: separable)."""
    extra = (1,) * (a.ndim - 2)
    i, wi = _positions(a.shape[0], at_i)
    wi = wi.reshape(-1, 1, *extra)
    b = a[i] * (1.0 - wi) + a[i + 1] * wi
    j, wj = _positions(a.shape[1], at_j)
    wj = wj.reshape(1, -1, *extra)
    return b[:, j] * (1.0 - wj) + b[:, j + 1] * wj


def restricted(a: NDArray) -> NDArray:
    """``a`` (ni, nj[, k]) interpolated linearly onto the nodes of its :func:`coarse_shape` grid."""
    ci, cj = coarse_shape(a.shape)
    return _resampled(a, np.linspace(0, a.shape[0] - 1, ci), np.linspace(0, a.shape[1] - 1, cj))


def prolonged(a: NDArray, shape: tuple[int, ...]) -> NDArray:
    """``a`` on the coarse grid of a grid of ``shape`` interpolated linearly back onto its nodes."""
    ni, nj = shape[:2]
    ci, cj = a.shape[:2]
    return _resampled(a, np.arange(ni) * (ci - 1) / (ni - 1), np.arange(nj) * (cj - 1) / (nj - 1))


def _full_weighting(r: NDArray) -> NDArray:
    """``r`` (ni, nj, 3), zero on the boundary, averaged over each node's 3 x 3 neighbours with
    weights ``[1 2 1] x [1 2 1] / 16`` (the boundary stays zero)."""
    out = r.copy()
    out[1:-1] = 0.25 * r[:-2] + 0.5 * r[1:-1] + 0.25 * r[2:]
    inner = out.copy()
    inner[:, 1:-1] = 0.25 * out[:, :-2] + 0.5 * out[:, 1:-1] + 0.25 * out[:, 2:]
    inner[[0, -1]] = 0.0
    inner[:, [0, -1]] = 0.0
    return inner


def _smooth(s: NDArray, t: NDArray, x: NDArray, rs: NDArray, rt: NDArray, P: NDArray, Q: NDArray,
            target: NDArray | None, box: tuple[float, float, float, float], sweeps: int,
            omega: float = SMOOTHING) -> None:
    """``sweeps`` sweeps in place on the linearized surface (``x`` moved with the nodes)."""
    for _ in range(sweeps):
        sweep(s, t, x, rs, rt, P, Q, omega, box, target)


def correct(surface: NurbsSurface, s: NDArray, t: NDArray, x: NDArray, rs: NDArray, rt: NDArray,
            P: NDArray, Q: NDArray, box: tuple[float, float, float, float], sign: float,
            target: NDArray | None = None) -> bool:
    """One FAS coarse-grid correction of the grid ``(s, t)`` (ni, nj) in place.

    Parameters
    ----------
    surface : NurbsSurface
    s, t : (ni, nj) float
        The parameters of the nodes, the boundary held.
    x, rs, rt : (ni, nj, 3) float
        The nodes in space and the tangents they were moved with (the linearized
        surface of the sweeps); ``x`` is moved with the correction the same way.
    P, Q : (ni, nj) float
        Control functions.
    box : (u0, u1, v0, v1)
        The parameters are clipped to it.
    sign : float
        The orientation of the grid's cells in the parameters (+1 or -1).
    target : (ni, nj, 3) float, optional
        This level solves ``R = target`` (a coarse level of a finer one).

    Returns
    -------
    bool
        The correction was applied (False: the grid is too small, or the correction
        folded a cell even when quartered).
    """
    ni, nj = s.shape
    if min(ni, nj) < COARSEST:
        return False
    ci, cj = coarse_shape(s.shape)
    ri, rj = (ni - 1) / (ci - 1), (nj - 1) / (cj - 1)
    residual = tangential_residual(x, rs, rt, P, Q, target)
    sc, tc = restricted(s), restricted(t)
    Pc, Qc = ri * restricted(P), rj * restricted(Q)
    d = surface.derivatives(sc, tc, 1)
    xc, rsc, rtc = d[..., 0, 0, :].copy(), d[..., 1, 0, :], d[..., 0, 1, :]
    tau = tangential_residual(xc, rsc, rtc, Pc, Qc) \
        - (ri * rj) ** 2 * restricted(_full_weighting(residual))
    tau[[0, -1]] = 0.0
    tau[:, [0, -1]] = 0.0
    s0, t0 = sc.copy(), tc.copy()
    if min(ci, cj) < COARSEST:                       # the coarsest level: sweeps alone
        _smooth(sc, tc, xc, rsc, rtc, Pc, Qc, tau, box, COARSEST_SWEEPS, sor_relaxation(max(sc.shape)))
    else:                                            # a V-cycle
        _smooth(sc, tc, xc, rsc, rtc, Pc, Qc, tau, box, PRE)
        correct(surface, sc, tc, xc, rsc, rtc, Pc, Qc, box, sign, tau)
        _smooth(sc, tc, xc, rsc, rtc, Pc, Qc, tau, box, POST)
    ds, dt = prolonged(sc - s0, s.shape), prolonged(tc - t0, s.shape)
    for a in (ds, dt):
        a[[0, -1]] = 0.0
        a[:, [0, -1]] = 0.0
    u0, u1, v0, v1 = box
    for scale in (1.0, 0.5, 0.25):
        sn = np.clip(s + scale * ds, u0, u1)
        tn = np.clip(t + scale * dt, v0, v1)
        if not folds(sn, tn, sign):
            x += rs * (sn - s)[..., None] + rt * (tn - t)[..., None]
            s[...], t[...] = sn, tn
            return True
    return False
