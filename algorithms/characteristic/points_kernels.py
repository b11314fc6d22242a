"""Newton on ``grad phi = 0`` (002 eq. 9) compiled: every seed's iterations in one numba call.

:func:`.points.critical_points` runs the same steps batched in numpy; each of its
up to 16 rounds cost a jet call, an eigen-decomposition and a dozen small array
operations (some 3-4 ms per certificate on the degree-6 pair). :func:`newton_compiled`
takes, seed by seed, the same Newton step ``-H^{-1} grad phi`` (with the
pseudo-inverse on a degenerate ``H``, :func:`.points._newton_steps`), the same
step cap (a tenth of the diagonal) and the same stops: a seed dies when ``H``
is flat or singular, its foot stops being unique, or it leaves ``r``'s domain;
it is done when the step falls under ``1e-13`` of the diagonal.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..jit import jit
from .curves_kernels import AVAILABLE, buffers, jet, kernel_arguments

__all__ = ["AVAILABLE", "newton_compiled"]


@jit
def _step(h00, h01, h11, g0, g1, flat, degenerate, pseudo):
    """``(d0, d1, ok)``: the Newton step; with ``pseudo`` the eigenvalues below
    ``degenerate`` of the largest are left out when ``H`` is rank 1."""
    if not pseudo:
        det = h00 * h11 - h01 * h01
        if not abs(det) > 1e-300:
            return 0.0, 0.0, False
        return -(h11 * g0 - h01 * g1) / det, -(h00 * g1 - h01 * g0) / det, True
    mean, half = 0.5 * (h00 + h11), 0.5 * (h00 - h11)
    rad = np.sqrt(half * half + h01 * h01)
    lam0, lam1 = mean - rad, mean + rad                              # ascending, as eigh
    if h01 != 0.0:                                                   # eigenvector of lam1
        e0, e1 = lam1 - h11, h01
    elif h00 >= h11:
        e0, e1 = 1.0, 0.0
    else:
        e0, e1 = 0.0, 1.0
    norm = np.sqrt(e0 * e0 + e1 * e1)
    e0, e1 = e0 / norm, e1 / norm                                    # v1 = (e0, e1)
    f0, f1 = -e1, e0                                                 # v0, orthogonal
    top = max(abs(lam0), abs(lam1))
    rank1 = abs(lam0 * lam1) <= degenerate * top * top
    d0 = d1 = 0.0
    for lam, a, b in ((lam0, f0, f1), (lam1, e0, e1)):
        if not rank1 or abs(lam) > degenerate * top:
            c = (a * g0 + b * g1) / lam
            d0 -= a * c
            d1 -= b * c
    return d0, d1, top > flat


@jit
def _newton_all(rq, pp, uv, st, max_iter, diag, r_lo, r_hi, flat, degenerate, pseudo):
    o, w = buffers(rq)
    m = uv.shape[0]
    done = np.zeros(m, dtype=np.bool_)
    eps0, eps1 = 1e-9 * (r_hi[0] - r_lo[0]), 1e-9 * (r_hi[1] - r_lo[1])
    for k in range(m):
        x0, x1, s0, s1 = uv[k, 0], uv[k, 1], st[k, 0], st[k, 1]
        for _ in range(max_iter):
            jet(rq, pp, o, w, x0, x1, s0, s1)
            s0, s1 = o[3][0, 0], o[3][0, 1]
            h = o[6]
            d0, d1, ok = _step(h[0, 0, 0], h[0, 0, 1], h[0, 1, 1], o[5][0, 0], o[5][0, 1],
                               flat, degenerate, pseudo)
            length = np.sqrt(d0 * d0 + d1 * d1)
            f = min(1.0, 0.1 * diag / max(length, 1e-300))
            x0, x1 = x0 + d0 * f, x1 + d1 * f
            inside = (r_lo[0] - eps0 <= x0 <= r_hi[0] + eps0
                      and r_lo[1] - eps1 <= x1 <= r_hi[1] + eps1)
            if not ok or o[8][0] != 0 or not inside:
                break
            if length <= 1e-13 * diag:
                done[k] = True
                break
        uv[k, 0], uv[k, 1], st[k, 0], st[k, 1] = x0, x1, s0, s1
    return uv, st, done


def newton_compiled(field, uv: NDArray, st: NDArray, *, max_iter: int, flat: float,
                    degenerate: float, pseudo: bool) -> tuple[NDArray, NDArray, NDArray]:
    """Newton on ``grad phi = 0`` from ``uv (k, 2)`` (feet ``st``), seed by seed.

    Returns
    -------
    uv, st : (k, 2) float
        The last iterates and their feet.
    done : (k,) bool
        Converged (step under ``1e-13`` of the diagonal) without being dropped.
    """
    rq, pp = kernel_arguments(field)
    c = np.ascontiguousarray
    return _newton_all(rq, pp, c(uv, dtype=float).copy(), c(st, dtype=float).copy(),
                       int(max_iter), float(field.diagonal), field.lower, field.upper,
                       float(flat), float(degenerate), bool(pseudo))
